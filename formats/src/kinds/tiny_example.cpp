// SPDX-License-Identifier: Apache-2.0
// Checks and placement rules of the tiny-example records (see kinds/tiny_example.h).
#include <glintbake/format/kinds/tiny_example.h>
#include <glintbake/format/numbers.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace glintbake::format {
namespace {

constexpr int kRangeSamples = 720;  // rotations tried per range when bounding the example's extent

bool finite(double v) { return std::isfinite(v); }

uint64_t mix64(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Uniform in [0, 1) from the seed, the cell and a stream index.
double cellUniform(uint64_t seed, int64_t i, int64_t j, uint64_t k) {
  uint64_t h = mix64(seed ^ 0x54494E59ull);
  h = mix64(h ^ uint64_t(i));
  h = mix64(h ^ (uint64_t(j) * 0xD6E8FEB86659FD93ull));
  h = mix64(h ^ k);
  return double(h >> 11) * (1.0 / 9007199254740992.0);
}

void multiply(const double a[4], const double b[4], double out[4]) {
  const double r[4] = {a[0] * b[0] + a[1] * b[2], a[0] * b[1] + a[1] * b[3], a[2] * b[0] + a[3] * b[2],
                       a[2] * b[1] + a[3] * b[3]};
  std::copy(r, r + 4, out);
}

// M = R(theta) H(shear) scale S, with R a counter-clockwise rotation as the image is seen
// (positions have y down) and S the record's shared matrix.
void exampleMatrix(const TinyExampleRecord& r, double degrees, double scale, double out[4]) {
  const double t = degrees * kPi / 180.0;
  const double c = std::cos(t), s = std::sin(t);
  const double rot[4] = {c, s, -s, c};
  const double shear[4] = {scale, scale * r.shear[0], scale * r.shear[1], scale};
  double m[4];
  multiply(rot, shear, m);
  multiply(m, r.matrix, out);
}

double det(const double m[4]) { return m[0] * m[3] - m[1] * m[2]; }

// The layout pixel of cell (i, j) (the image repeating over the plane), or null without a layout.
const float* layoutCell(const TinyLayout* layout, int64_t i, int64_t j) {
  if (!layout || !layout->values || layout->width == 0 || layout->height == 0) return nullptr;
  const int64_t w = layout->width, h = layout->height;
  const int64_t x = ((i % w) + w) % w, y = ((j % h) + h) % h;
  return layout->values + (size_t(y) * size_t(w) + size_t(x)) * layout->channels;
}

}  // namespace

const char* tinyExampleTypeString(TinyExampleType type) {
  switch (type) {
    case TinyExampleType::kTiled:
      return "tiled";
    case TinyExampleType::kStochastic:
      return "stochastic";
  }
  return "unknown";
}

uint32_t tinyTilesPerSide(uint32_t n, uint32_t level) {
  if (level >= 31 || (n >> (level + 1)) == 0) return 0;
  return n >> (level + 1);
}

uint64_t tinyLevelSectionSize(const TinyExampleRecord& r, uint32_t level) {
  const uint64_t m = tinyTilesPerSide(r.example_size, level);
  return 32 + m * m * uint64_t(r.ndf_res) * uint64_t(r.ndf_res) * ((r.flags & kTinyFlagHalf) != 0 ? 2 : 4);
}

bool tinyInvert(const double m[4], double inv[4]) {
  const double d = det(m);
  if (!(std::fabs(d) > 1e-300) || !finite(d)) return false;
  inv[0] = m[3] / d;
  inv[1] = -m[1] / d;
  inv[2] = -m[2] / d;
  inv[3] = m[0] / d;
  return true;
}

const char* checkTinyExampleRecord(const TinyExampleRecord& r) {
  if (r.magic != TinyExampleRecord().magic) return "tiny-example record: bad magic";
  if (r.version != 1 && r.version != 2) return "tiny-example record: unsupported version";
  const uint32_t n = r.example_size;
  if (n < kMinTinyExampleSize || n > kMaxTinyExampleSize || (n & (n - 1)) != 0)
    return "tiny-example record: example_size is not a power of two in [4, 256]";
  uint32_t levels = 0;
  while ((2u << levels) <= n) ++levels;
  if (r.levels != levels) return "tiny-example record: levels is not log2(example_size)";
  if (r.ndf_res < 2 || r.ndf_res > kMaxTinyNdfRes) return "tiny-example record: ndf_res out of range";
  if (r.type > uint32_t(TinyExampleType::kStochastic)) return "tiny-example record: unknown type";
  if (r.reserved != 0 || (r.version == 1 && r.flags != 0) ||
      (r.flags & ~(kTinyFlagLayout | kTinyFlagOverlap | kTinyFlagHalf)) != 0)
    return "tiny-example record: reserved fields are not zero";
  if (r.version == 2 && r.flags == 0) return "tiny-example record: version 2 without flags";
  if ((r.flags & (kTinyFlagLayout | kTinyFlagOverlap)) != 0 && r.type != uint32_t(TinyExampleType::kStochastic))
    return "tiny-example record: layout images and overlaps need the stochastic type";
  if (!(finite(r.sigma_r) && r.sigma_r > 0.0 && r.sigma_r <= 1.0)) return "tiny-example record: sigma_r out of range";
  for (double v : r.matrix)
    if (!finite(v)) return "tiny-example record: matrix is not finite";
  const double d = std::fabs(det(r.matrix));
  if (!(d >= kMinTinyDet && d <= kMaxTinyDet)) return "tiny-example record: |det matrix| out of range";
  if (!finite(r.translate[0]) || !finite(r.translate[1]) || std::fabs(r.translate[0]) > 1e9 ||
      std::fabs(r.translate[1]) > 1e9)
    return "tiny-example record: translate out of range";
  if (r.type == uint32_t(TinyExampleType::kTiled)) return nullptr;
  if (!(finite(r.rotate_range[0]) && finite(r.rotate_range[1]) && r.rotate_range[0] <= r.rotate_range[1] &&
        std::fabs(r.rotate_range[0]) <= 3600.0 && std::fabs(r.rotate_range[1]) <= 3600.0))
    return "tiny-example record: rotate_range out of range";
  if (!(finite(r.scale_range[0]) && finite(r.scale_range[1]) && r.scale_range[0] <= r.scale_range[1] &&
        r.scale_range[0] >= kMinTinyScale && r.scale_range[1] <= kMaxTinyScale))
    return "tiny-example record: scale_range out of range";
  if (!(finite(r.shear[0]) && finite(r.shear[1]) && std::fabs(r.shear[0]) <= kMaxTinyShear &&
        std::fabs(r.shear[1]) <= kMaxTinyShear && std::fabs(1.0 - r.shear[0] * r.shear[1]) >= 1e-3))
    return "tiny-example record: shear out of range";
  const double dmin = r.scale_range[0] * r.scale_range[0] * std::fabs(1.0 - r.shear[0] * r.shear[1]) * d;
  const double dmax = r.scale_range[1] * r.scale_range[1] * std::fabs(1.0 - r.shear[0] * r.shear[1]) * d;
  if (!(dmin >= kMinTinyDet && dmax <= kMaxTinyDet)) return "tiny-example record: |det| of the examples out of range";
  if (!(finite(r.density) && r.density > 0.0 && r.density <= 1.0)) return "tiny-example record: density out of range";
  if (!(finite(r.occupancy) && r.occupancy > 0.0 && r.occupancy <= 1.0))
    return "tiny-example record: occupancy out of range";
  const double min_cell =
      (r.flags & kTinyFlagOverlap) != 0 ? tinyMinCellSize(r) / (2.0 * kMaxTinyOverlapReach) : tinyMinCellSize(r);
  if (!(finite(r.cell_size) && r.cell_size <= 1e6 && r.cell_size >= min_cell * (1.0 - 1e-9)))
    return (r.flags & kTinyFlagOverlap) != 0 ? "tiny-example record: cell_size too small for the overlap reach"
                                             : "tiny-example record: cell_size smaller than an example";
  return nullptr;
}

double tinyMinCellSize(const TinyExampleRecord& r) {
  const double half = 0.5 * double(r.example_size);
  double ext = 0.0;
  for (int k = 0; k <= kRangeSamples; ++k) {
    const double deg = r.rotate_range[0] + (r.rotate_range[1] - r.rotate_range[0]) * k / kRangeSamples;
    double m[4];
    exampleMatrix(r, deg, r.scale_range[1], m);
    ext = std::max({ext, (std::fabs(m[0]) + std::fabs(m[1])) * half, (std::fabs(m[2]) + std::fabs(m[3])) * half});
    if (r.rotate_range[0] == r.rotate_range[1]) break;
  }
  // Rotations between the samples: the extent's slope is at most |M| n / 2 per radian.
  const double step = (r.rotate_range[1] - r.rotate_range[0]) * kPi / 180.0 / kRangeSamples;
  return 2.0 * ext * (1.0 + 2.0 * step);
}

const char* checkTinyLayout(const TinyLayout& layout, uint64_t* bad_index) {
  if (layout.width < 1 || layout.height < 1 || layout.width > kMaxTinyLayoutSide || layout.height > kMaxTinyLayoutSide)
    return "layout image: size out of range (1..1024 cells per side)";
  if (layout.channels < 1 || layout.channels > kMaxTinyLayoutChannels)
    return "layout image: not 1 (presence), 2 (+ rotation) or 3 (+ scale) channels";
  if (!layout.values) return "layout image: no values";
  const uint64_t count = uint64_t(layout.width) * layout.height * layout.channels;
  for (uint64_t k = 0; k < count; ++k) {
    const float v = layout.values[k];
    if (!(v >= 0.0f && v <= 1.0f)) {
      if (bad_index) *bad_index = k;
      return std::isfinite(v) ? "layout image: a value outside [0, 1]" : "layout image: a value that is not finite";
    }
  }
  return nullptr;
}

double tinyCoveredFraction(const TinyExampleRecord& r, const TinyLayout* layout) {
  if ((r.flags & kTinyFlagOverlap) != 0) return tinySampledCoverage(r, layout);
  const double a = r.scale_range[0], b = r.scale_range[1];
  double mean_s2 = (a * a + a * b + b * b) / 3.0;
  if (layout && layout->values && layout->width > 0 && layout->height > 0) {
    // The mean over the image's cells of presence x s^2 (s uniform on the range without channel 2).
    double sum = 0.0;
    for (uint32_t y = 0; y < layout->height; ++y) {
      for (uint32_t x = 0; x < layout->width; ++x) {
        const float* c = layoutCell(layout, x, y);
        double s2 = mean_s2;
        if (layout->channels >= 3) {
          const double s = a + (b - a) * double(c[2]);
          s2 = s * s;
        }
        sum += double(c[0]) * s2;
      }
    }
    mean_s2 = sum / (double(layout->width) * double(layout->height));
  }
  const double mean_det = mean_s2 * std::fabs(1.0 - r.shear[0] * r.shear[1]) * std::fabs(det(r.matrix));
  const double n = r.example_size;
  return r.occupancy * mean_det * n * n / (r.cell_size * r.cell_size);
}

namespace {

// The example of cell (i, j); with `any`, whatever its presence (the candidate).
TinyPlacement cellExample(const TinyExampleRecord& r, int64_t i, int64_t j, const TinyLayout* layout, bool any) {
  TinyPlacement p;
  p.cell_x = i;
  p.cell_y = j;
  const float* cell = (r.flags & kTinyFlagLayout) != 0 ? layoutCell(layout, i, j) : nullptr;
  if ((r.flags & kTinyFlagLayout) != 0 && !cell) return p;  // a layout asset read without its layout
  const double presence = cell ? double(cell[0]) : 1.0;
  const double u0 = cellUniform(r.seed, i, j, 0);
  p.threshold = presence == 1.0 ? u0 : presence > 0.0 ? u0 / presence : std::numeric_limits<double>::infinity();
  if (!any && !(p.threshold < r.occupancy)) return p;
  const double u_rot = cell && layout->channels >= 2 ? double(cell[1]) : cellUniform(r.seed, i, j, 1);
  const double u_scale = cell && layout->channels >= 3 ? double(cell[2]) : cellUniform(r.seed, i, j, 2);
  const double deg = r.rotate_range[0] + (r.rotate_range[1] - r.rotate_range[0]) * u_rot;
  const double scale = r.scale_range[0] + (r.scale_range[1] - r.scale_range[0]) * u_scale;
  exampleMatrix(r, deg, scale, p.matrix);
  if ((r.flags & kTinyFlagOverlap) != 0) {
    p.centre[0] = (double(i) + cellUniform(r.seed, i, j, 3)) * r.cell_size;
    p.centre[1] = (double(j) + cellUniform(r.seed, i, j, 4)) * r.cell_size;
    p.present = true;
    return p;
  }
  const double half = 0.5 * double(r.example_size);
  const double ext_x = (std::fabs(p.matrix[0]) + std::fabs(p.matrix[1])) * half;
  const double ext_y = (std::fabs(p.matrix[2]) + std::fabs(p.matrix[3])) * half;
  const double slack_x = std::max(0.0, 0.5 * r.cell_size - ext_x), slack_y = std::max(0.0, 0.5 * r.cell_size - ext_y);
  p.centre[0] = (double(i) + 0.5) * r.cell_size + (2.0 * cellUniform(r.seed, i, j, 3) - 1.0) * slack_x;
  p.centre[1] = (double(j) + 0.5) * r.cell_size + (2.0 * cellUniform(r.seed, i, j, 4) - 1.0) * slack_y;
  p.present = true;
  return p;
}

}  // namespace

TinyPlacement tinyCellPlacement(const TinyExampleRecord& r, int64_t i, int64_t j, const TinyLayout* layout) {
  TinyPlacement p = cellExample(r, i, j, layout, false);
  p.present = p.present && p.threshold < r.occupancy;
  return p;
}

TinyPlacement tinyCellCandidate(const TinyExampleRecord& r, int64_t i, int64_t j, const TinyLayout* layout) {
  return cellExample(r, i, j, layout, true);
}

int tinyOverlapReach(const TinyExampleRecord& r) {
  if ((r.flags & kTinyFlagOverlap) == 0 || !(r.cell_size > 0.0)) return 0;
  // A cheap bound on the half extent of every example, sqrt(2) |M| n / 2 (|M| the largest singular
  // value of M at the largest scale: no rotation makes a row of M longer), computed per query. The
  // record check keeps the true extent within kMaxTinyOverlapReach cells, so clamping is safe.
  const double h[4] = {1.0, r.shear[0], r.shear[1], 1.0};
  double m[4];
  multiply(h, r.matrix, m);
  const double f2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2] + m[3] * m[3], d = det(m);
  const double sigma_max = std::sqrt(0.5 * (f2 + std::sqrt(std::max(0.0, f2 * f2 - 4.0 * d * d))));
  const double half = 1.4142135623730951 * r.scale_range[1] * sigma_max * 0.5 * double(r.example_size);
  const double cells = std::ceil(half / r.cell_size);
  return int(std::clamp(cells, 1.0, double(kMaxTinyOverlapReach)));
}

