// SPDX-License-Identifier: Apache-2.0
// Camera rays, object intersection and pixel footprints.
#include <glintbake/bake/render/geometry.h>
#include <glintbake/format/numbers.h>

#include <cmath>

namespace glintbake::bake::render {
namespace {

constexpr double kMinT = 1e-9;

Vec3 toVec(const Vec3d& v) { return Vec3{v[0], v[1], v[2]}; }
using runtime::cross;
using runtime::dot;
using runtime::normalize;

double wrap01(double x) {
  double f = x - std::floor(x);
  if (f >= 1.0) f = 0.0;
  return f;
}

// Completes a hit from dP/du and dP/dv: the tangent frame (tangent along dP/du, bitangent the
// texture up direction -dP/dv made orthogonal, normal their cross product).
void buildFrame(SurfaceHit* hit, const Vec3& outward) {
  Vec3 t = normalize(hit->dpdu);
  Vec3 n = normalize(outward);
  if (!(dot(t, t) > 0.5)) {
    // Degenerate parameterisation (a sphere's pole): any tangent will do.
    t = normalize(std::fabs(n.x) < 0.9 ? cross(Vec3{1, 0, 0}, n) : cross(Vec3{0, 1, 0}, n));
  }
  t = normalize(t - dot(t, n) * n);
  hit->tangent = t;
  hit->normal = n;
  hit->bitangent = cross(n, t);  // then t x b = n
}

}  // namespace

CameraModel::CameraModel(const Camera& camera) : camera_(camera) {
  forward_ = normalize(toVec(camera.look_at) - toVec(camera.position));
  right_ = normalize(cross(forward_, toVec(camera.up)));
  up_ = cross(right_, forward_);
  half_height_ = camera.type == CameraType::kPerspective ? std::tan(0.5 * camera.fov_degrees * kPi / 180.0)
                                                         : 0.5 * camera.ortho_height;
}

RayWithDifferentials CameraModel::generate(double px, double py) const {
  const double aspect = double(camera_.width) / camera_.height;
  auto make = [&](double x, double y) {
    // Screen coordinates in [-1, 1] vertically (y up), scaled by the aspect horizontally.
    const double sx = (2.0 * x / camera_.width - 1.0) * aspect * half_height_;
    const double sy = (1.0 - 2.0 * y / camera_.height) * half_height_;
    Ray r;
    if (camera_.type == CameraType::kPerspective) {
      r.origin = toVec(camera_.position);
      r.direction = normalize(forward_ + sx * right_ + sy * up_);
    } else {
      r.origin = toVec(camera_.position) + sx * right_ + sy * up_;
      r.direction = forward_;
    }
    return r;
  };
  return RayWithDifferentials{make(px, py), make(px + 1.0, py), make(px, py + 1.0)};
}

ObjectModel::ObjectModel(const Object& object) : object_(object) {
  bend_ = object.bend_degrees * kPi / 180.0;
  bend_radius_ = bend_ > 1e-6 ? object.size / bend_ : 0.0;
}

bool ObjectModel::intersect(const Ray& ray, SurfaceHit* hit) const {
  switch (object_.type) {
    case ObjectType::kSphere:
      return intersectSphere(ray, hit);
    case ObjectType::kBentQuad:
      return bend_radius_ > 0.0 ? intersectCylinder(ray, hit) : intersectPlane(ray, hit);
    case ObjectType::kPlane:
    default:
      return intersectPlane(ray, hit);
  }
}

bool ObjectModel::intersectPlane(const Ray& ray, SurfaceHit* hit) const {
  const Vec3 c = toVec(object_.center);
  if (std::fabs(ray.direction.y) < 1e-15) return false;
  const double t = (c.y - ray.origin.y) / ray.direction.y;
  if (!(t > kMinT)) return false;
  const Vec3 p = ray.origin + t * ray.direction;
  const double u = (p.x - c.x) / object_.size + 0.5;
  const double v = (p.z - c.z) / object_.size + 0.5;
  if (u < 0.0 || u >= 1.0 || v < 0.0 || v >= 1.0) return false;
  hit->t = t;
  hit->position = p;
  hit->u = u;
  hit->v = v;
  hit->dpdu = Vec3{object_.size, 0.0, 0.0};
  hit->dpdv = Vec3{0.0, 0.0, object_.size};
  buildFrame(hit, Vec3{0.0, 1.0, 0.0});
  return true;
}

bool ObjectModel::intersectSphere(const Ray& ray, SurfaceHit* hit) const {
  const Vec3 c = toVec(object_.center);
  const double r = object_.radius;
  const Vec3 oc = ray.origin - c;
  const double b = dot(oc, ray.direction);
  const double cc = dot(oc, oc) - r * r;
  const double disc = b * b - cc;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  double t = -b - sq;
  if (!(t > kMinT)) t = -b + sq;
  if (!(t > kMinT)) return false;
  const Vec3 p = ray.origin + t * ray.direction;
  const Vec3 d = (1.0 / r) * (p - c);
  // p = c + r (sin(theta) cos(phi), cos(theta), -sin(theta) sin(phi)), u = phi / 2pi, v = theta / pi.
  const double theta = std::acos(std::fmax(-1.0, std::fmin(1.0, d.y)));
  double phi = std::atan2(-d.z, d.x);
  if (phi < 0.0) phi += 2.0 * kPi;
  hit->t = t;
  hit->position = p;
  hit->u = wrap01(phi / (2.0 * kPi));
  hit->v = std::fmin(theta / kPi, std::nextafter(1.0, 0.0));
  const double st = std::sin(theta), ct = std::cos(theta), sp = std::sin(phi), cp = std::cos(phi);
  hit->dpdu = (2.0 * kPi * r) * Vec3{-st * sp, 0.0, -st * cp};
  hit->dpdv = (kPi * r) * Vec3{ct * cp, -st, -ct * sp};
  buildFrame(hit, d);
  return true;
}

bool ObjectModel::intersectCylinder(const Ray& ray, SurfaceHit* hit) const {
  // Axis parallel to z through (cx, cy - R); the strip spans angles a in [-bend/2, bend/2] from +y:
  // p = axis + (R sin a, R cos a, z), u = a / bend + 1/2, v = z / size + 1/2.
  const Vec3 c = toVec(object_.center);
  const double R = bend_radius_;
  const double ox = ray.origin.x - c.x, oy = ray.origin.y - (c.y - R);
  const double dx = ray.direction.x, dy = ray.direction.y;
  const double qa = dx * dx + dy * dy;
  if (qa < 1e-30) return false;
  const double qb = ox * dx + oy * dy;
  const double qc = ox * ox + oy * oy - R * R;
  const double disc = qb * qb - qa * qc;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  const double roots[2] = {(-qb - sq) / qa, (-qb + sq) / qa};
  for (double t : roots) {
    if (!(t > kMinT)) continue;
    const Vec3 p = ray.origin + t * ray.direction;
    const double px = p.x - c.x, py = p.y - (c.y - R);
    const double a = std::atan2(px, py);
    const double u = a / bend_ + 0.5;
    const double v = (p.z - c.z) / object_.size + 0.5;
    if (u < 0.0 || u >= 1.0 || v < 0.0 || v >= 1.0) continue;
    hit->t = t;
    hit->position = p;
    hit->u = u;
    hit->v = v;
    hit->dpdu = (bend_ * R) * Vec3{std::cos(a), -std::sin(a), 0.0};
    hit->dpdv = Vec3{0.0, 0.0, object_.size};
    buildFrame(hit, Vec3{std::sin(a), std::cos(a), 0.0});
    return true;
  }
  return false;
}

runtime::Footprint pixelFootprint(const RayWithDifferentials& rays, const SurfaceHit& hit, double pixel_sigma,
                                  int map_width, int map_height, double uv_scale, double min_sigma, bool wrap) {
  // Offset rays meet the tangent plane of the hit (pbrt-v4 section 10.1.1).
  auto planePoint = [&](const Ray& r, Vec3* p) {
    const double denom = dot(hit.normal, r.direction);
    if (std::fabs(denom) < 1e-12) return false;
    const double t = dot(hit.normal, hit.position - r.origin) / denom;
    *p = r.origin + t * r.direction;
    return true;
  };
  Vec3 px, py;
  double dudx = 0.0, dvdx = 0.0, dudy = 0.0, dvdy = 0.0;
  if (planePoint(rays.dx, &px) && planePoint(rays.dy, &py)) {
    const Vec3 dpdx = px - hit.position, dpdy = py - hit.position;
    // Least squares of dp = dpdu du + dpdv dv (normal equations of the 3 x 2 system).
    const double a = dot(hit.dpdu, hit.dpdu), b = dot(hit.dpdu, hit.dpdv), d = dot(hit.dpdv, hit.dpdv);
    const double det = a * d - b * b;
    if (std::fabs(det) > 1e-300) {
      const double inv = 1.0 / det;
      const double ex = dot(hit.dpdu, dpdx), fx = dot(hit.dpdv, dpdx);
      const double ey = dot(hit.dpdu, dpdy), fy = dot(hit.dpdv, dpdy);
      dudx = (d * ex - b * fx) * inv;
      dvdx = (a * fx - b * ex) * inv;
      dudy = (d * ey - b * fy) * inv;
      dvdy = (a * fy - b * ey) * inv;
    }
  }
  const double sx = map_width * uv_scale, sy = map_height * uv_scale;
  const double j00 = sx * dudx, j01 = sx * dudy, j10 = sy * dvdx, j11 = sy * dvdy;
  double sigma = pixel_sigma * std::sqrt(0.5 * (j00 * j00 + j01 * j01 + j10 * j10 + j11 * j11));
  if (!std::isfinite(sigma)) sigma = 1e6;
  runtime::Footprint fp;
  fp.x = (wrap ? wrap01(hit.u * uv_scale) : hit.u * uv_scale) * map_width;
  fp.y = (wrap ? wrap01(hit.v * uv_scale) : hit.v * uv_scale) * map_height;
  fp.sigma = std::fmin(1e6, std::fmax(min_sigma, sigma));
  return fp;
}

}  // namespace glintbake::bake::render
