// SPDX-License-Identifier: Apache-2.0
#include <glintbake/cli/container_output.h>

#include <cstring>
#include <vector>

namespace glintbake::cli {

ContainerOutput::ContainerOutput(Tool& tool, const std::string& path, format::AssetKind kind, int zstd_level)
    : tool_(tool), kind_(kind), path_(path) {
  // A container is written with seeks (index, checksums): no stream can hold it.
  if (path == "-")
    throw Error(kExitBadArguments, "a container cannot be written to standard output ('-'): name a .gbk file");
  const format::ContainerStatus status = writer_.open(path, kind, zstd_level);
  if (status != format::ContainerStatus::kOk) {
    throw Error(kExitIo, "cannot create " + path + ": " + reason(status));
  }
  temporary_ = writer_.temporaryPath();
  if (!temporary_.empty()) registerTemporary(temporary_);
  tool.addOutput(path);
}

std::string ContainerOutput::reason(format::ContainerStatus status) const {
  const int error_number = writer_.errorNumber();
  return error_number ? std::string(std::strerror(error_number)) : std::string(format::statusString(status));
}

ContainerOutput::~ContainerOutput() {
  if (!finished_) writer_.abort();
  if (!temporary_.empty()) unregisterTemporary(temporary_);
}

void ContainerOutput::addSection(uint32_t type, uint64_t key, const void* data, size_t size) {
  const format::ContainerStatus status = writer_.addSection(type, key, data, size);
  if (status != format::ContainerStatus::kOk) throw Error(kExitIo, "cannot write " + path_ + ": " + reason(status));
}

void ContainerOutput::addImageSection(uint32_t type, uint64_t key, int width, int height, int channels,
                                      const float* data, int layers) {
  format::ImageSectionHeader header;
  header.width = uint32_t(width);
  header.height = uint32_t(height);
  header.channels = uint32_t(channels);
  header.layers = uint32_t(layers);
  const size_t values = size_t(width) * size_t(height) * size_t(channels) * size_t(layers);
  std::vector<uint8_t> bytes(sizeof(header) + values * sizeof(float));
  std::memcpy(bytes.data(), &header, sizeof(header));
  std::memcpy(bytes.data() + sizeof(header), data, values * sizeof(float));
  addSection(type, key, bytes.data(), bytes.size());
}

void ContainerOutput::finish(const Json& metadata) { finishText(metadata.dump()); }

void ContainerOutput::finishText(const std::string& metadata_json) {
  format::ContainerStatus status = writer_.addMetadata(metadata_json);
  if (status == format::ContainerStatus::kOk) status = writer_.finish();
  if (status != format::ContainerStatus::kOk) throw Error(kExitIo, "cannot write " + path_ + ": " + reason(status));
  finished_ = true;
}

}  // namespace glintbake::cli