bool tinyContains(const TinyExampleRecord& r, const TinyPlacement& p, double x, double y, double local[2]) {
  double inv[4];
  if (!p.present || !tinyInvert(p.matrix, inv)) return false;
  const double n = r.example_size;
  const double dx = x - p.centre[0], dy = y - p.centre[1];
  const double lx = inv[0] * dx + inv[1] * dy + 0.5 * n, ly = inv[2] * dx + inv[3] * dy + 0.5 * n;
  if (!(lx >= 0.0 && lx < n && ly >= 0.0 && ly < n)) return false;
  local[0] = lx;
  local[1] = ly;
  return true;
}

double tinySampledCoverage(const TinyExampleRecord& r, const TinyLayout* layout) {
  const double step = kTinyCoverageCells * r.cell_size / kTinyCoverageSamples;
  int64_t owned = 0;
  double local[2];
  for (int b = 0; b < kTinyCoverageSamples; ++b)
    for (int a = 0; a < kTinyCoverageSamples; ++a)
      owned += tinyOwner(r, (a + 0.5) * step, (b + 0.5) * step, local, layout).present ? 1 : 0;
  return double(owned) / (double(kTinyCoverageSamples) * kTinyCoverageSamples);
}

TinyPlacement tinyOwner(const TinyExampleRecord& r, double x, double y, double local[2], const TinyLayout* layout) {
  const double n = r.example_size;
  double inv[4];
  if (r.type == uint32_t(TinyExampleType::kTiled)) {
    TinyPlacement p;
    if (!tinyInvert(r.matrix, inv)) return p;
    const double dx = x - r.translate[0], dy = y - r.translate[1];
    const double ex = inv[0] * dx + inv[1] * dy, ey = inv[2] * dx + inv[3] * dy;
    const double cx = std::floor(ex / n), cy = std::floor(ey / n);
    p.present = true;
    p.cell_x = int64_t(cx);
    p.cell_y = int64_t(cy);
    std::copy(r.matrix, r.matrix + 4, p.matrix);
    // Centre of the copy: translate + M (copy corner + n / 2).
    const double vx = (cx + 0.5) * n, vy = (cy + 0.5) * n;
    p.centre[0] = r.translate[0] + r.matrix[0] * vx + r.matrix[1] * vy;
    p.centre[1] = r.translate[1] + r.matrix[2] * vx + r.matrix[3] * vy;
    local[0] = std::clamp(ex - cx * n, 0.0, std::nextafter(n, 0.0));
    local[1] = std::clamp(ey - cy * n, 0.0, std::nextafter(n, 0.0));
    return p;
  }
  if ((r.flags & kTinyFlagOverlap) != 0) {
    // Of the examples covering the point, the one with the nearest centre.
    const int reach = tinyOverlapReach(r);
    const int64_t ci = int64_t(std::floor(x / r.cell_size)), cj = int64_t(std::floor(y / r.cell_size));
    TinyPlacement best;
    double best_d = 0.0, at[2];
    for (int64_t j = cj - reach; j <= cj + reach; ++j) {
      for (int64_t i = ci - reach; i <= ci + reach; ++i) {
        const TinyPlacement e = tinyCellPlacement(r, i, j, layout);
        if (!tinyContains(r, e, x, y, at)) continue;
        const double dx = x - e.centre[0], dy = y - e.centre[1], d = dx * dx + dy * dy;
        if (!best.present || tinyNearer(d, e, best_d, best)) {
          best = e;
          best_d = d;
          local[0] = at[0];
          local[1] = at[1];
        }
      }
    }
    return best;
  }
  TinyPlacement p =
      tinyCellPlacement(r, int64_t(std::floor(x / r.cell_size)), int64_t(std::floor(y / r.cell_size)), layout);
  if (!p.present || !tinyInvert(p.matrix, inv)) {
    p.present = false;
    return p;
  }
  const double dx = x - p.centre[0], dy = y - p.centre[1];
  const double lx = inv[0] * dx + inv[1] * dy + 0.5 * n, ly = inv[2] * dx + inv[3] * dy + 0.5 * n;
  if (!(lx >= 0.0 && lx < n && ly >= 0.0 && ly < n)) {
    p.present = false;
    return p;
  }
  local[0] = lx;
  local[1] = ly;
  return p;
}

}  // namespace glintbake::format
