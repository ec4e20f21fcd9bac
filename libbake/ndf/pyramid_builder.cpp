#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/format/kinds/ndf_pyramid_blend.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <new>

namespace glintbake::bake::ndf {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kConvergenceSamplesPerAxis = 4;
constexpr int kSplitParts = 16;           // row sets of a split footprint
constexpr double kSplitFlakes = 1 << 18;  // split footprints with more flakes than this

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Relative MSE of image a against b: sum (a - b)^2 / sum b^2 (0 when both vanish).
double relativeMse(const float* a, const double* b, size_t n) {
  double num = 0.0, den = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double d = double(a[i]) - double(b[i]);
    num += d * d;
    den += double(b[i]) * double(b[i]);
  }
  return den > 0.0 ? num / den : (num > 0.0 ? 1.0 : 0.0);
}

// A convergence sample: one centre of a level and the runtime's prediction of its image from the
// level below (the bilinear blend of up to 4 centres of that level, format::NdfPyramidBlend).
struct Sample {
  int centre = 0;                   // index j * grid_width + i on its own level
  int below[4] = {-1, -1, -1, -1};  // centres of the level below
  double weight[4] = {0, 0, 0, 0};
  std::vector<double> prediction;  // R * R, accumulated while the level below is written
};

// The level record of level `level` (its geometry from levelGeometry).
format::NdfLevelRecord levelRecord(const NormalMap& map, const PyramidOptions& options, int level,
                                   const LevelGeometry& geo) {
  format::NdfLevelRecord rec;
  rec.level = uint32_t(level);
  rec.ndf_res = uint32_t(options.splat.ndf_res);
  rec.grid_width = uint32_t(geo.grid_width);
  rec.grid_height = uint32_t(geo.grid_height);
  rec.region_size = uint32_t(options.region_size);
  rec.regions_x = uint32_t(geo.regions_x);
  rec.regions_y = uint32_t(geo.regions_y);
  rec.wrap = map.wrap == Wrap::kRepeat ? 0u : 1u;
  rec.map_width = uint32_t(map.width);
  rec.map_height = uint32_t(map.height);
  rec.rate = uint32_t(options.rate);
  rec.stride_x = geo.stride_x;
  rec.stride_y = geo.stride_y;
  rec.origin_x = 0.5 * geo.stride_x;
  rec.origin_y = 0.5 * geo.stride_y;
  rec.sigma_texels = geo.sigma;
  rec.sigma_r = options.splat.sigma_r;
  return rec;
}

// Up to kConvergenceSamplesPerAxis^2 evenly spread centres of level `geo`, with their neighbours
// on the level below (`below`), weighted as the runtime's footprint blend weighs them.
std::vector<Sample> planSamples(const LevelGeometry& geo, const format::NdfLevelRecord& below, size_t image_floats) {
  format::NdfPyramidBlend blend;
  blend.init(&below, 1);
  int nsx = std::min(geo.grid_width, kConvergenceSamplesPerAxis);
  int nsy = std::min(geo.grid_height, kConvergenceSamplesPerAxis);
  // At most a quarter of the level's centres (at least one): the level is probed before it is
  // computed, and the probe of a level that turns out converged is work thrown away.
  while (4 * nsx * nsy > geo.grid_width * geo.grid_height && (nsx > 1 || nsy > 1)) {
    if (nsx >= nsy) {
      --nsx;
    } else {
      --nsy;
    }
  }
  std::vector<Sample> samples(size_t(nsx) * size_t(nsy));
  for (int k = 0; k < nsx * nsy; ++k) {
    Sample& s = samples[size_t(k)];
    const int i = int((k % nsx + 0.5) * geo.grid_width / nsx);
    const int j = int((k / nsx + 0.5) * geo.grid_height / nsy);
    s.centre = j * geo.grid_width + i;
    int q = 0;
    auto emit = [&](int, size_t centre, double weight) {
      s.below[q] = int(centre);
      s.weight[q] = weight;
      ++q;
    };
    blend.blendLevel(0, 1.0, (i + 0.5) * geo.stride_x, (j + 0.5) * geo.stride_y, emit);
    s.prediction.assign(image_floats, 0.0);
  }
  return samples;
}

}  // namespace

