// SPDX-License-Identifier: Apache-2.0
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
#include <optional>

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
    format::NdfBlendLevel part;
    blend.bilinearLevel(0, 1.0, (i + 0.5) * geo.stride_x, (j + 0.5) * geo.stride_y, &part);
    part.forEach(emit);
    s.prediction.assign(image_floats, 0.0);
  }
  return samples;
}

}  // namespace

BakeStatus validatePyramidOptions(const PyramidOptions& o) {
  auto bad = [](const std::string& m) { return BakeStatus(makeError(ErrorCode::kBadArgument, m)); };
  if (o.splat.ndf_res < 2 || o.splat.ndf_res > 4096) return bad("--ndf-res must be in [2, 4096]");
  if (!(o.splat.sigma_r > 0.0 && o.splat.sigma_r <= 1.0)) return bad("--sigma-r must be in (0, 1]");
  if (!(o.splat.footprint_truncation >= 1.0 && o.splat.footprint_truncation <= 10.0))
    return bad("--footprint-truncation must be in [1, 10]");
  if (!(o.splat.lobe_truncation >= 2.0 && o.splat.lobe_truncation <= 10.0))
    return bad("lobe truncation must be in [2, 10]");
  if (o.rate < 1 || o.rate > kMaxFlakeRate) return bad("--rate must be in [1, " + std::to_string(kMaxFlakeRate) + "]");
  if (!(o.stride0 > 0.0 && o.stride0 <= 1e6)) return bad("--stride must be positive");
  if (!(o.sigma0 > 0.0 && o.sigma0 <= 1e6)) return bad("--sigma0 must be positive");
  if (o.levels < 0 || o.levels > kMaxPyramidLevels)
    return bad("--levels must be auto or in [1, " + std::to_string(kMaxPyramidLevels) + "]");
  if (!(o.converge_mse > 0.0)) return bad("--converge-mse must be positive");
  if (o.converge_from_grid < 0 || o.converge_from_level < 0) return bad("the convergence grid and level must be >= 0");
  if (o.region_size < 1 || o.region_size > 256) return bad("--region must be in [1, 256]");
  return okStatus();
}

LevelGeometry levelGeometry(int map_width, int map_height, const PyramidOptions& options, int level, bool periodic) {
  LevelGeometry g;
  const double stride = options.stride0 * std::ldexp(1.0, level);
  g.sigma = options.sigma0 * std::ldexp(1.0, level);
  // Centres along an axis of `size` texels: the stride rounded so that they tile the axis; on a
  // periodic axis at least two while the footprint is narrower than kFlatAxisSigma periods.
  auto centres = [&](int size) {
    const int n = std::max(1, int(std::lround(std::min(double(size) / stride, 1e9))));
    return periodic && n < 2 && g.sigma < kFlatAxisSigma * double(size) ? 2 : n;
  };
  g.grid_width = centres(map_width);
  g.grid_height = centres(map_height);
  g.stride_x = double(map_width) / g.grid_width;
  g.stride_y = double(map_height) / g.grid_height;
  g.regions_x = (g.grid_width + options.region_size - 1) / options.region_size;
  g.regions_y = (g.grid_height + options.region_size - 1) / options.region_size;
  return g;
}

BakeStatus WriterPyramidSink::addLevel(const format::NdfLevelRecord& record) {
  if (format::RecordCheck c = format::checkNdfLevelRecord(record, record.level, record.level > 0 ? &below_ : nullptr);
      !c) {
    return makeError(ErrorCode::kRuntime, std::string("level descriptor fails its check: ") + c.detail);
  }
  below_ = record;
  if (format::ContainerStatus st =
          writer_.addSection(format::kSectionNdfLevel, uint64_t(record.level), &record, sizeof(record));
      st != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, std::string("cannot write level descriptor: ") + writer_.errorString(st));
  }
  return okStatus();
}

BakeStatus WriterPyramidSink::addChunk(const PyramidChunk& chunk) {
  const uint64_t key = format::ndfChunkKey(uint32_t(chunk.level), uint64_t(chunk.region));
  if (format::ContainerStatus st =
          writer_.addSection(format::kSectionNdfChunk, key, chunk.section, chunk.section_bytes);
      st != format::ContainerStatus::kOk) {
    return makeError(ErrorCode::kIo, std::string("cannot write NDF chunk: ") + writer_.errorString(st));
  }
  return okStatus();
}

