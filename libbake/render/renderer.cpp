// SPDX-License-Identifier: Apache-2.0
// Direct lighting of one object with the glinty microfacet BRDF, over image tiles.
#include <glintbake/bake/render/renderer.h>

#include <glintbake/bake/render/geometry.h>
#include <glintbake/reference/flakes.h>
#include <glintbake/runtime/brdf.h>
#include <glintbake/runtime/ltc.h>
#include <glintbake/runtime/sg.h>

#include "reference_ndf.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>

namespace glintbake::bake::render {
namespace {

using runtime::BrdfSample;
using runtime::dot;
using runtime::MicrofacetBrdf;
using runtime::normalize;
using runtime::Rgb;

constexpr int kTile = 16;

Vec3 lightVec(const Vec3d& v) { return Vec3{v[0], v[1], v[2]}; }

uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// A counter-based stream of uniforms in [0, 1) keyed by (seed, pixel, light): splitmix64.
class Stream {
 public:
  Stream(uint64_t seed, uint64_t pixel, uint64_t light)
      : state_(mix64(mix64(seed * 0x9E3779B97F4A7C15ull + pixel) ^ (light + 0x632BE59BD9B4E019ull))) {}
  double next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return double(mix64(state_) >> 11) * 0x1.0p-53;
  }