Status validatePyramidOptions(const PyramidOptions& o) {
  auto bad = [](const std::string& m) { return Status(makeError(ErrorCode::kBadArgument, m)); };
  if (o.splat.ndf_res < 2 || o.splat.ndf_res > 4096) return bad("--ndf-res must be in [2, 4096]");
  if (!(o.splat.sigma_r > 0.0 && o.splat.sigma_r <= 1.0)) return bad("--sigma-r must be in (0, 1]");
  if (!(o.splat.footprint_truncation >= 1.0 && o.splat.footprint_truncation <= 10.0))
    return bad("footprint truncation must be in [1, 10]");
  if (!(o.splat.lobe_truncation >= 2.0 && o.splat.lobe_truncation <= 10.0))
    return bad("lobe truncation must be in [2, 10]");
  if (o.rate < 1 || o.rate > kMaxFlakeRate) return bad("--rate must be in [1, " + std::to_string(kMaxFlakeRate) + "]");
  if (!(o.stride0 > 0.0 && o.stride0 <= 1e6)) return bad("--stride must be positive");
  if (!(o.sigma0 > 0.0 && o.sigma0 <= 1e6)) return bad("--sigma0 must be positive");
  if (o.levels < 0 || o.levels > kMaxPyramidLevels)
    return bad("--levels must be auto or in [1, " + std::to_string(kMaxPyramidLevels) + "]");
  if (!(o.converge_mse > 0.0)) return bad("--converge-mse must be positive");
  if (o.region_size < 1 || o.region_size > 256) return bad("--region must be in [1, 256]");
  return okStatus();
}

LevelGeometry levelGeometry(int map_width, int map_height, const PyramidOptions& options, int level) {
  LevelGeometry g;
  const double stride = options.stride0 * std::ldexp(1.0, level);
  g.grid_width = std::max(1, int(std::lround(std::min(double(map_width) / stride, 1e9))));
  g.grid_height = std::max(1, int(std::lround(std::min(double(map_height) / stride, 1e9))));
  g.stride_x = double(map_width) / g.grid_width;
  g.stride_y = double(map_height) / g.grid_height;
  g.sigma = options.sigma0 * std::ldexp(1.0, level);
  g.regions_x = (g.grid_width + options.region_size - 1) / options.region_size;
  g.regions_y = (g.grid_height + options.region_size - 1) / options.region_size;
  return g;
}

Status WriterPyramidSink::addLevel(const format::NdfLevelRecord& record) {
  if (format::RecordCheck c = format::checkNdfLevelRecord(record, record.level, record.level > 0 ? &below_ : nullptr);
      !c) {
    return makeError(ErrorCode::kRuntime, std::string("level descriptor fails its check: ") + c.detail);
  }
  below_ = record;
  if (format::Status st = writer_.addSection(format::kSectionNdfLevel, uint64_t(record.level), &record, sizeof(record));
      st != format::Status::kOk) {
    return makeError(ErrorCode::kIo, std::string("cannot write level descriptor: ") + format::statusString(st));
  }
  return okStatus();
}

Status WriterPyramidSink::addChunk(const PyramidChunk& chunk) {
  const uint64_t key = format::ndfChunkKey(uint32_t(chunk.level), uint64_t(chunk.region));
  if (format::Status st = writer_.addSection(format::kSectionNdfChunk, key, chunk.section, chunk.section_bytes);
      st != format::Status::kOk) {
    return makeError(ErrorCode::kIo, std::string("cannot write NDF chunk: ") + format::statusString(st));
  }
  return okStatus();
}

Status buildNdfPyramid(const NormalMap& map, const PyramidOptions& options, format::Writer& writer,
                       PyramidReport* report, const PyramidProgress& progress, const std::atomic<bool>* cancel) {
  WriterPyramidSink sink(writer);
  return buildNdfPyramid(map, options, sink, report, progress, cancel);
}

