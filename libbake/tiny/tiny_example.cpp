// SPDX-License-Identifier: Apache-2.0
// Tiny examples: records, tile images and the asset's sections (see bake/tiny/tiny_example.h).
#include <glintbake/bake/tiny/tiny_example.h>
#include <glintbake/format/binary16.h>
#include <glintbake/runtime/tiny_example_ndf.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace glintbake::bake::tiny {

namespace {

bool finite2(const double v[2]) { return std::isfinite(v[0]) && std::isfinite(v[1]); }

// Overlapping layouts: for every coverage sample point, the smallest threshold of the examples that
// would cover it (the point is covered at occupancy q when that is below q), sorted.
std::vector<double> coverageThresholds(const format::TinyExampleRecord& r, const format::TinyLayout* layout) {
  const int reach = format::tinyOverlapReach(r);
  const int cells = format::kTinyCoverageCells + 2 * reach, samples = format::kTinyCoverageSamples;
  std::vector<format::TinyPlacement> candidates(size_t(cells) * cells);
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i)
      candidates[size_t(j) * cells + i] = format::tinyCellCandidate(r, i - reach, j - reach, layout);
  const double step = format::kTinyCoverageCells * r.cell_size / samples;
  std::vector<double> out(size_t(samples) * samples);
  tbb::parallel_for(0, samples, [&](int b) {
    double local[2];
    for (int a = 0; a < samples; ++a) {
      const double x = (a + 0.5) * step, y = (b + 0.5) * step;
      const int ci = int(std::floor(x / r.cell_size)), cj = int(std::floor(y / r.cell_size));
      double best = std::numeric_limits<double>::infinity();
      for (int j = cj - reach; j <= cj + reach; ++j)
        for (int i = ci - reach; i <= ci + reach; ++i) {
          const format::TinyPlacement& c = candidates[size_t(j + reach) * cells + size_t(i + reach)];
          if (c.threshold < best && format::tinyContains(r, c, x, y, local)) best = c.threshold;
        }
      out[size_t(b) * samples + a] = best;
    }
  });
  std::sort(out.begin(), out.end());
  return out;
}

// The cell side and occupancy of an overlapping layout for the density (or, with a layout image and
// no density, occupancy 1 and the density it gives): cells of the examples' mean area first, smaller
// ones while the density is out of reach.
BakeStatus chooseOverlapLayout(format::TinyExampleRecord* r, const format::TinyLayout* layout, double density,
                               bool density_given) {
  format::TinyExampleRecord plain = *r;
  plain.flags &= ~format::kTinyFlagOverlap;
  plain.cell_size = 1.0;
  plain.occupancy = 1.0;
  const double mean_area = format::tinyCoveredFraction(plain, nullptr);  // E|det M| n^2
  const double min_cell = format::tinyMinCellSize(*r) / (2.0 * format::kMaxTinyOverlapReach);
  double cell = std::max(min_cell, std::sqrt(mean_area));
  for (int attempt = 0;; ++attempt) {
    r->cell_size = std::ceil(cell * 64.0) / 64.0;
    r->occupancy = 1.0;
    const std::vector<double> t = coverageThresholds(*r, layout);
    const size_t reachable = size_t(std::lower_bound(t.begin(), t.end(), 1.0) - t.begin());
    if (layout && !density_given) {
      if (reachable == 0)
        return makeError(ErrorCode::kInvalidInput, "layout image: presence is 0 in every cell (no example anywhere)");
      r->density = double(reachable) / double(t.size());
      return okStatus();
    }
    const size_t k = size_t(std::ceil(density * double(t.size()) - 1e-9));
    if (k >= 1 && k <= reachable) {
      // Just above the k-th smallest threshold: exactly k sample points covered.
      r->occupancy = std::min(1.0, std::nextafter(t[k - 1], 2.0));
      r->density = density;
      return okStatus();
    }
    if (r->cell_size <= min_cell * (1.0 + 1e-9) || attempt >= 16)
      return makeError(ErrorCode::kBadArgument, "--density " + std::to_string(density) +
                                                    " exceeds the largest covered fraction of this overlapping "
                                                    "layout (" +
                                                    std::to_string(double(reachable) / double(t.size())) + ")");
    cell = std::max(min_cell, cell / 1.25);
  }
}

}  // namespace

