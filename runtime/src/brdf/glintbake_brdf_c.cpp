// SPDX-License-Identifier: Apache-2.0
// The C API over brdf.h and sg.h.
#include <glintbake/runtime/brdf.h>
#include <glintbake/runtime/glintbake_brdf_c.h>
#include <glintbake/runtime/sg.h>

#include <memory>
#include <new>

struct gb_brdf_ndf {
  std::unique_ptr<glintbake::runtime::NdfSource> source;
};

namespace {

using namespace glintbake::runtime;

int32_t statusCode(RuntimeStatus s) { return static_cast<int32_t>(s); }

Vec3 toVec(const double v[3]) { return Vec3{v[0], v[1], v[2]}; }
Rgb toRgb(const double v[3]) { return Rgb{v[0], v[1], v[2]}; }
void fromRgb(const Rgb& c, double out[3]) {
  out[0] = c.r;
  out[1] = c.g;
  out[2] = c.b;
}

bool makeBrdf(const gb_brdf_params* p, MicrofacetBrdf* out) {
  if (p == nullptr) return false;
  if (p->model != GB_MODEL_GGX && p->model != GB_MODEL_BECKMANN) return false;
  if (p->fresnel < GB_FRESNEL_NONE || p->fresnel > GB_FRESNEL_CONDUCTOR) return false;
  if (!(p->alpha >= kMinAlpha && p->alpha <= 4.0)) return false;
  Fresnel fresnel;
  fresnel.kind = static_cast<FresnelKind>(p->fresnel);
  fresnel.f0 = toRgb(p->f0);
  fresnel.eta = toRgb(p->eta);
  fresnel.k = toRgb(p->k);
  const MicrofacetModel model = static_cast<MicrofacetModel>(p->model);
  if (p->ndf == nullptr) {
    *out = MicrofacetBrdf::smooth(model, p->alpha, fresnel);
  } else {
    Footprint fp;
    fp.x = p->x;
    fp.y = p->y;
    fp.sigma = p->sigma;
    *out = MicrofacetBrdf::glinty(p->ndf->source.get(), fp, model, p->alpha, fresnel);
  }
  return true;
}

bool makeSg(const gb_sg* in, SphericalGaussian* out) {
  if (in == nullptr) return false;
  out->axis = toVec(in->axis);
  out->sharpness = in->sharpness;
  out->amplitude = toRgb(in->amplitude);
  return in->sharpness > 0.0;
}

}  // namespace

extern "C" {

int32_t gb_brdf_ndf_open(const char* path, gb_brdf_ndf** out) {
  if (out == nullptr) return statusCode(RuntimeStatus::kInvalidArgument);
  *out = nullptr;
  if (path == nullptr) return statusCode(RuntimeStatus::kInvalidArgument);
  std::unique_ptr<NdfSource> source;
  const RuntimeStatus st = openNdfAsset(path, &source);
  if (st != RuntimeStatus::kOk) return statusCode(st);
  gb_brdf_ndf* ndf = new (std::nothrow) gb_brdf_ndf;
  if (ndf == nullptr) return statusCode(RuntimeStatus::kOutOfMemory);
  ndf->source = std::move(source);
  *out = ndf;
  return statusCode(RuntimeStatus::kOk);
}

void gb_brdf_ndf_close(gb_brdf_ndf* ndf) { delete ndf; }

int32_t gb_brdf_eval(const gb_brdf_params* params, const double wi[3], const double wo[3], double f[3]) {
  MicrofacetBrdf brdf;
  if (!makeBrdf(params, &brdf) || wi == nullptr || wo == nullptr || f == nullptr)
    return statusCode(RuntimeStatus::kInvalidArgument);
  Rgb value;
  const RuntimeStatus st = brdf.eval(toVec(wi), toVec(wo), &value);
  if (st == RuntimeStatus::kOk) fromRgb(value, f);
  return statusCode(st);
}

int32_t gb_brdf_sample(const gb_brdf_params* params, const double wo[3], double u1, double u2, double wi[3],
                       double* pdf, double weight[3]) {
  MicrofacetBrdf brdf;
  if (!makeBrdf(params, &brdf) || wo == nullptr || wi == nullptr || pdf == nullptr || weight == nullptr)
    return statusCode(RuntimeStatus::kInvalidArgument);
  BrdfSample s;
  const RuntimeStatus st = brdf.sample(toVec(wo), u1, u2, &s);
  if (st != RuntimeStatus::kOk) return statusCode(st);
  wi[0] = s.wi.x;
  wi[1] = s.wi.y;
  wi[2] = s.wi.z;
  *pdf = s.pdf;
  fromRgb(s.weight, weight);
  return statusCode(RuntimeStatus::kOk);
}

int32_t gb_brdf_pdf(const gb_brdf_params* params, const double wi[3], const double wo[3], double* pdf) {
  MicrofacetBrdf brdf;
  if (!makeBrdf(params, &brdf) || wi == nullptr || wo == nullptr || pdf == nullptr)
    return statusCode(RuntimeStatus::kInvalidArgument);
  return statusCode(brdf.pdf(toVec(wi), toVec(wo), pdf));
}

int32_t gb_sg_support(const gb_sg* sg, double eps, double* cos_theta_max, int32_t* empty) {
  SphericalGaussian g;
  if (!makeSg(sg, &g) || !(eps > 0.0) || cos_theta_max == nullptr || empty == nullptr)
    return statusCode(RuntimeStatus::kInvalidArgument);
  const SgSupport support = sgSupport(g, eps);
  *cos_theta_max = support.cos_theta_max;
  *empty = support.empty ? 1 : 0;
  return statusCode(RuntimeStatus::kOk);
}

int32_t gb_sg_integral(const gb_sg* sg, double integral[3]) {
  SphericalGaussian g;
  if (!makeSg(sg, &g) || integral == nullptr) return statusCode(RuntimeStatus::kInvalidArgument);
  fromRgb(sgIntegral(g), integral);
  return statusCode(RuntimeStatus::kOk);
}

int32_t gb_sg_prefiltered_shading(const gb_brdf_params* params, const gb_sg* sg, double eps, const double wo[3],
                                  double radiance[3]) {
  MicrofacetBrdf brdf;
  SphericalGaussian g;
  if (!makeBrdf(params, &brdf) || !makeSg(sg, &g) || wo == nullptr || radiance == nullptr)
    return statusCode(RuntimeStatus::kInvalidArgument);
  Rgb value;
  const RuntimeStatus st = prefilteredSgShading(brdf, g, eps, toVec(wo), &value);
  if (st == RuntimeStatus::kOk) fromRgb(value, radiance);
  return statusCode(st);
}

}  // extern "C"
