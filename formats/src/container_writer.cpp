// SPDX-License-Identifier: Apache-2.0
// Writer: streams sections into a temporary file, then writes index and header and renames.
#include <glintbake/format/atomic_file.h>
#include <glintbake/format/container.h>

#include "hash_stream.h"
#include "layout.h"

#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <set>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace glintbake::format {

using namespace layout;

namespace {

// The frame parameters every stored zstd section uses: fixed level, content size recorded, no
// checksum (the index has one), no dictionary id, single-threaded.
void setFrameParameters(ZSTD_CCtx* cctx, int zstd_level) {
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, zstd_level);
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_contentSizeFlag, 1);
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 0);
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_dictIDFlag, 0);
}

// Compresses into `compressed` and returns true when zstd shrinks the data (the stored form is
// then compressed[0, *stored_size)); false means store the raw bytes. kInvalidArgument on a zstd
// failure.
ContainerStatus compressSection(ZSTD_CCtx* cctx, const void* data, size_t size, std::vector<uint8_t>& compressed,
                                bool* shrinks, size_t* stored_size) {
  *shrinks = false;
  *stored_size = size;
  if (size == 0) return ContainerStatus::kOk;
  compressed.resize(ZSTD_compressBound(size));
  const size_t n = ZSTD_compress2(cctx, compressed.data(), compressed.size(), data, size);
  if (ZSTD_isError(n)) return ContainerStatus::kInvalidArgument;
  if (n < size) {  // keep zstd only when it shrinks the section
    *shrinks = true;
    *stored_size = n;
  }
  return ContainerStatus::kOk;
}

}  // namespace

struct Writer::Impl {
  std::string final_path;
  AtomicFile file;
  bool open = false;
  bool failed = false;
  bool finished = false;
  AssetKind kind = AssetKind::kUnknown;
  int zstd_level = 9;
  uint64_t position = 0;  // bytes written so far (the file's current size)
  bool has_metadata = false;
  std::vector<SectionInfo> sections;
  std::set<std::pair<uint32_t, uint64_t>> keys;
  detail::XXH3Streamer file_hash;  // bytes [kHeaderSize, position)
  ZSTD_CCtx* cctx = nullptr;
  std::vector<uint8_t> compressed;

  ~Impl() {
    if (cctx) ZSTD_freeCCtx(cctx);
  }

  // Writes all of data at the current position (sequential, after the header).
  bool append(const void* data, size_t size) {
    if (file.write(data, size) != ContainerStatus::kOk) return false;
    file_hash.update(data, size);
    position += size;
    return true;
  }

  bool padTo(uint64_t alignment) {
    static const uint8_t kZeros[kSectionAlignment] = {};
    const uint64_t target = alignUp(position, alignment);
    return append(kZeros, size_t(target - position));
  }

  ContainerStatus fail(ContainerStatus status) {
    failed = true;
    return status;
  }
};

Writer::Writer() : impl_(std::make_unique<Impl>()) {}

Writer::~Writer() {
  if (!impl_->finished) abort();
}

ContainerStatus Writer::open(const std::string& path, AssetKind kind, int zstd_level) {
  if (impl_->open || impl_->finished) return ContainerStatus::kInvalidArgument;
  if (path.empty() || zstd_level < 1 || zstd_level > 19) return ContainerStatus::kInvalidArgument;
  Impl& w = *impl_;
  w.final_path = path;
  w.kind = kind;
  w.zstd_level = zstd_level;
  if (w.file.open(path) != ContainerStatus::kOk) return ContainerStatus::kIoError;
  w.open = true;
  w.cctx = ZSTD_createCCtx();
  if (!w.cctx || !w.file_hash.ok()) return w.fail(ContainerStatus::kIoError);
  setFrameParameters(w.cctx, zstd_level);  // deterministic frames
  // The header is written last; reserve its bytes now (they are not part of the file hash).
  static const uint8_t kZeroHeader[kHeaderSize] = {};
  if (w.file.write(kZeroHeader, kHeaderSize) != ContainerStatus::kOk) return w.fail(ContainerStatus::kIoError);
  w.position = kHeaderSize;
  return ContainerStatus::kOk;
}