Result<format::TinyExampleRecord> makeTinyRecord(int n, int ndf_res, double sigma_r, const TinyPlacementOptions& p) {
  using format::TinyExampleType;
  if (ndf_res < 2 || ndf_res > int(format::kMaxTinyNdfRes))
    return makeError(ErrorCode::kBadArgument, "--ndf-res must be in [2, 1024]");
  if (!(std::isfinite(sigma_r) && sigma_r > 0.0 && sigma_r <= 1.0))
    return makeError(ErrorCode::kBadArgument, "--sigma-r must be in (0, 1]");
  if (!finite2(p.rotate_range) || p.rotate_range[0] > p.rotate_range[1] || std::fabs(p.rotate_range[0]) > 3600.0 ||
      std::fabs(p.rotate_range[1]) > 3600.0)
    return makeError(ErrorCode::kBadArgument, "rotation range must be finite, A <= B, within +-3600 degrees");
  if (!finite2(p.scale_range) || p.scale_range[0] > p.scale_range[1] || p.scale_range[0] < format::kMinTinyScale ||
      p.scale_range[1] > format::kMaxTinyScale)
    return makeError(ErrorCode::kBadArgument, "--scale-range must satisfy 0.125 <= A <= B <= 8");
  if (!finite2(p.shear) || std::fabs(p.shear[0]) > format::kMaxTinyShear ||
      std::fabs(p.shear[1]) > format::kMaxTinyShear || std::fabs(1.0 - p.shear[0] * p.shear[1]) < 1e-3)
    return makeError(ErrorCode::kBadArgument, "--shear must be within +-2 per axis with HX * HY != 1");
  if (!finite2(p.translate) || std::fabs(p.translate[0]) > 1e9 || std::fabs(p.translate[1]) > 1e9)
    return makeError(ErrorCode::kBadArgument, "--translate out of range");
  format::TinyExampleRecord r;
  r.example_size = uint32_t(n);
  while ((2u << r.levels) <= uint32_t(n)) ++r.levels;
  r.ndf_res = uint32_t(ndf_res);
  r.type = uint32_t(p.type);
  r.sigma_r = sigma_r;
  const double mirror[4] = {p.mirror ? -1.0 : 1.0, 0.0, 0.0, 1.0};
  if (p.type == TinyExampleType::kTiled) {
    if (p.rotate_range[0] != p.rotate_range[1] || p.scale_range[0] != p.scale_range[1])
      return makeError(ErrorCode::kBadArgument,
                       "the tiled type takes one rotation and one scale (--rotate-range and "
                       "--scale-range need A == B)");
    // The tiled matrix is the stochastic rule with a one-point range: R H S (mirror).
    format::TinyExampleRecord probe = r;
    std::copy(mirror, mirror + 4, probe.matrix);
    probe.type = uint32_t(TinyExampleType::kStochastic);
    probe.rotate_range[0] = probe.rotate_range[1] = p.rotate_range[0];
    probe.scale_range[0] = probe.scale_range[1] = p.scale_range[0];
    probe.shear[0] = p.shear[0];
    probe.shear[1] = p.shear[1];
    probe.occupancy = 1.0;
    probe.density = 1.0;
    probe.cell_size = 1e6;
    const format::TinyPlacement one = format::tinyCellPlacement(probe, 0, 0);
    std::copy(one.matrix, one.matrix + 4, r.matrix);
    // Rotations by multiples of 90 degrees land exactly on the texel grid.
    for (double& v : r.matrix)
      if (std::fabs(v - std::round(v)) < 1e-12) v = std::round(v);
    r.translate[0] = p.translate[0];
    r.translate[1] = p.translate[1];
  } else {
    if (!(std::isfinite(p.density) && p.density > 0.0 && p.density <= 1.0))
      return makeError(ErrorCode::kBadArgument, "--density must be in (0, 1]");
    std::copy(mirror, mirror + 4, r.matrix);
    r.seed = p.seed;
    r.density = p.density;
    std::copy(p.rotate_range, p.rotate_range + 2, r.rotate_range);
    std::copy(p.scale_range, p.scale_range + 2, r.scale_range);
    std::copy(p.shear, p.shear + 2, r.shear);
    r.occupancy = 1.0;
    r.cell_size = std::ceil(format::tinyMinCellSize(r) * 64.0) / 64.0;
    const format::TinyLayout* layout = p.layout.width > 0 ? &p.layout : nullptr;
    if (layout) {
      if (const char* why = format::checkTinyLayout(*layout)) return makeError(ErrorCode::kInvalidInput, why);
      r.version = 2;
      r.flags = format::kTinyFlagLayout;
    }
    if (p.overlap) {
      r.version = 2;
      r.flags |= format::kTinyFlagOverlap;
      if (BakeStatus st = chooseOverlapLayout(&r, layout, p.density, p.density_given); !st) return st.error();
      if (const char* why = format::checkTinyExampleRecord(r)) return makeError(ErrorCode::kBadArgument, why);
      return r;
    }
    const double full = format::tinyCoveredFraction(r, layout);
    if (layout && !(full > 0.0))
      return makeError(ErrorCode::kInvalidInput, "layout image: presence is 0 in every cell (no example anywhere)");
    if (layout && !p.density_given) {
      r.density = std::min(1.0, full);
    } else {
      if (p.density > full * (1.0 + 1e-12))
        return makeError(ErrorCode::kBadArgument, "--density " + std::to_string(p.density) +
                                                      " exceeds the largest covered fraction of this layout (" +
                                                      std::to_string(full) + ")");
      r.occupancy = std::min(1.0, p.density / full);
    }
  }
  if (const char* why = format::checkTinyExampleRecord(r)) return makeError(ErrorCode::kBadArgument, why);
  return r;
}