BakeStatus ShardPyramidSink::addLevel(const format::NdfLevelRecord& record) {
  if (format::RecordCheck c = format::checkNdfLevelRecord(record, record.level, record.level > 0 ? &below_ : nullptr);
      !c) {
    return makeError(ErrorCode::kRuntime, std::string("level descriptor fails its check: ") + c.detail);
  }
  below_ = record;
  return partial_.add(format::kSectionNdfLevel, uint64_t(record.level), &record, sizeof(record), /*common=*/true);
}

BakeStatus ShardPyramidSink::addChunk(const PyramidChunk& chunk) {
  const uint64_t key = format::ndfChunkKey(uint32_t(chunk.level), uint64_t(chunk.region));
  return partial_.add(format::kSectionNdfChunk, key, chunk.section, chunk.section_bytes);
}

BakeStatus ShardPyramidSink::skipChunk(int, int) {
  partial_.skip();
  return okStatus();
}

BakeStatus buildNdfPyramid(const NormalMap& map, const PyramidOptions& options, format::Writer& writer,
                           PyramidReport* report, const PyramidProgress& progress, const std::atomic<bool>* cancel) {
  WriterPyramidSink sink(writer);
  return buildNdfPyramid(map, options, sink, report, progress, cancel);
}

namespace {

// One build of a pyramid, stage by stage: the level plan (geometry, record, convergence samples),
// the convergence probe, and the region pipeline (images computed in parallel, region r + 1 while
// region r is in the sink). Every image is computed by one thread, or, for footprints with very
// many flakes, as kSplitParts row sets summed in a fixed order, so results never depend on the
// thread count.
class PyramidBuild {
 public:
  PyramidBuild(const NormalMap& map, const PyramidOptions& options, PyramidSink& sink, PyramidReport& report,
               const PyramidProgress& progress, const std::atomic<bool>* cancel,
               const FootprintImageSource* source = nullptr)
      : map_(map),
        source_(source),
        options_(options),
        sink_(sink),
        rep_(report),
        progress_(progress),
        cancel_(cancel),
        res_(options.splat.ndf_res),
        image_floats_(size_t(res_) * size_t(res_)) {}

  BakeStatus run();

 private:
  // The level being built: its plan and its convergence samples.
  struct Level {
    int level = 0;
    LevelGeometry geo;
    format::NdfLevelRecord rec;
    bool split = false;                      // footprints split over kSplitParts row sets
    FootprintPartition partition;            // the level's partition-of-unity factors (splat.h)
    std::vector<Sample> samples;             // of this level, predicted from the level below
    std::vector<Sample> next;                // of the next level, predicted from this one
    std::vector<std::vector<float>> probed;  // images of `samples`, computed by the probe
    Clock::time_point start;                 // when the level's plan was made (the probe counts)
    uint64_t bytes_before = 0;               // sink bytes before the level
  };

  bool cancelled() const { return cancel_ && cancel_->load(std::memory_order_relaxed); }
  // Footprints of the map's flakes wrap around it (levelGeometry's periodic axes).
  bool periodic() const { return !source_ && map_.wrap == Wrap::kRepeat; }
  // Whether a level of one centre is the last: on a clamped normal map only once its footprint is
  // nearly flat over the map (kClampedFlatSigma), since wider footprints get that image's shape.
  bool lastSingleCentre(const LevelGeometry& geo) const {
    if (geo.grid_width != 1 || geo.grid_height != 1) return false;
    if (source_ || map_.wrap == Wrap::kRepeat) return true;
    return geo.sigma >= kClampedFlatSigma * double(std::max(map_.width, map_.height));
  }
  static BakeStatus cancelError() { return makeError(ErrorCode::kRuntime, "cancelled"); }

