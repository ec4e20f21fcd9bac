// SPDX-License-Identifier: Apache-2.0
// Entry points of the tensor-ndf packer: option checks, packing while the pyramid is built from a
// normal map, and packing an ndf-pyramid container chunk by chunk.
#include <glintbake/bake/tensor/tensor_assembly.h>
#include <glintbake/bake/tensor/tensor_pack.h>
#include <glintbake/format/kinds/ndf_pyramid.h>

#include "tensor/tensor_pack_internal.h"

#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <new>
#include <optional>
#include <string>

namespace glintbake::bake::tensor {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Runs f in an arena of `threads` workers (0: the caller's arena, e.g. the tool's global limit).
template <typename F>
BakeStatus inArena(int threads, F&& f) {
  if (threads <= 0) return f();
  tbb::task_arena arena(threads);
  BakeStatus result = okStatus();
  arena.execute([&] { result = f(); });
  return result;
}

Error invalidPyramidInput(const std::string& message) { return makeError(ErrorCode::kInvalidInput, message); }

// Maps a reader failure to the library's categories: unreadable files are I/O errors, everything
// else (checksums, decoding, sizes) means the container is corrupt.
Error readError(const std::string& what, format::ContainerStatus st) {
  const ErrorCode code = st == format::ContainerStatus::kIoError ? ErrorCode::kIo : ErrorCode::kInvalidInput;
  return makeError(code, "cannot read " + what + ": " + format::statusString(st));
}

// Checks a level record read from an untrusted container (the format's record check, against the
// level below), plus the packer's own limits on the grid and the region.
BakeStatus checkLevelRecord(const format::NdfLevelRecord& rec, int level, const format::NdfLevelRecord* below) {
  const std::string where = "ndf-level " + std::to_string(level) + ": ";
  if (format::RecordCheck c = format::checkNdfLevelRecord(rec, uint32_t(level), below); !c)
    return invalidPyramidInput(where + c.detail);
  if (uint64_t(rec.grid_width) * rec.grid_height > (uint64_t(1) << 26))
    return invalidPyramidInput(where + "centre grid out of range");
  if (rec.region_size > 256) return invalidPyramidInput(where + "region layout inconsistent with the grid");
  return okStatus();
}

}  // namespace

BakeStatus validateTensorPackOptions(const TensorPackOptions& o) {
  if (BakeStatus s = validateCpOptions(o.cp); !s) return s;
  auto bad = [](const std::string& m) { return BakeStatus(makeError(ErrorCode::kBadArgument, m)); };
  if (o.block < 1 || o.block > kMaxBlockBins)
    return bad("--block must be in [1, " + std::to_string(kMaxBlockBins) + "]");
  if (!(o.blank_threshold >= 0.0 && o.blank_threshold <= 1.0)) return bad("--blank-threshold must be in [0, 1]");
  if (std::isnan(o.error_target) || o.error_target > 1.0) return bad("--error-target must be in [0, 1]");
  if (o.precision != 0 && o.precision != 1) return bad("--precision must be float32 or float16");
  if (o.threads < 0) return bad("--threads must be >= 0");
  return okStatus();
}

namespace {

// The pyramid of a map or of a procedural source, compressed region by region as it is built,
// into `consumer` (a shard's recorder; not finished here), or, when it is null, into the asset's
// assembler over `writer`.
template <typename Build>
BakeStatus packBuiltPyramid(const ndf::PyramidOptions& pyramid, const TensorPackOptions& options,
                            format::Writer* writer, TensorRegionConsumer* consumer, TensorPackReport* report,
                            const std::atomic<bool>* cancel, const Build& build) {
  const auto t0 = Clock::now();
  if (BakeStatus s = validateTensorPackOptions(options); !s) return s;
  if (BakeStatus s = ndf::validatePyramidOptions(pyramid); !s) return s;
  if (pyramid.splat.ndf_res % options.block != 0) {
    return makeError(ErrorCode::kBadArgument, "--block " + std::to_string(options.block) + " must divide --ndf-res " +
                                                  std::to_string(pyramid.splat.ndf_res));
  }
  TensorPackReport local;
  TensorPackReport& rep = report ? *report : local;
  rep = TensorPackReport{};
  return inArena(options.threads, [&]() -> BakeStatus {
    std::optional<TensorAssembler> assembler;
    if (!consumer) consumer = &assembler.emplace(*writer, options, rep);
    detail::TensorPackSink sink(*consumer, options, rep, cancel, writer);
    const auto t_build = Clock::now();
    if (BakeStatus s = build(sink, rep.pyramid); !s) return s;
    rep.ndf_seconds = secondsSince(t_build) - sink.secondsInside();
    if (BakeStatus s = sink.finish(); !s) return s;
    if (assembler) {
      if (BakeStatus s = assembler->finish(); !s) return s;
    }
    rep.total_seconds = secondsSince(t0);
    return okStatus();
  });
}

}  // namespace

