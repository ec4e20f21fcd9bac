// SPDX-License-Identifier: Apache-2.0
// Decoding one section front to back in bounded memory (SectionDecoder), for the validator, diff
// tools and any reader of sections larger than it wants to hold.
#include "container_parse.h"

#include "hash_stream.h"

#include <zstd.h>

#include <algorithm>
#include <cstring>

namespace glintbake::format::detail {

SectionDecoder::~SectionDecoder() {
  if (dctx_) ZSTD_freeDCtx(static_cast<ZSTD_DCtx*>(dctx_));
}

ContainerStatus SectionDecoder::fail(ContainerStatus status) {
  if (status_ == ContainerStatus::kOk) status_ = status;
  return status_;
}

bool SectionDecoder::refill() {
  if (stored_read_ >= info_.stored_size) return false;
  const size_t n = size_t(std::min<uint64_t>(kSectionStreamChunk, info_.stored_size - stored_read_));
  if (const uint8_t* data = source_->data()) {
    in_data_ = data + info_.offset + stored_read_;
  } else {
    piece_.resize(n);
    if (!source_->readAt(info_.offset + stored_read_, piece_.data(), n)) {
      io_failed_ = true;
      return false;
    }
    in_data_ = piece_.data();
  }
  in_size_ = n;
  in_pos_ = 0;
  stored_read_ += n;
  return true;
}

ContainerStatus SectionDecoder::start(const ByteSource& source, const SectionInfo& info) {
  source_ = &source;
  info_ = info;
  produced_ = 0;
  stored_read_ = 0;
  in_data_ = nullptr;
  in_size_ = in_pos_ = 0;
  io_failed_ = frame_done_ = started_ = false;
  status_ = ContainerStatus::kOk;
  if (info.codec != uint32_t(Codec::kRaw) && info.codec != uint32_t(Codec::kZstd))
    return fail(ContainerStatus::kDecompressFailed);
  if (info.codec == uint32_t(Codec::kRaw) && (info.stored_size != info.raw_size || info.raw_size > source.size()))
    return fail(ContainerStatus::kCorruptIndex);
  if (info.offset > source.size() || info.stored_size > source.size() - info.offset)
    return fail(ContainerStatus::kTruncated);

  // One pass over the stored bytes: the checksum and, for zstd, the frame's structure.
  ZstdFrameScan scan(info.stored_size);
  const bool zstd = info.codec == uint32_t(Codec::kZstd);
  uint64_t checksum = 0;
  if (const uint8_t* data = source.data()) {
    checksum = hash64(data + info.offset, size_t(info.stored_size));
    if (zstd && checksum == info.checksum) scan.feed(data + info.offset, size_t(info.stored_size));
  } else {
    XXH3Streamer hasher;
    if (!hasher.ok()) return fail(ContainerStatus::kIoError);
    while (refill()) {
      hasher.update(in_data_, in_size_);
      if (zstd) scan.feed(in_data_, in_size_);
    }
    if (io_failed_) return fail(ContainerStatus::kTruncated);
    checksum = hasher.digest();
    stored_read_ = 0;
    in_size_ = in_pos_ = 0;
  }
  if (checksum != info.checksum) return fail(ContainerStatus::kChecksumMismatch);
  started_ = !zstd;
  if (!zstd) return ContainerStatus::kOk;
  const ContainerStatus frame = scan.verdict(info.raw_size);
  if (frame != ContainerStatus::kOk) return fail(frame);

  if (!dctx_) dctx_ = ZSTD_createDCtx();
  if (!dctx_) return fail(ContainerStatus::kDecompressFailed);
  auto* dctx = static_cast<ZSTD_DCtx*>(dctx_);
  ZSTD_DCtx_reset(dctx, ZSTD_reset_session_and_parameters);
  // The scan has bounded the window already; the decoder enforces the same limit itself.
  static_assert(kMaxZstdWindowSize == uint64_t(1) << 27, "window limit and its log agree");
  ZSTD_DCtx_setParameter(dctx, ZSTD_d_windowLogMax, 27);
  started_ = info.raw_size != 0 || finishFrame() == ContainerStatus::kOk;
  return status_;
}

// Decodes exactly `size` bytes into dst, feeding stored pieces as the decoder asks for them.
ContainerStatus SectionDecoder::pump(uint8_t* dst, size_t size) {
  auto* dctx = static_cast<ZSTD_DCtx*>(dctx_);
  ZSTD_outBuffer out{dst, size, 0};
  while (out.pos < out.size) {
    if (frame_done_) return fail(ContainerStatus::kDecompressFailed);  // the frame ended early
    if (in_pos_ == in_size_ && !refill()) {
      return fail(io_failed_ ? ContainerStatus::kTruncated : ContainerStatus::kDecompressFailed);
    }
    ZSTD_inBuffer in{in_data_, in_size_, in_pos_};
    const size_t left = ZSTD_decompressStream(dctx, &out, &in);
    in_pos_ = in.pos;
    if (ZSTD_isError(left)) return fail(ContainerStatus::kDecompressFailed);
    frame_done_ = left == 0;
  }
  return ContainerStatus::kOk;
}

// After raw_size bytes: the frame must end here (no byte more) and use every stored byte.
ContainerStatus SectionDecoder::finishFrame() {
  auto* dctx = static_cast<ZSTD_DCtx*>(dctx_);
  while (!frame_done_) {
    if (in_pos_ == in_size_ && !refill()) {
      return fail(io_failed_ ? ContainerStatus::kTruncated : ContainerStatus::kDecompressFailed);
    }
    uint8_t extra = 0;
    ZSTD_outBuffer out{&extra, 1, 0};
    ZSTD_inBuffer in{in_data_, in_size_, in_pos_};
    const size_t left = ZSTD_decompressStream(dctx, &out, &in);
    in_pos_ = in.pos;
    if (ZSTD_isError(left) || out.pos != 0) return fail(ContainerStatus::kDecompressFailed);
    frame_done_ = left == 0;
  }
  if (in_pos_ != in_size_ || stored_read_ != info_.stored_size) return fail(ContainerStatus::kDecompressFailed);
  return ContainerStatus::kOk;
}

ContainerStatus SectionDecoder::read(void* dst, size_t size) {
  if (status_ != ContainerStatus::kOk) return status_;
  const size_t n = size_t(std::min<uint64_t>(size, remaining()));
  if (n == 0) return ContainerStatus::kOk;
  if (dst == nullptr) return ContainerStatus::kInvalidArgument;
  if (info_.codec == uint32_t(Codec::kRaw)) {
    if (!source_->readAt(info_.offset + produced_, dst, n)) return fail(ContainerStatus::kTruncated);
    produced_ += n;
    return ContainerStatus::kOk;
  }
  if (pump(static_cast<uint8_t*>(dst), n) != ContainerStatus::kOk) return status_;
  produced_ += n;
  if (produced_ == info_.raw_size) return finishFrame();
  return ContainerStatus::kOk;
}

ContainerStatus streamSection(const ByteSource& source, const SectionInfo& info, SectionSink* sink) {
  SectionDecoder decoder;
  ContainerStatus status = decoder.start(source, info);
  if (status != ContainerStatus::kOk) return status;
  std::vector<uint8_t> chunk(size_t(std::min<uint64_t>(kSectionStreamChunk, info.raw_size)));
  while (decoder.remaining() > 0) {
    const size_t n = size_t(std::min<uint64_t>(chunk.size(), decoder.remaining()));
    status = decoder.read(chunk.data(), n);
    if (status != ContainerStatus::kOk) return status;
    sink->consume(chunk.data(), n);
  }
  return ContainerStatus::kOk;
}

}  // namespace glintbake::format::detail
