// SPDX-License-Identifier: Apache-2.0
// The Wang tile set of an exemplar: edge samples, the four-triangle assembly with minimum-error
// cuts along the diagonals, and the exact outer rings (see wang/wang.h).
#include <glintbake/bake/wang/wang.h>
#include <glintbake/format/numbers.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace glintbake::bake::wang {
namespace {

uint64_t splitMix(uint64_t* state) {
  uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Offsets of one edge sample in the exemplar: `along` runs with the edge, `across` is the exemplar
// row (column) the edge's middle line reads.
struct EdgeSample {
  int along = 0, across = 0;
};

// The sample's coordinate `d` texels across the edge (d >= 0 on the far side of the edge line,
// d < 0 on the near side): the texels at d = -1 and d = 0 read the same exemplar line, so both
// sides of an edge start from the same texels.
int acrossIndex(int d) { return d >= 0 ? d : d + 1; }

// Where a sample's offsets may fall so that its reads stay inside the exemplar (span texels along,
// 2 T - 1 across); wraps (exemplar's wrap mode) when the exemplar is smaller.
int pickOffset(uint64_t* rng, int size, int lo_margin, int hi_margin) {
  const int span = size - lo_margin - hi_margin;
  if (span <= 0) return int(splitMix(rng) % uint64_t(size));
  return lo_margin + int(splitMix(rng) % uint64_t(span));
}

enum Label : uint8_t { kN = 0, kE = 1, kS = 2, kW = 3 };

struct Assembler {
  const NormalMap& ex;
  int T;
  std::vector<EdgeSample> horizontal, vertical;  // per colour
  int corner_x = 0, corner_y = 0;

  // The normal of label L's sample at tile texel (x, y) for tile edges e.
  const float* sample(const std::array<uint8_t, 4>& e, int label, int x, int y) const {
    switch (label) {
      case kN: {
        const EdgeSample& s = horizontal[e[kN]];
        return ex.fetch(s.along + x, s.across + acrossIndex(y));
      }
      case kS: {
        const EdgeSample& s = horizontal[e[kS]];
        return ex.fetch(s.along + x, s.across + acrossIndex(y - T));
      }
      case kW: {
        const EdgeSample& s = vertical[e[kW]];
        return ex.fetch(s.across + acrossIndex(x), s.along + y);
      }
      default: {
        const EdgeSample& s = vertical[e[kE]];
        return ex.fetch(s.across + acrossIndex(x - T), s.along + y);
      }
    }
  }
};

double angleDegrees(const float* a, const float* b) {
  const double d = double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
  return std::acos(std::clamp(d, -1.0, 1.0)) * (180.0 / kPi);
}

// The straight cut: the nearest edge of the texel's centre (ties in the order N, E, S, W).
int plainLabel(int T, int x, int y) {
  const int d[4] = {2 * y + 1, 2 * T - 2 * x - 1, 2 * T - 2 * y - 1, 2 * x + 1};
  int best = 0;
  for (int i = 1; i < 4; ++i) {
    if (d[i] < d[best]) best = i;
  }
  return best;
}

struct SeamSum {
  double sum = 0.0, max = 0.0;
  uint64_t n = 0;
  void add(double e) {
    sum += e;
    max = std::max(max, e);
    ++n;
  }
  void add(const SeamSum& o) {
    sum += o.sum;
    max = std::max(max, o.max);
    n += o.n;
  }
  SeamError result() const { return {n > 0 ? sum / double(n) : 0.0, max, n}; }
};

// One tile: labels (plain, then the four wedges' cuts), texels, outer ring.
void assembleTile(const Assembler& as, const std::array<uint8_t, 4>& e, int band, bool optimise, float* out,
                  SeamSum* seam, SeamSum* plain) {
  const int T = as.T;
  std::vector<uint8_t> label(size_t(T) * size_t(T));
  for (int y = 0; y < T; ++y) {
    for (int x = 0; x < T; ++x) label[size_t(y) * T + x] = uint8_t(plainLabel(T, x, y));
  }
  // The wedge around each half-diagonal from a corner to the centre, in virtual coordinates where
  // the corner is (0, 0), A the sample on the left (x small) and B the one on top (y small):
  // flip_x, flip_y map them to the tile.
  struct Wedge {
    bool flip_x, flip_y;
    int a, b;
  };
  const Wedge wedges[4] = {{false, false, kW, kN}, {true, false, kE, kN}, {false, true, kW, kS}, {true, true, kE, kS}};
  std::vector<double> cost, acc;
  std::vector<int8_t> from;
  for (const Wedge& w : wedges) {
    const auto real = [&](int vx, int vy, int* x, int* y) {
      *x = w.flip_x ? T - 1 - vx : vx;
      *y = w.flip_y ? T - 1 - vy : vy;
    };
    // error of a cut whose first B texel on line m (vx + vy = m) is vx = k
    const auto err = [&](int m, int k) {
      int x, y;
      real(k, m - k, &x, &y);
      return angleDegrees(as.sample(e, w.a, x, y), as.sample(e, w.b, x, y));
    };
    const int lines = T - 1;  // m = 0 .. T - 2
    const int W = std::max(band, 0);
    const int width = 2 * W + 1;
    const auto halfWidth = [&](int m) { return std::min({W, m / 4, (T - 1 - m) / 4}); };
    // Dynamic programming over the offsets o = k - ceil(m / 2), |o| <= halfWidth(m), |o' - o| <= 1.
    acc.assign(size_t(lines) * width, std::numeric_limits<double>::infinity());
    from.assign(size_t(lines) * width, 0);
    for (int m = 0; m < lines; ++m) {
      const int hw = optimise ? halfWidth(m) : 0;
      for (int o = -hw; o <= hw; ++o) {
        const double c = err(m, (m + 1) / 2 + o);
        double best = m == 0 ? 0.0 : std::numeric_limits<double>::infinity();
        int8_t arg = 0;
        if (m > 0) {
          for (int d = -1; d <= 1; ++d) {
            const int p = o + d;
            if (p < -W || p > W) continue;
            const double v = acc[size_t(m - 1) * width + size_t(p + W)];
            if (v < best) best = v, arg = int8_t(d);
          }
        }
        acc[size_t(m) * width + size_t(o + W)] = best + c;
        from[size_t(m) * width + size_t(o + W)] = arg;
      }
    }
    // Backtrack from the best offset of the last line (0: the band is closed there).
    int o = 0;
    for (int m = lines - 1; m >= 0; --m) {
      const int k = (m + 1) / 2 + o;
      seam->add(err(m, k));
      plain->add(err(m, (m + 1) / 2));
      const int hw = halfWidth(m);
      for (int vx = (m + 1) / 2 - hw - 1; vx <= (m + 1) / 2 + hw; ++vx) {
        const int vy = m - vx;
        if (vx < 0 || vy < 0) continue;
        int x, y;
        real(vx, vy, &x, &y);
        uint8_t& l = label[size_t(y) * T + x];
        if (l != w.a && l != w.b) continue;
        l = uint8_t(vx < k ? w.a : w.b);
      }
      o += from[size_t(m) * width + size_t(o + W)];
    }
  }
  for (int y = 0; y < T; ++y) {
    for (int x = 0; x < T; ++x) {
      int l = label[size_t(y) * T + x];
      // The outer ring belongs to its edge's sample; the four corner texels are one exemplar texel.
      if (y == 0) l = kN;
      if (y == T - 1) l = kS;
      if (x == 0) l = kW;
      if (x == T - 1) l = kE;
      const bool corner = (x == 0 || x == T - 1) && (y == 0 || y == T - 1);
      const float* n = corner ? as.ex.fetch(as.corner_x, as.corner_y) : as.sample(e, l, x, y);
      float* o = out + (size_t(y) * T + x) * 3;
      o[0] = n[0], o[1] = n[1], o[2] = n[2];
    }
  }
}

}  // namespace

NormalMap WangTileSet::tile(int t) const {
  NormalMap m;
  m.width = m.height = tile_size;
  m.wrap = Wrap::kClamp;
  const size_t n = size_t(tile_size) * size_t(tile_size) * 3;
  m.normals.assign(normals.begin() + std::ptrdiff_t(size_t(t) * n),
                   normals.begin() + std::ptrdiff_t(size_t(t + 1) * n));
  return m;
}

Result<WangTileSet> buildWangTiles(const NormalMap& ex, const WangTileOptions& o) {
  if (o.colors < int(format::kMinWangColors) || o.colors > int(format::kMaxWangColors))
    return makeError(ErrorCode::kBadArgument, "--colors must be in [2, 4]");
  if (o.tile_size < int(format::kMinWangTileSize) || o.tile_size > int(format::kMaxWangTileSize))
    return makeError(ErrorCode::kBadArgument, "--tile-size must be in [8, 4096]");
  if (o.band < 0 || o.band > o.tile_size) return makeError(ErrorCode::kBadArgument, "the cut band must be in [0, T]");
  if (ex.width < o.tile_size || ex.height < o.tile_size)
    return makeError(ErrorCode::kInvalidInput, "the example (" + std::to_string(ex.width) + " x " +
                                                   std::to_string(ex.height) + ") is smaller than --tile-size " +
                                                   std::to_string(o.tile_size));
  const int T = o.tile_size, C = o.colors;
  Assembler as{ex, T, {}, {}};
  uint64_t rng = o.seed ^ 0x57414E4754494C45ull;  // "WANGTILE"
  for (int c = 0; c < C; ++c) {
    as.horizontal.push_back({pickOffset(&rng, ex.width, 0, T), pickOffset(&rng, ex.height, T - 1, T)});
    as.vertical.push_back({pickOffset(&rng, ex.height, 0, T), pickOffset(&rng, ex.width, T - 1, T)});
  }
  as.corner_x = int(splitMix(&rng) % uint64_t(ex.width));
  as.corner_y = int(splitMix(&rng) % uint64_t(ex.height));

  WangTileSet set;
  set.colors = C;
  set.tile_size = T;
  set.tile_count = C * C * C * C;
  set.edges.resize(size_t(set.tile_count));
  for (int t = 0; t < set.tile_count; ++t) {
    // tile index = code = ((N C + E) C + S) C + W
    set.edges[size_t(t)] = {uint8_t(t / (C * C * C)), uint8_t((t / (C * C)) % C), uint8_t((t / C) % C), uint8_t(t % C)};
  }
  set.normals.assign(size_t(set.tile_count) * size_t(T) * size_t(T) * 3, 0.0f);
  std::vector<SeamSum> seams(size_t(set.tile_count)), plains(size_t(set.tile_count));
  const int band = o.band > 0 ? o.band : std::max(1, T / 8);
  tbb::parallel_for(0, set.tile_count, [&](int t) {
    assembleTile(as, set.edges[size_t(t)], band, o.optimise, &set.normals[size_t(t) * size_t(T) * size_t(T) * 3],
                 &seams[size_t(t)], &plains[size_t(t)]);
  });
  SeamSum seam, plain;
  for (int t = 0; t < set.tile_count; ++t) seam.add(seams[size_t(t)]), plain.add(plains[size_t(t)]);
  set.seam = seam.result();
  set.plain_seam = plain.result();
  return set;
}

NormalMap materialiseWangRegion(const WangTileSet& set, uint64_t grid_seed, int64_t i0, int64_t j0, int nx, int ny) {
  const int T = set.tile_size;
  NormalMap m;
  m.width = nx * T;
  m.height = ny * T;
  m.wrap = Wrap::kClamp;
  m.normals.resize(size_t(m.width) * size_t(m.height) * 3);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      uint8_t e[4];
      format::wangCellEdges(i0 + i, j0 + j, uint32_t(set.colors), grid_seed, e);
      const int t = int(format::wangTileCode(uint32_t(set.colors), e));
      for (int y = 0; y < T; ++y) {
        std::copy_n(set.texel(t, 0, y), size_t(T) * 3, m.at(i * T, j * T + y));
      }
    }
  }
  return m;
}

NormalMap wangAtlas(const WangTileSet& set) {
  const int T = set.tile_size;
  const int cols = int(std::ceil(std::sqrt(double(set.tile_count))));
  const int rows = (set.tile_count + cols - 1) / cols;
  NormalMap m;
  m.width = cols * T;
  m.height = rows * T;
  m.wrap = Wrap::kClamp;
  m.normals.assign(size_t(m.width) * size_t(m.height) * 3, 0.0f);
  for (size_t i = 2; i < m.normals.size(); i += 3) m.normals[i] = 1.0f;
  for (int t = 0; t < set.tile_count; ++t) {
    for (int y = 0; y < T; ++y)
      std::copy_n(set.texel(t, 0, y), size_t(T) * 3, m.at((t % cols) * T, (t / cols) * T + y));
  }
  return m;
}

}  // namespace glintbake::bake::wang