 private:
  uint64_t state_;
};

// A polygon light split into a fan of triangles with an area CDF.
struct PolygonLight {
  std::vector<Vec3> a, e1, e2;  // triangle i = a[i] + s e1[i] + t e2[i]
  std::vector<double> cdf;
  double area = 0.0;
  Vec3 normal;
};

PolygonLight makePolygon(const Light& light) {
  PolygonLight p;
  const Vec3 v0 = lightVec(light.vertices[0]);
  Vec3 nsum;
  for (size_t i = 1; i + 1 < light.vertices.size(); ++i) {
    const Vec3 e1 = lightVec(light.vertices[i]) - v0, e2 = lightVec(light.vertices[i + 1]) - v0;
    const Vec3 c = runtime::cross(e1, e2);
    const double area = 0.5 * std::sqrt(dot(c, c));
    p.a.push_back(v0);
    p.e1.push_back(e1);
    p.e2.push_back(e2);
    p.area += area;
    p.cdf.push_back(p.area);
    nsum = nsum + c;
  }
  p.normal = normalize(nsum);
  return p;
}

// Ray-polygon distance (Moller-Trumbore over the fan) or a negative value.
double hitPolygon(const PolygonLight& poly, const Vec3& o, const Vec3& d) {
  for (size_t i = 0; i < poly.a.size(); ++i) {
    const Vec3 pv = runtime::cross(d, poly.e2[i]);
    const double det = dot(poly.e1[i], pv);
    if (std::fabs(det) < 1e-18) continue;
    const double inv = 1.0 / det;
    const Vec3 tv = o - poly.a[i];
    const double u = dot(tv, pv) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const Vec3 qv = runtime::cross(tv, poly.e1[i]);
    const double v = dot(d, qv) * inv;
    if (v < 0.0 || u + v > 1.0) continue;
    const double t = dot(poly.e2[i], qv) * inv;
    if (t > 1e-9) return t;
  }
  return -1.0;
}

double powerHeuristic(double a, double b) {
  const double a2 = a * a, b2 = b * b;
  return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

struct Frame {
  Vec3 t, b, n;
  Vec3 toLocal(const Vec3& w) const { return Vec3{dot(w, t), dot(w, b), dot(w, n)}; }
  Vec3 toWorld(const Vec3& w) const { return w.x * t + w.y * b + w.z * n; }
};

void add(Rgb* acc, const Rgb& c, double k) {
  acc->r += c.r * k;
  acc->g += c.g * k;
  acc->b += c.b * k;
}

Rgb toRgb(const Vec3d& c) { return Rgb{c[0], c[1], c[2]}; }

class Shader {
 public:
  Shader(const Scene& scene, const RenderOptions& options) : scene_(scene), options_(options) {
    for (const Light& l : scene.lights) {
      polygons_.push_back(l.type == LightType::kPolygon ? makePolygon(l) : PolygonLight{});
    }
  }

  // Outgoing radiance at the hit towards wo (world). Returns false when an NDF query failed.
  bool shade(const MicrofacetBrdf& brdf, const SurfaceHit& hit, const Vec3& wo_world, uint64_t pixel, Rgb* out) const {
    const Frame frame{hit.tangent, hit.bitangent, hit.normal};
    const Vec3 wo = frame.toLocal(wo_world);
    Rgb total;
    if (!(wo.z > 0.0)) {
      *out = total;
      return true;
    }
    for (size_t li = 0; li < scene_.lights.size(); ++li) {
      const Light& light = scene_.lights[li];
      Stream rng(options_.seed, pixel, li);
      bool ok = true;
      switch (light.type) {
        case LightType::kPoint:
          ok = shadePoint(brdf, light, frame, hit, wo, &total);
          break;
        case LightType::kDirectional:
          ok = shadeDirectional(brdf, light, frame, wo, &total);
          break;
        case LightType::kPolygon:
          ok = shadePolygon(brdf, light, frame, hit, wo, wo_world, li, rng, &total);
          break;
        case LightType::kSphericalGaussian:
          ok = shadeSg(brdf, light, frame, wo, rng, &total);
          break;
        case LightType::kUniform:
          ok = shadeUniform(brdf, light, wo, rng, &total);
          break;
      }
      if (!ok) return false;
    }
    *out = total;
    return true;
  }

  // A point light: the BRDF at its direction, over the squared distance.
  bool shadePoint(const MicrofacetBrdf& brdf, const Light& light, const Frame& frame, const SurfaceHit& hit,
                  const Vec3& wo, Rgb* total) const {
    const Vec3 d = lightVec(light.position) - hit.position;
    const double d2 = dot(d, d);
    if (!(d2 > 0.0)) return true;
    const Vec3 wi = frame.toLocal((1.0 / std::sqrt(d2)) * d);
    Rgb f;
    if (brdf.eval(wi, wo, &f) != runtime::RuntimeStatus::kOk) return false;
    const double k = std::fmax(0.0, wi.z) / d2;
    total->r += f.r * light.color[0] * k;
    total->g += f.g * light.color[1] * k;
    total->b += f.b * light.color[2] * k;
    return true;
  }

  // A directional light: the BRDF at its direction.
  bool shadeDirectional(const MicrofacetBrdf& brdf, const Light& light, const Frame& frame, const Vec3& wo,
                        Rgb* total) const {
    const Vec3 wi = frame.toLocal(normalize(lightVec(light.direction)));
    Rgb f;
    if (brdf.eval(wi, wo, &f) != runtime::RuntimeStatus::kOk) return false;
    const double k = std::fmax(0.0, wi.z);
    total->r += f.r * light.color[0] * k;
    total->g += f.g * light.color[1] * k;
    total->b += f.b * light.color[2] * k;
    return true;
  }

  // A polygon light: the LTC table when given, else light and BRDF samples with MIS.
  bool shadePolygon(const MicrofacetBrdf& brdf, const Light& light, const Frame& frame, const SurfaceHit& hit,
                    const Vec3& wo, const Vec3& wo_world, size_t li, Stream& rng, Rgb* total) const {
    const double inv_spp = 1.0 / options_.spp;
    if (options_.ltc != nullptr) {
      add(total, shadeLtc(light, hit, wo_world, brdf), 1.0);
      return true;
    }
    const PolygonLight& poly = polygons_[li];
    Rgb acc;
    for (int n = 0; n < options_.spp; ++n) {
      // Light sample: a uniform point of the polygon.
      const double ut = rng.next() * poly.area, us = rng.next(), uv = rng.next();
      size_t tri = 0;
      while (tri + 1 < poly.cdf.size() && ut > poly.cdf[tri]) ++tri;
      const double su = std::sqrt(us);
      const Vec3 y = poly.a[tri] + (su * (1.0 - uv)) * poly.e1[tri] + (su * uv) * poly.e2[tri];
      const Vec3 d = y - hit.position;
      const double d2 = dot(d, d);
      const Vec3 wi_world = (1.0 / std::sqrt(d2)) * d;
      const double cos_l = std::fabs(dot(poly.normal, wi_world));
      if (cos_l > 1e-12) {
        const Vec3 wi = frame.toLocal(wi_world);
        Rgb f;
        double bpdf = 0.0;
        if (brdf.eval(wi, wo, &f) != runtime::RuntimeStatus::kOk) return false;
        if (wi.z > 0.0 && (f.r > 0.0 || f.g > 0.0 || f.b > 0.0)) {
          if (brdf.pdf(wi, wo, &bpdf) != runtime::RuntimeStatus::kOk) return false;
          const double lpdf = d2 / (poly.area * cos_l);
          add(&acc, f, wi.z * powerHeuristic(lpdf, bpdf) / lpdf);
        }
      }
      // BRDF sample.
      BrdfSample s;
      if (brdf.sample(wo, rng.next(), rng.next(), &s) != runtime::RuntimeStatus::kOk) return false;
      if (s.pdf > 0.0 && s.wi.z > 0.0) {
        const Vec3 wi_world2 = frame.toWorld(s.wi);
        const double t = hitPolygon(poly, hit.position, wi_world2);
        if (t > 0.0) {
          const double c2 = std::fabs(dot(poly.normal, wi_world2));
          const double lpdf = c2 > 0.0 ? t * t / (poly.area * c2) : 0.0;
          add(&acc, s.weight, powerHeuristic(s.pdf, lpdf));
        }
      }
    }
    total->r += acc.r * light.color[0] * inv_spp;
    total->g += acc.g * light.color[1] * inv_spp;
    total->b += acc.b * light.color[2] * inv_spp;
    return true;
  }

  // A spherical-Gaussian environment: prefiltered with assets (--env prefilter), else light and BRDF
  // samples with MIS.
  bool shadeSg(const MicrofacetBrdf& brdf, const Light& light, const Frame& frame, const Vec3& wo, Stream& rng,
               Rgb* total) const {
    const double inv_spp = 1.0 / options_.spp;
    runtime::SphericalGaussian sg;
    sg.axis = normalize(lightVec(light.direction));
    sg.sharpness = light.sharpness;
    sg.amplitude = toRgb(light.color);
    if (options_.mode == NdfMode::kAsset && options_.env_method == EnvMethod::kPrefilter) {
      runtime::SphericalGaussian local = sg;
      local.axis = frame.toLocal(sg.axis);
      const double amp = std::fmax(sg.amplitude.r, std::fmax(sg.amplitude.g, sg.amplitude.b));
      if (!(amp > 0.0)) return true;
      Rgb radiance;
      if (runtime::prefilteredSgShading(brdf, local, options_.sg_epsilon * amp, wo, &radiance) !=
          runtime::RuntimeStatus::kOk) {
        return false;
      }
      add(total, radiance, 1.0);
      return true;
    }
    Rgb acc;
    for (int n = 0; n < options_.spp; ++n) {
      double lpdf = 0.0;
      const Vec3 wi_world = runtime::sampleSg(sg, rng.next(), rng.next(), &lpdf);
      const Vec3 wi = frame.toLocal(wi_world);
      if (wi.z > 0.0 && lpdf > 0.0) {
        Rgb f;
        double bpdf = 0.0;
        if (brdf.eval(wi, wo, &f) != runtime::RuntimeStatus::kOk) return false;
        if (f.r > 0.0 || f.g > 0.0 || f.b > 0.0) {
          if (brdf.pdf(wi, wo, &bpdf) != runtime::RuntimeStatus::kOk) return false;
          const Rgb le = runtime::evalSg(sg, wi_world);
          const double k = wi.z * powerHeuristic(lpdf, bpdf) / lpdf;
          acc.r += f.r * le.r * k;
          acc.g += f.g * le.g * k;
          acc.b += f.b * le.b * k;
        }
      }
      BrdfSample s;
      if (brdf.sample(wo, rng.next(), rng.next(), &s) != runtime::RuntimeStatus::kOk) return false;
      if (s.pdf > 0.0 && s.wi.z > 0.0) {
        const Vec3 w = frame.toWorld(s.wi);
        const Rgb le = runtime::evalSg(sg, w);
        const double k = powerHeuristic(s.pdf, runtime::sgPdf(sg, w));
        acc.r += s.weight.r * le.r * k;
        acc.g += s.weight.g * le.g * k;
        acc.b += s.weight.b * le.b * k;
      }
    }
    add(total, acc, inv_spp);
    return true;
  }

  // A uniform environment: BRDF samples.
  bool shadeUniform(const MicrofacetBrdf& brdf, const Light& light, const Vec3& wo, Stream& rng, Rgb* total) const {
    const double inv_spp = 1.0 / options_.spp;
    Rgb acc;
    for (int n = 0; n < options_.spp; ++n) {
      BrdfSample s;
      if (brdf.sample(wo, rng.next(), rng.next(), &s) != runtime::RuntimeStatus::kOk) return false;
      if (s.pdf > 0.0 && s.wi.z > 0.0) add(&acc, s.weight, 1.0);
    }
    total->r += acc.r * light.color[0] * inv_spp;
    total->g += acc.g * light.color[1] * inv_spp;
    total->b += acc.b * light.color[2] * inv_spp;
    return true;
  }

  // Polygon light through the LTC table: radiance x integral of the LTC over the polygon x the
  // Schlick magnitude per channel.
  Rgb shadeLtc(const Light& light, const SurfaceHit& hit, const Vec3& wo_world, const MicrofacetBrdf& brdf) const {
    const float n[3] = {float(hit.normal.x), float(hit.normal.y), float(hit.normal.z)};
    const float v[3] = {float(wo_world.x), float(wo_world.y), float(wo_world.z)};
    float fx[3], fy[3], fz[3];
    runtime::ltcShadingFrame(n, v, fx, fy, fz);
    runtime::LtcCoefficients ltc;
    if (options_.ltc->lookup(float(std::sqrt(brdf.alpha())), runtime::ltcCosTheta(n, v), &ltc) !=
        runtime::RuntimeStatus::kOk) {
      return Rgb{};
    }
    float verts[runtime::kLtcMaxPolygonVertices][3];
    const int count = std::min(int(light.vertices.size()), runtime::kLtcMaxPolygonVertices);
    for (int i = 0; i < count; ++i) {
      const Vec3 d = lightVec(light.vertices[size_t(i)]) - hit.position;
      verts[i][0] = float(d.x * fx[0] + d.y * fx[1] + d.z * fx[2]);
      verts[i][1] = float(d.x * fy[0] + d.y * fy[1] + d.z * fy[2]);
      verts[i][2] = float(d.x * fz[0] + d.y * fz[1] + d.z * fz[2]);
    }
    const double integral = runtime::ltcIntegratePolygon(ltc, verts, count, true);
    const Rgb f0 = runtime::evalFresnel(brdf.fresnel(), 1.0);  // reflectance at normal incidence
    return Rgb{light.color[0] * integral * runtime::ltcFresnelMagnitude(ltc, float(f0.r)),
               light.color[1] * integral * runtime::ltcFresnelMagnitude(ltc, float(f0.g)),
               light.color[2] * integral * runtime::ltcFresnelMagnitude(ltc, float(f0.b))};
  }

 private:
  const Scene& scene_;
  const RenderOptions& options_;
  std::vector<PolygonLight> polygons_;
};

runtime::Fresnel makeFresnel(const Material& m) {
  runtime::Fresnel f;
  f.kind = m.fresnel == FresnelType::kNone      ? runtime::FresnelKind::kNone
           : m.fresnel == FresnelType::kSchlick ? runtime::FresnelKind::kSchlick
                                                : runtime::FresnelKind::kConductor;
  f.f0 = toRgb(m.f0);
  f.eta = toRgb(m.eta);
  f.k = toRgb(m.k);
  return f;
}

}  // namespace

const char* ndfModeString(NdfMode mode) {
  switch (mode) {
    case NdfMode::kReference:
      return "reference";
    case NdfMode::kAsset:
      return "asset";
    case NdfMode::kSmooth:
    default:
      return "smooth";
  }
}

bool ndfModeFromString(const std::string& text, NdfMode* mode) {
  if (text == "reference") {
    *mode = NdfMode::kReference;
  } else if (text == "asset") {
    *mode = NdfMode::kAsset;
  } else if (text == "smooth") {
    *mode = NdfMode::kSmooth;
  } else {
    return false;
  }
  return true;
}

Result<RenderedImage> renderScene(const Scene& scene, const NdfInputs& inputs, const RenderOptions& options) {
  if (options.spp < 1 || options.spp > 65536) return makeError(ErrorCode::kBadArgument, "spp must be in [1, 65536]");
  if (!(options.sg_epsilon > 0.0 && options.sg_epsilon < 1.0)) {
    return makeError(ErrorCode::kBadArgument, "the SG support epsilon must be in (0, 1)");
  }
  if (options.mode == NdfMode::kReference && inputs.flakes == nullptr) {
    return makeError(ErrorCode::kBadArgument, "--ndf reference needs the material's normal_map");
  }
  if (options.mode == NdfMode::kAsset && inputs.asset == nullptr) {
    return makeError(ErrorCode::kBadArgument, "--ndf asset needs the material's asset");
  }
  if (options.ltc != nullptr &&
      (options.mode != NdfMode::kSmooth || scene.material.shadowing != ShadowingModel::kGgx)) {
    return makeError(ErrorCode::kBadArgument, "LTC area lights need --ndf smooth and GGX shadowing");
  }
  if (options.ltc != nullptr) {
    for (const Light& l : scene.lights) {
      if (l.type == LightType::kPolygon && l.vertices.size() > size_t(runtime::kLtcMaxPolygonVertices)) {
        return makeError(ErrorCode::kBadArgument, "LTC area lights take polygons of at most " +
                                                      std::to_string(runtime::kLtcMaxPolygonVertices) + " vertices");
      }
    }
  }
  if (options.mode != NdfMode::kSmooth && (inputs.map_width < 1 || inputs.map_height < 1)) {
    return makeError(ErrorCode::kBadArgument, "the map size is unknown (give material.map_size)");
  }
  const Camera& cam = scene.camera;
  const Material& mat = scene.material;
  const CameraModel camera(cam);
  const ObjectModel object(scene.object);
  const Shader shader(scene, options);
  const runtime::Fresnel fresnel = makeFresnel(mat);
  const runtime::MicrofacetModel model =
      mat.shadowing == ShadowingModel::kBeckmann ? runtime::MicrofacetModel::kBeckmann : runtime::MicrofacetModel::kGgx;

  // Unbounded assets answer anywhere on the plane: their footprints are not wrapped into one map.
  const bool unbounded = options.mode == NdfMode::kAsset && inputs.asset != nullptr &&
                         inputs.asset->wrap() == runtime::MapWrap::kUnbounded;

  RenderedImage image;
  image.width = cam.width;
  image.height = cam.height;
  image.rgb.assign(size_t(cam.width) * cam.height * 3, 0.0f);
  std::vector<float> sigmas(size_t(cam.width) * cam.height, -1.0f);
  std::atomic<bool> failed{false};

  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, cam.height, kTile, 0, cam.width, kTile), [&](const tbb::blocked_range2d<int>& tile) {
        if (failed.load() || (options.cancel != nullptr && options.cancel->load())) return;
        ReferencePndf ref;  // --ndf reference: one lobe store per tile, re-aimed at each pixel
        for (int y = tile.rows().begin(); y < tile.rows().end(); ++y) {
          for (int x = tile.cols().begin(); x < tile.cols().end(); ++x) {
            const size_t index = size_t(y) * cam.width + x;
            const RayWithDifferentials rays = camera.generate(x + 0.5, y + 0.5);
            SurfaceHit hit;
            Rgb color = toRgb(scene.background);
            if (object.intersect(rays.ray, &hit)) {
              const runtime::Footprint fp =
                  pixelFootprint(rays, hit, cam.pixel_sigma, std::max(1, inputs.map_width),
                                 std::max(1, inputs.map_height), scene.object.uv_scale, 1e-3, !unbounded);
              sigmas[index] = float(fp.sigma);
              const Vec3 wo = -1.0 * rays.ray.direction;
              bool ok = true;
              if (options.mode == NdfMode::kSmooth) {
                ok = shader.shade(MicrofacetBrdf::smooth(model, mat.alpha, fresnel), hit, wo, index, &color);
              } else if (options.mode == NdfMode::kAsset) {
                ok = shader.shade(MicrofacetBrdf::glinty(inputs.asset, fp, model, mat.alpha, fresnel), hit, wo, index,
                                  &color);
              } else {
                ref.gather(*inputs.flakes, fp, mat.sigma_r);
                ok = shader.shade(MicrofacetBrdf::glinty(&ref, fp, model, mat.alpha, fresnel), hit, wo, index, &color);
              }
              if (!ok) failed.store(true);
            }
            image.rgb[index * 3 + 0] = float(color.r);
            image.rgb[index * 3 + 1] = float(color.g);
            image.rgb[index * 3 + 2] = float(color.b);
          }
        }
        if (options.progress) {
          options.progress(uint64_t(tile.rows().size()) * uint64_t(tile.cols().size()));
        }
      });
  if (failed.load()) return makeError(ErrorCode::kRuntime, "an NDF query failed during rendering");
  if (options.cancel != nullptr && options.cancel->load()) return makeError(ErrorCode::kRuntime, "cancelled");
  // Statistics in pixel order (deterministic).
  double sum = 0.0;
  double radiance[3] = {0.0, 0.0, 0.0};
  for (size_t i = 0; i < sigmas.size(); ++i) {
    if (sigmas[i] < 0.0f) continue;
    ++image.stats.pixels_hit;
    sum += sigmas[i];
    image.stats.max_sigma_texels = std::max(image.stats.max_sigma_texels, double(sigmas[i]));
    for (int k = 0; k < 3; ++k) radiance[k] += image.rgb[i * 3 + k];
  }
  if (image.stats.pixels_hit > 0) {
    const double n = double(image.stats.pixels_hit);
    image.stats.mean_sigma_texels = sum / n;
    for (int k = 0; k < 3; ++k) image.stats.mean_radiance[k] = radiance[k] / n;
  }
  return image;
}

}  // namespace glintbake::bake::render
