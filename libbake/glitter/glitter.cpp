// SPDX-License-Identifier: Apache-2.0
#include <glintbake/bake/glitter/glitter.h>
#include <glintbake/format/numbers.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <string>

namespace glintbake::bake::glitter {
namespace {

using format::GlitterVec3;

BakeStatus bad(const std::string& message) { return makeError(ErrorCode::kBadArgument, message); }

// Centroid rule of D cos over a triangle.
double centroidRule(format::GlitterDistribution d, double alpha, const GlitterVec3 v[3]) {
  GlitterVec3 c{v[0].x + v[1].x + v[2].x, v[0].y + v[1].y + v[2].y, v[0].z + v[1].z + v[2].z};
  const double len = std::sqrt(c.x * c.x + c.y * c.y + c.z * c.z);
  c = {c.x / len, c.y / len, c.z / len};
  return format::glitterNdfCos(d, alpha, c) * format::sphericalTriangleArea(v[0], v[1], v[2]);
}

double childrenRule(format::GlitterDistribution d, double alpha, const GlitterVec3 v[3]) {
  double sum = 0.0;
  for (int j = 0; j < 4; ++j) {
    GlitterVec3 c[3];
    format::glitterChildTriangle(v, j, c);
    sum += centroidRule(d, alpha, c);
  }
  return sum;
}

}  // namespace

BakeStatus validateGlitterParams(const GlitterParams& p) {
  if (p.particles < 1 || p.particles > format::kMaxGlitterParticles)
    return bad("--particles must be in [1, 2^40] (got " + std::to_string(p.particles) + ")");
  if (!(p.alpha >= format::kMinGlitterAlpha && p.alpha <= format::kMaxGlitterAlpha))
    return bad("--alpha must be in [0.001, 4]");
  if (p.distribution != format::GlitterDistribution::kBeckmann && p.distribution != format::GlitterDistribution::kGgx)
    return bad("--distribution must be beckmann or ggx");
  if (p.max_depth < 1 || p.max_depth > int(format::kMaxGlitterDepth)) return bad("--max-depth must be in [1, 20]");
  if (!(p.gamma > 0.0 && p.gamma <= format::kMaxGlitterGamma)) return bad("--gamma must be in (0, 28.6] degrees");
  if (p.map_width < 1 || p.map_height < 1 || p.map_width > int(format::kMaxGlitterMapSide) ||
      p.map_height > int(format::kMaxGlitterMapSide))
    return bad("--size must be in [1, 65536] per side");
  if (p.ndf_res < 2 || p.ndf_res > 4096) return bad("--ndf-res must be in [2, 4096]");
  return okStatus();
}

std::vector<format::GlitterIntegral> buildGlitterIntegrals(format::GlitterDistribution d, double alpha,
                                                           double tolerance, int max_depth, size_t max_entries) {
  // Breadth-first: the queue holds the triangles whose entries exist but whose children are not
  // decided yet; a refined triangle appends its four children, so entries stay in BFS order.
  struct Pending {
    size_t entry;
    int depth;
    GlitterVec3 v[3];
  };
  std::vector<format::GlitterIntegral> table(4);
  std::deque<Pending> queue;
  for (int r = 0; r < 4; ++r) {
    Pending p{size_t(r), 1, {}};
    format::glitterRootTriangle(r, p.v);
    queue.push_back(p);
  }
  while (!queue.empty()) {
    Pending p = queue.front();
    queue.pop_front();
    const double coarse = centroidRule(d, alpha, p.v);
    const double fine = childrenRule(d, alpha, p.v);
    // A peak at a vertex (the pole, for small alpha) can hide from both centroid rules: compare
    // with the rule that also samples the vertices.
    double corners = 0.0;
    for (const GlitterVec3& v : p.v) corners += format::glitterNdfCos(d, alpha, v);
    const double area = format::sphericalTriangleArea(p.v[0], p.v[1], p.v[2]);
    const double with_corners = 0.25 * (coarse + corners * area);
    const double error = std::max(std::fabs(fine - coarse), std::fabs(fine - with_corners));
    if (p.depth < max_depth && error > tolerance && table.size() + 4 <= max_entries) {
      table[p.entry].first_child = uint32_t(table.size());
      for (int j = 0; j < 4; ++j) {
        Pending c{table.size(), p.depth + 1, {}};
        format::glitterChildTriangle(p.v, j, c.v);
        table.emplace_back();
        queue.push_back(c);
      }
    } else {
      double sum = 0.0;  // the 16-point rule
      for (int j = 0; j < 4; ++j) {
        GlitterVec3 c[3];
        format::glitterChildTriangle(p.v, j, c);
        sum += childrenRule(d, alpha, c);
      }
      table[p.entry].integral = sum;
    }
  }
  // Children come after their parents: sum bottom-up.
  for (size_t i = table.size(); i-- > 0;) {
    if (table[i].first_child == 0) continue;
    double sum = 0.0;
    for (uint32_t j = 0; j < 4; ++j) sum += table[table[i].first_child + j].integral;
    table[i].integral = sum;
  }
  return table;
}

GlitterModel::GlitterModel(const GlitterParams& params) : params_(params) {
  table_ = buildGlitterIntegrals(params.distribution, params.alpha);
  surface_.distribution = params.distribution;
  surface_.alpha = params.alpha;
  surface_.particles = params.particles;
  surface_.seed = params.seed;
  surface_.max_depth = params.max_depth;
  surface_.integrals = table_.data();
  surface_.integral_count = table_.size();
}

format::GlitterTreeShape defaultGlitterShape(const GlitterParams& p, double sigma_texels) {
  format::GlitterTreeShape shape;
  shape.area = std::min(1.0, 12.0 * sigma_texels * sigma_texels / (double(p.map_width) * double(p.map_height)));
  shape.cone = 2.0 * kPi * (1.0 - std::cos(p.gamma));
  return shape;
}

format::GlitterRecord glitterRecord(const GlitterModel& model, const format::GlitterTreeShape& shape) {
  const GlitterParams& p = model.params();
  format::GlitterRecord r;
  r.distribution = uint32_t(p.distribution);
  r.max_depth = uint32_t(p.max_depth);
  r.particles = p.particles;
  r.seed = p.seed;
  r.alpha = p.alpha;
  r.gamma = p.gamma;
  r.map_width = uint32_t(p.map_width);
  r.map_height = uint32_t(p.map_height);
  r.ndf_res = uint32_t(p.ndf_res);
  r.integral_count = uint32_t(model.integrals().size());
  r.shape_area = shape.area;
  r.shape_cone = shape.cone;
  return r;
}

BakeStatus writeGlitterSections(format::Writer& writer, const GlitterModel& model,
                                const format::GlitterTreeShape& shape) {
  const format::GlitterRecord rec = glitterRecord(model, shape);
  if (const char* why = format::checkGlitterRecord(rec)) return makeError(ErrorCode::kRuntime, why);
  const auto& table = model.integrals();
  if (const char* why = format::checkGlitterIntegrals(table.data(), table.size()))
    return makeError(ErrorCode::kRuntime, why);
  if (writer.addSection(format::kSectionGlitterInfo, 0, &rec, sizeof rec) != format::ContainerStatus::kOk ||
      writer.addSection(format::kSectionGlitterIntegrals, 0, table.data(),
                        table.size() * sizeof(format::GlitterIntegral)) != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, "cannot write the glitter sections");
  return okStatus();
}

GlitterImageSource::GlitterImageSource(const GlitterModel& model, int ndf_res, double sigma0_texels)
    : model_(model), res_(ndf_res) {
  shape_ = defaultGlitterShape(model.params(), sigma0_texels);
  const double bin = 2.0 / ndf_res;
  shape_.cone = std::min(2.0 * kPi, bin * bin);
}

void GlitterImageSource::mapSize(int* width, int* height) const {
  *width = model_.params().map_width;
  *height = model_.params().map_height;
}

void GlitterImageSource::image(double x, double y, double sigma, float* out) const {
  const GlitterParams& p = model_.params();
  format::GlitterGaussian fp;
  fp.u = x / p.map_width;
  fp.v = y / p.map_height;
  fp.sigma_u = std::max(sigma, 1e-6) / p.map_width;
  fp.sigma_v = std::max(sigma, 1e-6) / p.map_height;
  const size_t n = size_t(res_) * size_t(res_);
  std::vector<double> bins(n, 0.0);
  format::glitterBinnedWeights(model_.view(), shape_, fp, res_, bins.data(), nullptr);
  const double bin_area = (2.0 / res_) * (2.0 / res_);
  const double scale = 1.0 / (double(p.particles) * bin_area);
  for (size_t i = 0; i < n; ++i) out[i] = float(bins[i] * scale);
}

}  // namespace glintbake::bake::glitter