BakeStatus packTensorNdfFromMap(const NormalMap& map, const ndf::PyramidOptions& pyramid,
                                const TensorPackOptions& options, format::Writer& writer, TensorPackReport* report,
                                const ndf::PyramidProgress& progress, const std::atomic<bool>* cancel) {
  return packBuiltPyramid(pyramid, options, &writer, nullptr, report, cancel,
                          [&](ndf::PyramidSink& sink, ndf::PyramidReport& built) {
                            return ndf::buildNdfPyramid(map, pyramid, sink, &built, progress, cancel);
                          });
}

BakeStatus packTensorNdfFromMap(const NormalMap& map, const ndf::PyramidOptions& pyramid,
                                const TensorPackOptions& options, TensorRegionConsumer& consumer,
                                TensorPackReport* report, const ndf::PyramidProgress& progress,
                                const std::atomic<bool>* cancel) {
  return packBuiltPyramid(pyramid, options, nullptr, &consumer, report, cancel,
                          [&](ndf::PyramidSink& sink, ndf::PyramidReport& built) {
                            return ndf::buildNdfPyramid(map, pyramid, sink, &built, progress, cancel);
                          });
}

BakeStatus packTensorNdfFromSource(const ndf::FootprintImageSource& source, const ndf::PyramidOptions& pyramid,
                                   const TensorPackOptions& options, format::Writer& writer, TensorPackReport* report,
                                   const ndf::PyramidProgress& progress, const std::atomic<bool>* cancel) {
  return packBuiltPyramid(pyramid, options, &writer, nullptr, report, cancel,
                          [&](ndf::PyramidSink& sink, ndf::PyramidReport& built) {
                            return ndf::buildNdfPyramid(source, pyramid, sink, &built, progress, cancel);
                          });
}

