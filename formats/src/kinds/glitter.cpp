// SPDX-License-Identifier: Apache-2.0
// Checks of the glitter records (see kinds/glitter.h).
#include <glintbake/format/kinds/glitter.h>
#include <glintbake/format/numbers.h>

#include <algorithm>
#include <cmath>

namespace glintbake::format {

const char* glitterDistributionString(GlitterDistribution d) {
  switch (d) {
    case GlitterDistribution::kBeckmann:
      return "beckmann";
    case GlitterDistribution::kGgx:
      return "ggx";
  }
  return "unknown";
}

const char* checkGlitterRecord(const GlitterRecord& r) {
  if (r.magic != GlitterRecord().magic) return "glitter record: bad magic";
  if (r.version != 1) return "glitter record: unsupported version";
  if (r.distribution > uint32_t(GlitterDistribution::kGgx)) return "glitter record: unknown distribution";
  if (r.max_depth < 1 || r.max_depth > kMaxGlitterDepth) return "glitter record: max_depth out of range";
  if (r.particles < 1 || r.particles > kMaxGlitterParticles) return "glitter record: particles out of range";
  if (!(std::isfinite(r.alpha) && r.alpha >= kMinGlitterAlpha && r.alpha <= kMaxGlitterAlpha))
    return "glitter record: alpha out of range";
  if (!(std::isfinite(r.gamma) && r.gamma > 0.0 && r.gamma <= kMaxGlitterGamma))
    return "glitter record: gamma out of range";
  if (r.map_width < 1 || r.map_height < 1 || r.map_width > kMaxGlitterMapSide || r.map_height > kMaxGlitterMapSide)
    return "glitter record: map size out of range";
  if (r.ndf_res < 2 || r.ndf_res > 4096) return "glitter record: ndf_res out of range";
  if (r.integral_count < 4 || r.integral_count > kMaxGlitterIntegrals)
    return "glitter record: integral_count out of range";
  if (!(std::isfinite(r.shape_area) && r.shape_area > 0.0 && r.shape_area <= 1.0))
    return "glitter record: shape_area out of range";
  if (!(std::isfinite(r.shape_cone) && r.shape_cone > 0.0 && r.shape_cone <= kTwoPi))
    return "glitter record: shape_cone out of range";
  return nullptr;
}

const char* checkGlitterLayout(size_t info_sections, size_t integral_sections) {
  if (info_sections != 1) return "a glitter asset holds one glitter-info section (type 128)";
  if (integral_sections != 1) return "a glitter asset holds one glitter-integrals section (type 129)";
  return nullptr;
}

const char* checkGlitterIntegrals(const GlitterIntegral* t, size_t count) {
  if (!t || count < 4 || count > kMaxGlitterIntegrals) return "glitter integrals: entry count out of range";
  size_t next = 4;  // the first child index the next parent must have
  double roots = 0.0;
  for (size_t i = 0; i < count; ++i) {
    if (!(std::isfinite(t[i].integral) && t[i].integral >= 0.0)) return "glitter integrals: value not finite";
    if (i < 4) roots += t[i].integral;
    if (t[i].first_child == 0) continue;
    if (t[i].first_child != next || next + 4 > count) return "glitter integrals: children out of order";
    next += 4;
    double sum = 0.0;
    for (size_t j = 0; j < 4; ++j) sum += t[t[i].first_child + j].integral;
    if (std::fabs(sum - t[i].integral) > 1e-6 * std::max(sum, 1e-300) + 1e-300)
      return "glitter integrals: parent is not the sum of its children";
  }
  if (next != count) return "glitter integrals: entries that are nobody's children";
  if (!(std::fabs(roots - 1.0) <= 1e-3)) return "glitter integrals: roots do not sum to 1";
  return nullptr;
}

}  // namespace glintbake::format