Status buildNdfPyramid(const NormalMap& map, const PyramidOptions& options, PyramidSink& sink, PyramidReport* report,
                       const PyramidProgress& progress, const std::atomic<bool>* cancel) {
  if (Status s = validatePyramidOptions(options); !s) return s;
  PyramidReport local_report;
  PyramidReport& rep = report ? *report : local_report;
  rep = PyramidReport{};

  const auto t_flakes = Clock::now();
  Result<FlakeSet> flakes_or = buildFlakes(map, options.rate);
  if (!flakes_or) return flakes_or.error();
  const FlakeSet& flakes = flakes_or.value();
  rep.flakes = uint64_t(flakes.grid_width) * uint64_t(flakes.grid_height);
  rep.flake_seconds = secondsSince(t_flakes);

  const int res = options.splat.ndf_res;
  const size_t image_floats = size_t(res) * size_t(res);
  tbb::enumerable_thread_specific<Splatter> splatters(flakes, options.splat);
  auto cancelled = [&] { return cancel && cancel->load(std::memory_order_relaxed); };
  auto cancelError = [] { return Status(makeError(ErrorCode::kRuntime, "cancelled")); };

  // Chunk buffers: 32-byte image section header (8 floats) followed by the images.
  const size_t max_layers = size_t(options.region_size) * size_t(options.region_size);
  std::vector<float> buffers[2];
  try {
    buffers[0].resize(8 + max_layers * image_floats);
    buffers[1].resize(8 + max_layers * image_floats);
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory allocating chunk buffers");
  }

  std::vector<std::vector<double>> part_acc(static_cast<size_t>(kSplitParts), std::vector<double>(image_floats));
  const int max_levels = options.levels > 0 ? options.levels : kMaxPyramidLevels;
  std::vector<Sample> next_samples;  // level-0 has no level below
  for (int level = 0; level < max_levels; ++level) {
    const LevelGeometry geo = levelGeometry(map.width, map.height, options, level);
    if (cancelled()) return cancelError();

    const auto t_level = Clock::now();
    const uint64_t bytes_before = sink.storedBytes();
    PyramidLevelReport lrep;
    lrep.level = level;
    lrep.geometry = geo;

    // Convergence bookkeeping. Samples of THIS level: compare its images with the prediction the
    // runtime makes from the level below (bilinear blend of that level's images, collected while it
    // was written). Samples of the NEXT level: collect the prediction from this level's images.
    std::vector<Sample> samples = std::move(next_samples);
    const format::NdfLevelRecord rec = levelRecord(map, options, level, geo);
    next_samples = planSamples(levelGeometry(map.width, map.height, options, level + 1), rec, image_floats);
    double mse_sum = 0.0;

    // Footprints with very many flakes (the top levels: few images, each costing up to several
    // map's worth of flakes) are split over kSplitParts interleaved row sets computed in parallel
    // and summed in a fixed order; the split depends only on the level, never on the thread count.
    const bool split = splatters.local().flakesPerImage(geo.sigma) > kSplitFlakes;
    // Image of centre (i, j) of this level. Split footprints use the shared part buffers: call those
    // from one thread at a time.
    auto computeImage = [&](int i, int j, float* out) {
      const double x = (i + 0.5) * geo.stride_x, y = (j + 0.5) * geo.stride_y;
      if (!split) {
        splatters.local().image(x, y, geo.sigma, out);
        return;
      }
      tbb::parallel_for(0, kSplitParts, [&](int part) {
        std::vector<double>& acc = part_acc[size_t(part)];
        std::fill(acc.begin(), acc.end(), 0.0);
        splatters.local().accumulate(x, y, geo.sigma, part, kSplitParts, acc.data());
      });
      for (int part = 1; part < kSplitParts; ++part) {
        for (size_t b = 0; b < image_floats; ++b) part_acc[0][b] += part_acc[size_t(part)][b];
      }
      splatters.local().finish(part_acc[0].data(), out);
    };

    // Automatic level count: probe this level at its convergence samples before computing it. If
    // the runtime's prediction from the level below is already within converge_mse there, the
    // level would add little (queries above the top clamp to the level below), so it is not
    // computed at all. Otherwise the probed images are reused when their regions are computed.
    std::vector<std::vector<float>> probe_images;
    if (options.levels == 0 && !samples.empty()) {
      try {
        probe_images.assign(samples.size(), std::vector<float>(image_floats));
      } catch (const std::bad_alloc&) {
        return makeError(ErrorCode::kRuntime, "out of memory allocating convergence samples");
      }
      auto probe = [&](size_t q) {
        const int centre = samples[q].centre;
        computeImage(centre % geo.grid_width, centre / geo.grid_width, probe_images[q].data());
      };
      if (split) {
        for (size_t q = 0; q < samples.size(); ++q) probe(q);
      } else {
        tbb::parallel_for(size_t(0), samples.size(), probe);
      }
      if (cancelled()) return cancelError();
      double probe_mse = 0.0;
      for (size_t q = 0; q < samples.size(); ++q) {
        probe_mse += relativeMse(probe_images[q].data(), samples[q].prediction.data(), image_floats);
      }
      probe_mse /= double(samples.size());
      if (probe_mse < options.converge_mse) {
        rep.stop_reason = "converged";
        rep.next_level_mse = probe_mse;
        return okStatus();
      }
    }
    auto probedImage = [&](int centre) -> const float* {
      for (size_t q = 0; q < probe_images.size(); ++q) {
        if (samples[q].centre == centre) return probe_images[q].data();
      }
      return nullptr;
    };

    if (Status s = sink.addLevel(rec); !s) return s;

    const int region_count = geo.regions_x * geo.regions_y;
    const uint64_t level_images = uint64_t(geo.grid_width) * uint64_t(geo.grid_height);
    uint64_t done = 0;

    // Computes region r into buffers[slot]; returns the number of layers.
    auto regionExtent = [&](int r, int* cx0, int* cy0, int* cw, int* ch) {
      const int rx = r % geo.regions_x, ry = r / geo.regions_x;
      *cx0 = rx * options.region_size;
      *cy0 = ry * options.region_size;
      *cw = std::min(options.region_size, geo.grid_width - *cx0);
      *ch = std::min(options.region_size, geo.grid_height - *cy0);
    };
    auto computeRegion = [&](int r, int slot) {
      int cx0, cy0, cw, ch;
      regionExtent(r, &cx0, &cy0, &cw, &ch);
      float* images = buffers[slot].data() + 8;
      auto one = [&](int k) {
        const int i = cx0 + k % cw, j = cy0 + k / cw;
        float* out = images + size_t(k) * image_floats;
        if (const float* probed = probedImage(j * geo.grid_width + i)) {
          std::memcpy(out, probed, image_floats * sizeof(float));
        } else {
          computeImage(i, j, out);
        }
      };
      if (split) {
        for (int k = 0; k < cw * ch; ++k) {
          if (cancelled()) return;
          one(k);
        }
        return;
      }
      tbb::parallel_for(tbb::blocked_range<int>(0, cw * ch, 1), [&](const tbb::blocked_range<int>& range) {
        for (int k = range.begin(); k != range.end(); ++k) {
          if (cancelled()) return;
          one(k);
        }
      });
    };

    // Double buffering: region r + 1 is computed while region r is compressed and written.
    computeRegion(0, 0);
    for (int r = 0; r < region_count; ++r) {
      if (cancelled()) return cancelError();
      tbb::task_group next;
      if (r + 1 < region_count) next.run([&, r] { computeRegion(r + 1, (r + 1) % 2); });
      int cx0, cy0, cw, ch;
      regionExtent(r, &cx0, &cy0, &cw, &ch);
      format::ImageSectionHeader header;
      header.width = uint32_t(res);
      header.height = uint32_t(res);
      header.channels = 1;
      header.layers = uint32_t(cw * ch);
      std::vector<float>& buf = buffers[r % 2];
      std::memcpy(buf.data(), &header, sizeof(header));
      const size_t bytes = sizeof(header) + size_t(cw * ch) * image_floats * sizeof(float);
      PyramidChunk chunk;
      chunk.level = level;
      chunk.region = r;
      chunk.x0 = cx0;
      chunk.y0 = cy0;
      chunk.width = cw;
      chunk.height = ch;
      chunk.ndf_res = res;
      chunk.images = buf.data() + 8;
      chunk.section = buf.data();
      chunk.section_bytes = bytes;
      Status sunk = sink.addChunk(chunk);
      next.wait();
      if (!sunk) return sunk;
      for (int k = 0; k < cw * ch; ++k) {
        const int centre = (cy0 + k / cw) * geo.grid_width + (cx0 + k % cw);
        const float* img = buf.data() + 8 + size_t(k) * image_floats;
        for (Sample& smp : samples) {
          if (smp.centre == centre) mse_sum += relativeMse(img, smp.prediction.data(), image_floats);
        }
        for (Sample& smp : next_samples) {
          for (int q = 0; q < 4; ++q) {
            if (smp.below[q] != centre || smp.weight[q] == 0.0) continue;
            for (size_t b = 0; b < image_floats; ++b) smp.prediction[b] += smp.weight[q] * double(img[b]);
          }
        }
      }
      lrep.raw_bytes += bytes;
      lrep.images += uint64_t(cw * ch);
      done += uint64_t(cw * ch);
      if (progress) progress(level, done, level_images);
    }
    if (!samples.empty()) lrep.mse_vs_previous = mse_sum / double(samples.size());
    if (Status s = sink.endLevel(level); !s) return s;
    lrep.stored_bytes = sink.storedBytes() - bytes_before;
    lrep.seconds = secondsSince(t_level);
    rep.levels.push_back(lrep);

    if (options.levels == 0 && geo.grid_width == 1 && geo.grid_height == 1) {
      rep.stop_reason = "grid-1x1";
      return okStatus();
    }
  }
  rep.stop_reason = options.levels > 0 ? "levels" : "max-levels";
  return okStatus();
}

}  // namespace glintbake::bake::ndf