BakeStatus checkTinyExample(const NormalMap& example) {
  const int n = example.width;
  if (example.width != example.height || n < int(format::kMinTinyExampleSize) || n > int(format::kMaxTinyExampleSize) ||
      (n & (n - 1)) != 0)
    return makeError(ErrorCode::kBadArgument, "the example is " + std::to_string(example.width) + " x " +
                                                  std::to_string(example.height) +
                                                  " texels; it must be square, a power of two from 4 to 256");
  return okStatus();
}

std::vector<float> tinyTexels(const NormalMap& example) {
  std::vector<float> t(size_t(example.width) * size_t(example.height) * 2);
  for (int y = 0; y < example.height; ++y) {
    for (int x = 0; x < example.width; ++x) {
      const float* n = example.at(x, y);
      float* o = &t[(size_t(y) * size_t(example.width) + size_t(x)) * 2];
      o[0] = n[0];
      o[1] = n[1];
    }
  }
  return t;
}

std::vector<std::vector<float>> bakeTinyLevels(const std::vector<float>& texels, int n, double sigma_r, int res) {
  int levels = 0;
  while ((2 << levels) <= n) ++levels;
  const size_t image = size_t(res) * size_t(res);
  std::vector<std::vector<float>> out(static_cast<size_t>(levels));
  // Level 0 from the texels' lobes.
  const int m0 = n / 2;
  out[0].assign(size_t(m0) * m0 * image, 0.0f);
  tbb::parallel_for(0, m0 * m0, [&](int t) {
    (void)runtime::tinyTileImage(texels.data(), n, true, sigma_r, res, (t % m0) * 2, (t / m0) * 2, 2,
                                 out[0].data() + size_t(t) * image);
  });
  // Coarser levels: the mean of the four children, in a fixed order.
  for (int l = 1; l < levels; ++l) {
    const int m = n >> (l + 1), fine = 2 * m;
    out[size_t(l)].assign(size_t(m) * m * image, 0.0f);
    const std::vector<float>& below = out[size_t(l) - 1];
    tbb::parallel_for(0, m * m, [&](int t) {
      const int tx = t % m, ty = t / m;
      const float* c[4];
      for (int k = 0; k < 4; ++k)
        c[k] = below.data() + (size_t(2 * ty + (k >> 1)) * fine + size_t(2 * tx + (k & 1))) * image;
      float* dst = out[size_t(l)].data() + size_t(t) * image;
      for (size_t b = 0; b < image; ++b)
        dst[b] = float(0.25 * ((double(c[0][b]) + double(c[1][b])) + (double(c[2][b]) + double(c[3][b]))));
    });
  }
  return out;
}

