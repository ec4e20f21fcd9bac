// SPDX-License-Identifier: Apache-2.0
// Roughness mips of a normal map: box-filtered unnormalised normals, |b| -> alpha_me -> alpha.
#include <glintbake/bake/ltc/roughness.h>

#include "ltc/exr_writer.h"

#include <tbb/parallel_for.h>

#include <cmath>

namespace glintbake::bake::ltc {

namespace {

constexpr double kUnitLengthSlack = 1e-6;

struct NormalLevel {
  int width = 0, height = 0;
  std::vector<double> b;  // 3 per texel, unnormalised averages
};

NormalLevel downsample(const NormalLevel& in) {
  NormalLevel out;
  out.width = (in.width + 1) / 2;
  out.height = (in.height + 1) / 2;
  out.b.assign(size_t(out.width) * size_t(out.height) * 3, 0.0);
  tbb::parallel_for(0, out.height, [&](int y) {
    for (int x = 0; x < out.width; ++x) {
      double sum[3] = {0, 0, 0};
      int count = 0;
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const int sx = 2 * x + dx, sy = 2 * y + dy;
          if (sx >= in.width || sy >= in.height) continue;
          const double* p = &in.b[(size_t(sy) * size_t(in.width) + size_t(sx)) * 3];
          sum[0] += p[0], sum[1] += p[1], sum[2] += p[2];
          ++count;
        }
      }
      double* q = &out.b[(size_t(y) * size_t(out.width) + size_t(x)) * 3];
      for (int c = 0; c < 3; ++c) q[c] = sum[c] / count;
    }
  });
  return out;
}

RoughnessLevel toRoughness(const NormalLevel& level, const RoughnessOptions& options) {
  RoughnessLevel out;
  out.width = level.width;
  out.height = level.height;
  const size_t n = size_t(level.width) * size_t(level.height);
  out.alpha.resize(n);
  out.mean_length.resize(n);
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    const double* b = &level.b[i * 3];
    double length = std::min(1.0, std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]));
    // Unit normals stored as float are unit only to within a few ulps; do not read that as roughness.
    if (length > 1.0 - kUnitLengthSlack) length = 1.0;
    const double alpha_meso = options.exact_meso ? alphaMesoExact(length) : options.meso.eval(length);
    out.mean_length[i] = float(length);
    out.alpha[i] = float(options.combine.eval(options.alpha_micro, alpha_meso));
  });
  return out;
}

}  // namespace

Result<std::vector<RoughnessLevel>> bakeRoughness(const NormalMap& map, const RoughnessOptions& options) {
  if (!(options.alpha_micro >= 0.0 && options.alpha_micro <= 1.0))
    return makeError(ErrorCode::kBadArgument, "alpha-micro must be in [0, 1]");
  if (map.width < 1 || map.height < 1 || map.normals.size() != size_t(map.width) * size_t(map.height) * 3)
    return makeError(ErrorCode::kInvalidInput, "the normal map is empty or inconsistent");
  NormalLevel level;
  level.width = map.width;
  level.height = map.height;
  level.b.assign(map.normals.begin(), map.normals.end());
  std::vector<RoughnessLevel> levels;
  for (;;) {
    levels.push_back(toRoughness(level, options));
    if (level.width == 1 && level.height == 1) break;
    level = downsample(level);
  }
  return levels;
}

BakeStatus writeRoughnessExr(const std::vector<RoughnessLevel>& levels, const std::string& path) {
  if (levels.empty()) return makeError(ErrorCode::kBadArgument, "no roughness levels to write");
  std::vector<ExrLevel> images;
  for (const auto& level : levels) images.push_back({level.width, level.height, level.alpha.data()});
  if (images.size() == 1) return writeExr(path, {"Y"}, images[0]);
  return writeMipmappedExr(path, "Y", images);
}

}  // namespace glintbake::bake::ltc