ContainerStatus Writer::addSection(uint32_t type, uint64_t key, const void* data, size_t size, Codec codec) {
  Impl& w = *impl_;
  if (!w.open || w.failed || w.finished) return ContainerStatus::kInvalidArgument;
  if (data == nullptr && size != 0) return ContainerStatus::kInvalidArgument;
  if (codec != Codec::kRaw && codec != Codec::kZstd) return ContainerStatus::kInvalidArgument;
  if (uint64_t(size) > kDefaultMaxRawSectionSize) return ContainerStatus::kTooLarge;
  const void* stored = data;
  size_t stored_size = size;
  Codec used = Codec::kRaw;
  if (codec == Codec::kZstd) {
    bool shrinks = false;
    if (compressSection(w.cctx, data, size, w.compressed, &shrinks, &stored_size) != ContainerStatus::kOk)
      return w.fail(ContainerStatus::kInvalidArgument);
    if (shrinks) {
      used = Codec::kZstd;
      stored = w.compressed.data();
    }
  }
  const ContainerStatus st = addStoredSection(type, key, used, size, stored, stored_size);
  // Release a large compression buffer rather than keep it for the writer's lifetime.
  if (w.compressed.capacity() > (size_t(64) << 20)) std::vector<uint8_t>().swap(w.compressed);
  return st;
}

ContainerStatus Writer::addStoredSection(uint32_t type, uint64_t key, Codec codec, uint64_t raw_size,
                                         const void* stored, size_t stored_size) {
  Impl& w = *impl_;
  if (!w.open || w.failed || w.finished) return ContainerStatus::kInvalidArgument;
  if (stored == nullptr && stored_size != 0) return ContainerStatus::kInvalidArgument;
  if (codec != Codec::kRaw && codec != Codec::kZstd) return ContainerStatus::kInvalidArgument;
  if (codec == Codec::kRaw && raw_size != stored_size) return ContainerStatus::kInvalidArgument;
  if (w.sections.size() >= kMaxSectionCount) return ContainerStatus::kTooLarge;
  if (raw_size > kDefaultMaxRawSectionSize) return ContainerStatus::kTooLarge;
  if (type == kSectionMetadata && w.has_metadata) return ContainerStatus::kInvalidArgument;
  if (!w.keys.insert({type, key}).second) return ContainerStatus::kInvalidArgument;  // (type, key) is unique

  SectionInfo info;
  info.type = type;
  info.key = key;
  info.raw_size = raw_size;
  info.codec = uint32_t(codec);
  if (!w.padTo(kSectionAlignment)) return w.fail(ContainerStatus::kIoError);
  info.offset = w.position;
  info.stored_size = stored_size;
  info.checksum = hash64(stored, stored_size);
  if (!w.append(stored, stored_size)) return w.fail(ContainerStatus::kIoError);
  w.sections.push_back(info);
  if (type == kSectionMetadata) w.has_metadata = true;
  return ContainerStatus::kOk;
}

SectionEncoder::SectionEncoder(int zstd_level) : level_(std::clamp(zstd_level, 1, 19)) {
  ZSTD_CCtx* cctx = ZSTD_createCCtx();
  if (cctx) setFrameParameters(cctx, level_);
  cctx_ = cctx;
}

SectionEncoder::~SectionEncoder() {
  if (cctx_) ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(cctx_));
}