bool tinyLevelsFitHalf(const std::vector<std::vector<float>>& levels) {
  for (const auto& level : levels)
    for (float v : level)
      if (!(v <= format::kTinyHalfMax)) return false;
  return true;
}

format::TinyExampleRecord withHalfLevels(format::TinyExampleRecord record) {
  record.version = 2;
  record.flags |= format::kTinyFlagHalf;
  return record;
}

BakeStatus writeTinyExampleSections(format::Writer& writer, const format::TinyExampleRecord& record,
                                    const std::vector<float>& texels, const std::vector<std::vector<float>>& levels,
                                    const format::TinyLayout* layout) {
  if (const char* why = format::checkTinyExampleRecord(record)) return makeError(ErrorCode::kRuntime, why);
  const size_t n = record.example_size, image = size_t(record.ndf_res) * record.ndf_res;
  if (texels.size() != n * n * 2 || levels.size() != record.levels)
    return makeError(ErrorCode::kRuntime, "tiny-example sections do not match the record");
  auto failed = [] { return makeError(ErrorCode::kIo, "cannot write the tiny-example sections"); };
  if (writer.addSection(format::kSectionTinyExampleInfo, 0, &record, sizeof record) != format::ContainerStatus::kOk ||
      writer.addSection(format::kSectionTinyExampleTexels, 0, texels.data(), texels.size() * 4) !=
          format::ContainerStatus::kOk)
    return failed();
  std::vector<uint8_t> bytes;
  for (uint32_t l = 0; l < record.levels; ++l) {
    const uint32_t m = format::tinyTilesPerSide(record.example_size, l);
    if (levels[l].size() != size_t(m) * m * image) return makeError(ErrorCode::kRuntime, "tile images of wrong size");
    format::ImageSectionHeader h;
    h.width = h.height = record.ndf_res;
    h.channels = 1;
    h.layers = m * m;
    const bool half = (record.flags & format::kTinyFlagHalf) != 0;
    if (half) {
      h.magic = format::kTinyHalfImageMagic;
      bytes.resize(sizeof h + levels[l].size() * 2);
      std::memcpy(bytes.data(), &h, sizeof h);
      for (size_t i = 0; i < levels[l].size(); ++i) {
        const uint16_t v = format::floatToHalf(levels[l][i]);
        std::memcpy(bytes.data() + sizeof h + 2 * i, &v, 2);
      }
    } else {
      bytes.resize(sizeof h + levels[l].size() * 4);
      std::memcpy(bytes.data(), &h, sizeof h);
      std::memcpy(bytes.data() + sizeof h, levels[l].data(), levels[l].size() * 4);
    }
    if (writer.addSection(half ? format::kSectionTinyExampleLevelHalf : format::kSectionTinyExampleLevel, l,
                          bytes.data(), bytes.size()) != format::ContainerStatus::kOk)
      return failed();
  }
  if ((record.flags & format::kTinyFlagLayout) != 0) {
    if (!layout || format::checkTinyLayout(*layout))
      return makeError(ErrorCode::kRuntime, "the record asks for a layout image and none valid was given");
    format::ImageSectionHeader h;
    h.width = layout->width;
    h.height = layout->height;
    h.channels = layout->channels;
    h.layers = 1;
    const size_t count = size_t(layout->width) * layout->height * layout->channels;
    bytes.resize(sizeof h + count * 4);
    std::memcpy(bytes.data(), &h, sizeof h);
    std::memcpy(bytes.data() + sizeof h, layout->values, count * 4);
    if (writer.addSection(format::kSectionTinyExampleLayout, 0, bytes.data(), bytes.size()) !=
        format::ContainerStatus::kOk)
      return failed();
  }
  return okStatus();
}

NormalMap materialiseTiled(const NormalMap& example, int copies) {
  NormalMap big;
  big.width = example.width * copies;
  big.height = example.height * copies;
  big.wrap = Wrap::kRepeat;
  big.normals.resize(size_t(big.width) * size_t(big.height) * 3);
  for (int y = 0; y < big.height; ++y)
    for (int x = 0; x < big.width; ++x)
      std::memcpy(big.at(x, y), example.at(x % example.width, y % example.height), 12);
  return big;
}

}  // namespace glintbake::bake::tiny
