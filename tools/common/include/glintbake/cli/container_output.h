// SPDX-License-Identifier: Apache-2.0
// A container file written by a tool: the format::Writer's temporary file is registered for
// removal on SIGINT/SIGTERM, removed on any failure, and renamed into place only by finish().
// Errors become cli::Error with the I/O exit code.
#pragma once

#include <glintbake/cli/tool.h>
#include <glintbake/format/container.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace glintbake::cli {

class ContainerOutput {
 public:
  // Opens the temporary file next to path and records path as the tool's output (depfile).
  ContainerOutput(Tool& tool, const std::string& path, format::AssetKind kind, int zstd_level = 9);
  ~ContainerOutput();
  ContainerOutput(const ContainerOutput&) = delete;
  ContainerOutput& operator=(const ContainerOutput&) = delete;

  void addSection(uint32_t type, uint64_t key, const void* data, size_t size);
  // An image section (format::ImageSectionHeader + width*height*channels*layers floats).
  void addImageSection(uint32_t type, uint64_t key, int width, int height, int channels, const float* data,
                       int layers = 1);
  // Container metadata for this output's asset kind (Tool::makeMetadata).
  Json makeMetadata(const Json& parameters) const { return tool_.makeMetadata(kind_, parameters); }
  // Adds the metadata section, writes index and header, renames into place.
  void finish(const Json& metadata);
  // The same with the metadata as text (kept byte for byte; sharded bakes' merge).
  void finishText(const std::string& metadata_json);

  // The underlying writer, for producers that stream sections themselves.
  format::Writer& writer() { return writer_; }
  uint64_t bytesWritten() const { return writer_.bytesWritten(); }

 private:
  // The OS reason of a failed write ("File too large"), else the status name.
  std::string reason(format::ContainerStatus status) const;

  Tool& tool_;
  format::AssetKind kind_;
  format::Writer writer_;
  std::string path_, temporary_;
  bool finished_ = false;
};

}  // namespace glintbake::cli