ContainerStatus SectionEncoder::encode(const void* data, size_t size, Codec codec, std::vector<uint8_t>* stored,
                                       Codec* used) {
  if (!cctx_ || !stored || !used || (data == nullptr && size != 0)) return ContainerStatus::kInvalidArgument;
  if (codec != Codec::kRaw && codec != Codec::kZstd) return ContainerStatus::kInvalidArgument;
  if (uint64_t(size) > kDefaultMaxRawSectionSize) return ContainerStatus::kTooLarge;
  *used = Codec::kRaw;
  if (codec == Codec::kZstd) {
    bool shrinks = false;
    size_t stored_size = size;
    if (ContainerStatus st =
            compressSection(static_cast<ZSTD_CCtx*>(cctx_), data, size, *stored, &shrinks, &stored_size);
        st != ContainerStatus::kOk)
      return st;
    if (shrinks) {
      stored->resize(stored_size);
      *used = Codec::kZstd;
      return ContainerStatus::kOk;
    }
  }
  const uint8_t* bytes = static_cast<const uint8_t*>(data);
  stored->assign(bytes, bytes + size);
  return ContainerStatus::kOk;
}

ContainerStatus Writer::addMetadata(const std::string& json_utf8) {
  return addSection(kSectionMetadata, 0, json_utf8.data(), json_utf8.size(), Codec::kZstd);
}

ContainerStatus Writer::finish() {
  Impl& w = *impl_;
  if (!w.open || w.finished) return ContainerStatus::kInvalidArgument;
  if (w.failed) {
    abort();
    return ContainerStatus::kInvalidArgument;
  }
  if (!w.has_metadata) {
    abort();
    return ContainerStatus::kInvalidArgument;
  }

  if (!w.padTo(kSectionAlignment)) {
    abort();
    return ContainerStatus::kIoError;
  }
  const uint64_t index_offset = w.position;
  std::vector<uint8_t> index(w.sections.size() * kIndexEntrySize, 0);
  for (size_t i = 0; i < w.sections.size(); ++i) {
    const SectionInfo& s = w.sections[i];
    uint8_t* e = index.data() + i * kIndexEntrySize;
    store32(e + kEntType, s.type);
    store32(e + kEntCodec, s.codec);
    store64(e + kEntKey, s.key);
    store64(e + kEntOffset, s.offset);
    store64(e + kEntStoredSize, s.stored_size);
    store64(e + kEntRawSize, s.raw_size);
    store64(e + kEntChecksum, s.checksum);
  }
  if (!w.append(index.data(), index.size())) {
    abort();
    return ContainerStatus::kIoError;
  }

  uint8_t h[kHeaderSize] = {};
  std::memcpy(h + kOffMagic, kMagic, sizeof(kMagic));
  store16(h + kOffVersionMajor, kFormatVersionMajor);
  store16(h + kOffVersionMinor, kFormatVersionMinor);
  store32(h + kOffAssetKind, uint32_t(w.kind));
  store32(h + kOffHeaderSize, uint32_t(kHeaderSize));
  store32(h + kOffSectionCount, uint32_t(w.sections.size()));
  store64(h + kOffIndexOffset, index_offset);
  store64(h + kOffIndexSize, index.size());
  store64(h + kOffFileSize, w.position);
  store64(h + kOffFileChecksum, w.file_hash.digest());
  store64(h + kOffIndexChecksum, hash64(index.data(), index.size()));
  store64(h + kOffHeaderChecksum, hash64(h, kHeaderSize));  // computed with the field still zero

  if (w.file.writeAt(h, kHeaderSize, 0) != ContainerStatus::kOk || w.file.commit() != ContainerStatus::kOk) {
    abort();
    return ContainerStatus::kIoError;
  }
  w.open = false;
  w.finished = true;
  return ContainerStatus::kOk;
}

void Writer::abort() {
  Impl& w = *impl_;
  w.file.abort();
  w.open = false;
  w.failed = true;
}

const std::string& Writer::temporaryPath() const { return impl_->file.temporaryPath(); }

int Writer::errorNumber() const { return impl_->file.errorNumber(); }

std::string Writer::errorString(ContainerStatus status) const {
  const int error_number = errorNumber();
  return error_number ? std::string(std::strerror(error_number)) : std::string(statusString(status));
}

uint64_t Writer::bytesWritten() const { return impl_->position; }

}  // namespace glintbake::format