  BakeStatus prepare();
  BakeStatus allocateBuffers();
  Level planLevel(int level, std::vector<Sample> samples);
  // Computes the probe images; *converged when the level below already predicts this one.
  BakeStatus probe(Level& lv, bool* converged);
  BakeStatus buildLevel(Level& lv);
  void computeImage(const Level& lv, int i, int j, float* out);
  void computeRegion(const Level& lv, int r, int slot);
  void regionExtent(const Level& lv, int r, int* cx0, int* cy0, int* cw, int* ch) const;
  const float* probedImage(const Level& lv, int centre) const;
  PyramidChunk chunkOf(const Level& lv, int r, std::vector<float>& buf) const;
  void collectSamples(Level& lv, const PyramidChunk& chunk, double* mse_sum) const;
  bool ownsRegion(const Level& lv, int r) const {
    return !options_.region_filter || options_.region_filter(lv.level, r);
  }
  bool probesNext(const Level& lv) const;
  void sampleRegion(Level& lv, int r);

  const NormalMap& map_;  // geometry only (no normals) when source_ is set
  const FootprintImageSource* source_;
  const PyramidOptions& options_;
  PyramidSink& sink_;
  PyramidReport& rep_;
  const PyramidProgress& progress_;
  const std::atomic<bool>* cancel_;
  const int res_;
  const size_t image_floats_;
  std::optional<FlakeSet> flakes_;
  std::optional<tbb::enumerable_thread_specific<Splatter>> splatters_;
  std::vector<float> buffers_[2];              // chunk buffers: 32-byte image section header (8 floats), then images
  std::vector<std::vector<double>> part_acc_;  // row-set sums of a split footprint
};

BakeStatus PyramidBuild::prepare() {
  if (source_) return allocateBuffers();
  const auto t_flakes = Clock::now();
  Result<FlakeSet> flakes_or = buildFlakes(map_, options_.rate);
  if (!flakes_or) return flakes_or.error();
  flakes_.emplace(std::move(flakes_or).value());
  rep_.flakes = uint64_t(flakes_->grid_width) * uint64_t(flakes_->grid_height);
  rep_.flake_seconds = secondsSince(t_flakes);
  splatters_.emplace(*flakes_, options_.splat);
  return allocateBuffers();
}

BakeStatus PyramidBuild::allocateBuffers() {
  const size_t max_layers = size_t(options_.region_size) * size_t(options_.region_size);
  try {
    buffers_[0].resize(8 + max_layers * image_floats_);
    buffers_[1].resize(8 + max_layers * image_floats_);
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory allocating chunk buffers");
  }
  part_acc_.assign(static_cast<size_t>(kSplitParts), std::vector<double>(image_floats_));
  return okStatus();
}

// Level plan. Samples of THIS level compare its images with the prediction the runtime makes from
// the level below (collected while that level was written); samples of the NEXT level collect the
// prediction from this level's images.
PyramidBuild::Level PyramidBuild::planLevel(int level, std::vector<Sample> samples) {
  Level lv;
  lv.start = Clock::now();
  lv.bytes_before = sink_.storedBytes();
  lv.level = level;
  lv.geo = levelGeometry(map_.width, map_.height, options_, level, periodic());
  lv.rec = levelRecord(map_, options_, level, lv.geo);
  lv.samples = std::move(samples);
  lv.next = planSamples(levelGeometry(map_.width, map_.height, options_, level + 1, periodic()), lv.rec, image_floats_);
  // Footprints with very many flakes (the top levels: few images, each costing up to several
  // map's worth of flakes) are split; the split depends only on the level.
  lv.split = !source_ && splatters_->local().flakesPerImage(lv.geo.sigma) > kSplitFlakes;
  if (!source_ && flakes_) {
    lv.partition = footprintPartition(*flakes_, lv.geo.sigma, lv.geo.grid_width, lv.geo.stride_x, lv.geo.grid_height,
                                      lv.geo.stride_y);
  }
  return lv;
}

// Image of centre (i, j) of the level. Split footprints use the shared part buffers: call those
// from one thread at a time.
void PyramidBuild::computeImage(const Level& lv, int i, int j, float* out) {
  const double x = (i + 0.5) * lv.geo.stride_x, y = (j + 0.5) * lv.geo.stride_y;
  if (source_) {
    source_->image(x, y, lv.geo.sigma, out);
    return;
  }
  if (!lv.split) {
    splatters_->local().image(x, y, lv.geo.sigma, out, &lv.partition);
    return;
  }
  tbb::parallel_for(0, kSplitParts, [&](int part) {
    std::vector<double>& acc = part_acc_[size_t(part)];
    std::fill(acc.begin(), acc.end(), 0.0);
    splatters_->local().accumulate(x, y, lv.geo.sigma, part, kSplitParts, acc.data(), &lv.partition);
  });
  for (int part = 1; part < kSplitParts; ++part) {
    for (size_t b = 0; b < image_floats_; ++b) part_acc_[0][b] += part_acc_[size_t(part)][b];
  }
  splatters_->local().finish(part_acc_[0].data(), out);
}

// Automatic level count: the level is probed at its convergence samples before it is computed. If
// the runtime's prediction from the level below is already within converge_mse there, the level
// would add little (queries above the top clamp to the level below), so it is not computed at all.
// Otherwise the probed images are reused when their regions are computed.
BakeStatus PyramidBuild::probe(Level& lv, bool* converged) {
  *converged = false;
  if (options_.levels != 0 || lv.samples.empty()) return okStatus();
  if (lv.level - 1 < options_.converge_from_level) return okStatus();
  if (options_.converge_from_grid > 0 && lv.level > 0) {
    const LevelGeometry below = levelGeometry(map_.width, map_.height, options_, lv.level - 1, periodic());
    if (std::max(below.grid_width, below.grid_height) > options_.converge_from_grid) return okStatus();
  }
  try {
    lv.probed.assign(lv.samples.size(), std::vector<float>(image_floats_));
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory allocating convergence samples");
  }
  auto one = [&](size_t q) {
    const int centre = lv.samples[q].centre;
    computeImage(lv, centre % lv.geo.grid_width, centre / lv.geo.grid_width, lv.probed[q].data());
  };
  if (lv.split) {
    for (size_t q = 0; q < lv.samples.size(); ++q) one(q);
  } else {
    tbb::parallel_for(size_t(0), lv.samples.size(), one);
  }
  if (cancelled()) return cancelError();
  double probe_mse = 0.0;
  for (size_t q = 0; q < lv.samples.size(); ++q) {
    probe_mse += relativeMse(lv.probed[q].data(), lv.samples[q].prediction.data(), image_floats_);
  }
  probe_mse /= double(lv.samples.size());
  if (probe_mse < options_.converge_mse) {
    rep_.stop_reason = "converged";
    rep_.next_level_mse = probe_mse;
    *converged = true;
  }
  return okStatus();
}

const float* PyramidBuild::probedImage(const Level& lv, int centre) const {
  for (size_t q = 0; q < lv.probed.size(); ++q) {
    if (lv.samples[q].centre == centre) return lv.probed[q].data();
  }
  return nullptr;
}

void PyramidBuild::regionExtent(const Level& lv, int r, int* cx0, int* cy0, int* cw, int* ch) const {
  const int rx = r % lv.geo.regions_x, ry = r / lv.geo.regions_x;
  *cx0 = rx * options_.region_size;
  *cy0 = ry * options_.region_size;
  *cw = std::min(options_.region_size, lv.geo.grid_width - *cx0);
  *ch = std::min(options_.region_size, lv.geo.grid_height - *cy0);
}

// Computes the images of region r into buffers_[slot] (probed images are copied).
void PyramidBuild::computeRegion(const Level& lv, int r, int slot) {
  int cx0, cy0, cw, ch;
  regionExtent(lv, r, &cx0, &cy0, &cw, &ch);
  float* images = buffers_[slot].data() + 8;
  auto one = [&](int k) {
    const int i = cx0 + k % cw, j = cy0 + k / cw;
    float* out = images + size_t(k) * image_floats_;
    if (const float* probed = probedImage(lv, j * lv.geo.grid_width + i)) {
      std::memcpy(out, probed, image_floats_ * sizeof(float));
    } else {
      computeImage(lv, i, j, out);
    }
  };
  if (lv.split) {
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
}

// The finished region r in `buf` as a chunk: its image section header written in front.
PyramidChunk PyramidBuild::chunkOf(const Level& lv, int r, std::vector<float>& buf) const {
  int cx0, cy0, cw, ch;
  regionExtent(lv, r, &cx0, &cy0, &cw, &ch);
  format::ImageSectionHeader header;
  header.width = uint32_t(res_);
  header.height = uint32_t(res_);
  header.channels = 1;
  header.layers = uint32_t(cw * ch);
  std::memcpy(buf.data(), &header, sizeof(header));
  PyramidChunk chunk;
  chunk.level = lv.level;
  chunk.region = r;
  chunk.x0 = cx0;
  chunk.y0 = cy0;
  chunk.width = cw;
  chunk.height = ch;
  chunk.ndf_res = res_;
  chunk.images = buf.data() + 8;
  chunk.section = buf.data();
  chunk.section_bytes = sizeof(header) + size_t(cw * ch) * image_floats_ * sizeof(float);
  return chunk;
}

// Convergence bookkeeping of one written chunk: the MSE of this level's samples, and this level's
// share of the next level's predictions.
void PyramidBuild::collectSamples(Level& lv, const PyramidChunk& chunk, double* mse_sum) const {
  for (int k = 0; k < chunk.width * chunk.height; ++k) {
    const int centre = (chunk.y0 + k / chunk.width) * lv.geo.grid_width + (chunk.x0 + k % chunk.width);
    const float* img = chunk.images + size_t(k) * image_floats_;
    for (Sample& smp : lv.samples) {
      if (smp.centre == centre) *mse_sum += relativeMse(img, smp.prediction.data(), image_floats_);
    }
    for (Sample& smp : lv.next) {
      for (int q = 0; q < 4; ++q) {
        if (smp.below[q] != centre || smp.weight[q] == 0.0) continue;
        for (size_t b = 0; b < image_floats_; ++b) smp.prediction[b] += smp.weight[q] * double(img[b]);
      }
    }
  }
}

// The region pipeline of one level: region r + 1 is computed while region r is in the sink.
// Whether probe() will run for the level above lv (the same tests, from the geometry alone).
bool PyramidBuild::probesNext(const Level& lv) const {
  if (options_.levels != 0 || lv.next.empty()) return false;
  if (lv.level < options_.converge_from_level) return false;
  if (options_.converge_from_grid > 0 && std::max(lv.geo.grid_width, lv.geo.grid_height) > options_.converge_from_grid)
    return false;
  return true;
}

// A region another shard computes: only the images of its centres that the next level's probe
// predicts from, added to the predictions in the order collectSamples adds them (so the sums are
// those of the whole bake, bit for bit). Sequential: split footprints share part_acc_.
void PyramidBuild::sampleRegion(Level& lv, int r) {
  if (!probesNext(lv)) return;
  int cx0, cy0, cw, ch;
  regionExtent(lv, r, &cx0, &cy0, &cw, &ch);
  std::vector<float> image;
  for (int k = 0; k < cw * ch; ++k) {
    const int i = cx0 + k % cw, j = cy0 + k / cw;
    const int centre = j * lv.geo.grid_width + i;
    bool needed = false;
    for (const Sample& smp : lv.next) {
      for (int q = 0; q < 4; ++q) needed = needed || (smp.below[q] == centre && smp.weight[q] != 0.0);
    }
    if (!needed) continue;
    const float* img = probedImage(lv, centre);
    if (!img) {
      image.resize(image_floats_);
      computeImage(lv, i, j, image.data());
      img = image.data();
    }
    for (Sample& smp : lv.next) {
      for (int q = 0; q < 4; ++q) {
        if (smp.below[q] != centre || smp.weight[q] == 0.0) continue;
        for (size_t b = 0; b < image_floats_; ++b) smp.prediction[b] += smp.weight[q] * double(img[b]);
      }
    }
  }
}

BakeStatus PyramidBuild::buildLevel(Level& lv) {
  PyramidLevelReport lrep;
  lrep.level = lv.level;
  lrep.geometry = lv.geo;
  if (BakeStatus s = sink_.addLevel(lv.rec); !s) return s;

  const int region_count = lv.geo.regions_x * lv.geo.regions_y;
  const uint64_t level_images = uint64_t(lv.geo.grid_width) * uint64_t(lv.geo.grid_height);
  uint64_t done = 0;
  double mse_sum = 0.0;
  if (ownsRegion(lv, 0)) computeRegion(lv, 0, 0);
  for (int r = 0; r < region_count; ++r) {
    if (cancelled()) return cancelError();
    const bool owns_next = r + 1 < region_count && ownsRegion(lv, r + 1);
    if (!ownsRegion(lv, r)) {
      if (BakeStatus s = sink_.skipChunk(lv.level, r); !s) return s;
      sampleRegion(lv, r);
      if (owns_next) computeRegion(lv, r + 1, (r + 1) % 2);
      continue;
    }
    tbb::task_group next;
    if (owns_next) next.run([&, r] { computeRegion(lv, r + 1, (r + 1) % 2); });
    const PyramidChunk chunk = chunkOf(lv, r, buffers_[r % 2]);
    BakeStatus sunk = sink_.addChunk(chunk);
    next.wait();
    if (!sunk) return sunk;
    collectSamples(lv, chunk, &mse_sum);
    const uint64_t images = uint64_t(chunk.width * chunk.height);
    lrep.raw_bytes += chunk.section_bytes;
    lrep.images += images;
    done += images;
    if (progress_) progress_(lv.level, done, level_images);
  }
  if (!lv.samples.empty()) lrep.mse_vs_previous = mse_sum / double(lv.samples.size());
  if (BakeStatus s = sink_.endLevel(lv.level); !s) return s;
  lrep.stored_bytes = sink_.storedBytes() - lv.bytes_before;
  lrep.seconds = secondsSince(lv.start);
  rep_.levels.push_back(lrep);
  return okStatus();
}

BakeStatus PyramidBuild::run() {
  if (BakeStatus s = prepare(); !s) return s;
  const int max_levels = options_.levels > 0 ? options_.levels : kMaxPyramidLevels;
  std::vector<Sample> samples;  // level 0 has no level below
  for (int level = 0; level < max_levels; ++level) {
    if (cancelled()) return cancelError();
    Level lv = planLevel(level, std::move(samples));
    bool converged = false;
    if (BakeStatus s = probe(lv, &converged); !s || converged) return s;
    if (BakeStatus s = buildLevel(lv); !s) return s;
    if (options_.levels == 0 && lastSingleCentre(lv.geo)) {
      rep_.stop_reason = "grid-1x1";
      return okStatus();
    }
    samples = std::move(lv.next);
  }
  rep_.stop_reason = options_.levels > 0 ? "levels" : "max-levels";
  return okStatus();
}

}  // namespace

BakeStatus buildNdfPyramid(const NormalMap& map, const PyramidOptions& options, PyramidSink& sink,
                           PyramidReport* report, const PyramidProgress& progress, const std::atomic<bool>* cancel) {
  if (BakeStatus s = validatePyramidOptions(options); !s) return s;
  PyramidReport local_report;
  PyramidReport& rep = report ? *report : local_report;
  rep = PyramidReport{};
  PyramidBuild build(map, options, sink, rep, progress, cancel);
  return build.run();
}

BakeStatus buildNdfPyramid(const FootprintImageSource& source, const PyramidOptions& options, PyramidSink& sink,
                           PyramidReport* report, const PyramidProgress& progress, const std::atomic<bool>* cancel) {
  if (BakeStatus s = validatePyramidOptions(options); !s) return s;
  NormalMap geometry;  // the level records need the surface's size and wrap only
  source.mapSize(&geometry.width, &geometry.height);
  geometry.wrap = source.wrap();
  PyramidReport local_report;
  PyramidReport& rep = report ? *report : local_report;
  rep = PyramidReport{};
  PyramidBuild build(geometry, options, sink, rep, progress, cancel, &source);
  return build.run();
}

BakeStatus buildNdfPyramid(const FootprintImageSource& source, const PyramidOptions& options, format::Writer& writer,
                           PyramidReport* report, const PyramidProgress& progress, const std::atomic<bool>* cancel) {
  WriterPyramidSink sink(writer);
  return buildNdfPyramid(source, options, sink, report, progress, cancel);
}

}  // namespace glintbake::bake::ndf
