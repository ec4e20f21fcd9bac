// SPDX-License-Identifier: Apache-2.0
// Reader: random access to the sections of a container, checked against untrusted input.
#include <glintbake/format/container.h>

#include "byte_source.h"
#include "container_parse.h"

#include <algorithm>
#include <memory>
#include <tuple>

namespace glintbake::format {

struct Reader::Impl {
  std::unique_ptr<detail::ByteSource> source;
  detail::ParsedContainer parsed;
  // (type, key, index) sorted, for find() in O(log n).
  std::vector<std::tuple<uint32_t, uint64_t, uint32_t>> lookup;

  ContainerStatus adopt(std::unique_ptr<detail::ByteSource> src, const ReaderOptions& options) {
    const ContainerStatus status = detail::parseContainer(*src, options, &parsed, nullptr);
    if (status == ContainerStatus::kOk && options.verify_file_checksum) {
      const ContainerStatus checksum = detail::verifyFileChecksumOf(*src, parsed.header.file_checksum);
      if (checksum != ContainerStatus::kOk) {
        parsed = {};
        return checksum;
      }
    }
    if (status != ContainerStatus::kOk) {
      parsed = {};
      return status;
    }
    source = std::move(src);
    lookup.clear();
    lookup.reserve(parsed.sections.size());
    for (uint32_t i = 0; i < parsed.sections.size(); ++i) {
      lookup.emplace_back(parsed.sections[i].type, parsed.sections[i].key, i);
    }
    std::sort(lookup.begin(), lookup.end());
    return ContainerStatus::kOk;
  }
};

Reader::Reader() : impl_(std::make_unique<Impl>()) {}
Reader::~Reader() = default;

ContainerStatus Reader::open(const std::string& path, const ReaderOptions& options) {
  close();
  auto file = std::make_unique<detail::FileSource>();
  if (!file->open(path)) return ContainerStatus::kIoError;
  return impl_->adopt(std::move(file), options);
}

ContainerStatus Reader::openMemory(const void* data, size_t size, const ReaderOptions& options) {
  close();
  if (data == nullptr && size != 0) return ContainerStatus::kInvalidArgument;
  static const uint8_t kEmpty = 0;
  return impl_->adopt(std::make_unique<detail::MemorySource>(data ? data : &kEmpty, size), options);
}

void Reader::close() {
  impl_->source.reset();
  impl_->parsed = {};
  impl_->lookup.clear();
}

const HeaderInfo& Reader::header() const { return impl_->parsed.header; }

AssetKind Reader::kind() const { return AssetKind(impl_->parsed.header.asset_kind); }

const std::vector<SectionInfo>& Reader::sections() const { return impl_->parsed.sections; }

int Reader::find(uint32_t type) const {
  const auto& lookup = impl_->lookup;
  auto it = std::lower_bound(lookup.begin(), lookup.end(), std::make_tuple(type, uint64_t(0), uint32_t(0)));
  // The first section of this type in index order, not the one with the smallest key.
  int best = -1;
  for (; it != lookup.end() && std::get<0>(*it) == type; ++it) {
    const int index = int(std::get<2>(*it));
    if (best < 0 || index < best) best = index;
  }
  return best;
}

int Reader::find(uint32_t type, uint64_t key) const {
  const auto& lookup = impl_->lookup;
  auto it = std::lower_bound(lookup.begin(), lookup.end(), std::make_tuple(type, key, uint32_t(0)));
  if (it != lookup.end() && std::get<0>(*it) == type && std::get<1>(*it) == key) return int(std::get<2>(*it));
  return -1;
}

ContainerStatus Reader::readSection(size_t i, std::vector<uint8_t>* out) const {
  if (!impl_->source || out == nullptr) return ContainerStatus::kInvalidArgument;
  if (i >= impl_->parsed.sections.size()) return ContainerStatus::kNotFound;
  // raw_size was checked against ReaderOptions::max_raw_section_size by open(); the frame is checked
  // against it before out grows.
  return detail::readSectionAlloc(*impl_->source, impl_->parsed.sections[i], out);
}

ContainerStatus Reader::readSectionInto(size_t i, void* dst, size_t dst_size) const {
  if (!impl_->source) return ContainerStatus::kInvalidArgument;
  if (i >= impl_->parsed.sections.size()) return ContainerStatus::kNotFound;
  return detail::readSectionFrom(*impl_->source, impl_->parsed.sections[i], dst, dst_size);
}

struct SectionStream::Impl {
  detail::SectionDecoder decoder;
};

SectionStream::SectionStream() : impl_(std::make_unique<Impl>()) {}
SectionStream::~SectionStream() = default;

uint64_t SectionStream::size() const { return impl_->decoder.size(); }

uint64_t SectionStream::remaining() const { return impl_->decoder.remaining(); }

ContainerStatus SectionStream::read(void* dst, size_t size) { return impl_->decoder.read(dst, size); }

ContainerStatus Reader::openSectionStream(size_t i, SectionStream* stream) const {
  if (stream == nullptr) return ContainerStatus::kInvalidArgument;
  stream->impl_ = std::make_unique<SectionStream::Impl>();
  if (!impl_->source) return ContainerStatus::kInvalidArgument;
  if (i >= impl_->parsed.sections.size()) return ContainerStatus::kNotFound;
  return stream->impl_->decoder.start(*impl_->source, impl_->parsed.sections[i]);
}

ContainerStatus Reader::readStored(size_t i, std::vector<uint8_t>* out) const {
  if (!impl_->source || out == nullptr) return ContainerStatus::kInvalidArgument;
  if (i >= impl_->parsed.sections.size()) return ContainerStatus::kNotFound;
  const SectionInfo& info = impl_->parsed.sections[i];
  out->resize(size_t(info.stored_size));
  if (!impl_->source->readAt(info.offset, out->data(), out->size())) {
    out->clear();
    return ContainerStatus::kTruncated;
  }
  return ContainerStatus::kOk;
}

ContainerStatus Reader::readMetadata(std::string* json_utf8) const {
  if (json_utf8 == nullptr) return ContainerStatus::kInvalidArgument;
  const int i = find(kSectionMetadata);
  if (i < 0) return ContainerStatus::kNotFound;
  if (impl_->parsed.sections[size_t(i)].raw_size > kMaxMetadataSize) return ContainerStatus::kTooLarge;
  std::vector<uint8_t> bytes;
  const ContainerStatus status = readSection(size_t(i), &bytes);
  if (status != ContainerStatus::kOk) return status;
  json_utf8->assign(bytes.begin(), bytes.end());
  return ContainerStatus::kOk;
}

ContainerStatus Reader::verifyFileChecksum() const {
  if (!impl_->source) return ContainerStatus::kInvalidArgument;
  return detail::verifyFileChecksumOf(*impl_->source, impl_->parsed.header.file_checksum);
}

}  // namespace glintbake::format