BakeStatus packTensorNdfFromPyramid(const format::Reader& reader, const TensorPackOptions& options,
                                    format::Writer& writer, TensorPackReport* report, const std::atomic<bool>* cancel) {
  const auto t0 = Clock::now();
  if (BakeStatus s = validateTensorPackOptions(options); !s) return s;
  if (reader.kind() != format::AssetKind::kNdfPyramid) {
    return invalidPyramidInput(std::string("not an ndf-pyramid container (asset kind ") +
                               format::assetKindString(reader.kind()) + ")");
  }
  TensorPackReport local;
  TensorPackReport& rep = report ? *report : local;
  rep = TensorPackReport{};
  return inArena(options.threads, [&]() -> BakeStatus {
    TensorAssembler assembler(writer, options, rep);
    detail::TensorPackSink sink(assembler, options, rep, cancel, &writer);
    std::vector<uint8_t> bytes;
    std::vector<float> chunk_buffer;
    format::NdfLevelRecord below;
    int level = 0;
    for (;; ++level) {
      const int li = reader.find(format::kSectionNdfLevel, uint64_t(level));
      if (li < 0) break;
      if (level >= ndf::kMaxPyramidLevels)
        return invalidPyramidInput("more than " + std::to_string(ndf::kMaxPyramidLevels) + " levels");
      if (reader.sections()[size_t(li)].raw_size != sizeof(format::NdfLevelRecord)) {
        return invalidPyramidInput("ndf-level " + std::to_string(level) + ": wrong section size");
      }
      if (format::ContainerStatus st = reader.readSection(size_t(li), &bytes); st != format::ContainerStatus::kOk) {
        return readError("ndf-level " + std::to_string(level), st);
      }
      format::NdfLevelRecord rec;
      std::memcpy(&rec, bytes.data(), sizeof(rec));
      if (BakeStatus s = checkLevelRecord(rec, level, level > 0 ? &below : nullptr); !s) return s;
      below = rec;
      const int first_res = int(rec.ndf_res);
      if (first_res % options.block != 0) {
        return makeError(ErrorCode::kBadArgument, "--block " + std::to_string(options.block) +
                                                      " must divide the pyramid's NDF resolution " +
                                                      std::to_string(first_res));
      }
      if (BakeStatus s = sink.addLevel(rec); !s) return s;

      const size_t image_floats = size_t(rec.ndf_res) * rec.ndf_res;
      const int regions = int(rec.regions_x * rec.regions_y);
      for (int r = 0; r < regions; ++r) {
        const int rx = r % int(rec.regions_x), ry = r / int(rec.regions_x);
        ndf::PyramidChunk chunk;
        chunk.level = level;
        chunk.region = r;
        chunk.x0 = rx * int(rec.region_size);
        chunk.y0 = ry * int(rec.region_size);
        chunk.width = std::min(int(rec.region_size), int(rec.grid_width) - chunk.x0);
        chunk.height = std::min(int(rec.region_size), int(rec.grid_height) - chunk.y0);
        chunk.ndf_res = int(rec.ndf_res);
        const std::string what = "ndf-chunk " + std::to_string(r) + " of level " + std::to_string(level);
        const int ci = reader.find(format::kSectionNdfChunk, format::ndfChunkKey(uint32_t(level), uint64_t(r)));
        if (ci < 0) return invalidPyramidInput("missing " + what);
        const size_t layers = size_t(chunk.width) * size_t(chunk.height);
        const size_t expected = sizeof(format::ImageSectionHeader) + layers * image_floats * sizeof(float);
        if (reader.sections()[size_t(ci)].raw_size != expected)
          return invalidPyramidInput(what + ": wrong section size");
        try {
          chunk_buffer.resize(expected / sizeof(float));
        } catch (const std::bad_alloc&) {
          return makeError(ErrorCode::kRuntime, "out of memory reading " + what);
        }
        if (format::ContainerStatus st = reader.readSectionInto(size_t(ci), chunk_buffer.data(), expected);
            st != format::ContainerStatus::kOk) {
          return readError(what, st);
        }
        format::ImageSectionHeader header;
        std::memcpy(static_cast<void*>(&header), chunk_buffer.data(), sizeof(header));
        if (header.magic != format::ImageSectionHeader{}.magic || header.width != rec.ndf_res ||
            header.height != rec.ndf_res || header.channels != 1 || header.layers != layers) {
          return invalidPyramidInput(what + ": image header disagrees with the level");
        }
        const float* images = chunk_buffer.data() + sizeof(header) / sizeof(float);
        for (size_t n = 0; n < layers * image_floats; ++n) {
          if (!std::isfinite(images[n])) return invalidPyramidInput(what + ": non-finite NDF value");
        }
        chunk.images = images;
        chunk.section = chunk_buffer.data();
        chunk.section_bytes = expected;
        if (BakeStatus s = sink.addChunk(chunk); !s) return s;
      }
      if (BakeStatus s = sink.endLevel(level); !s) return s;
    }
    if (level == 0) return invalidPyramidInput("the container has no ndf-level sections");
    if (BakeStatus s = sink.finish(); !s) return s;
    if (BakeStatus s = assembler.finish(); !s) return s;
    rep.total_seconds = secondsSince(t0);
    rep.ndf_seconds = rep.total_seconds - sink.secondsInside();
    return okStatus();
  });
}

}  // namespace glintbake::bake::tensor
