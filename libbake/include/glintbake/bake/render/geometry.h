// SPDX-License-Identifier: Apache-2.0
// Camera rays with differentials, ray-object intersection, the shading frame and the texel
// footprint of a pixel (Igehy 1999, "Tracing Ray Differentials"; pbrt-v4 section 10.1).
#pragma once

#include <glintbake/bake/render/scene.h>
#include <glintbake/runtime/brdf.h>

namespace glintbake::bake::render {

using runtime::Vec3;

struct Ray {
  Vec3 origin;
  Vec3 direction;  // unit
};

// A camera ray through a pixel position plus the rays one pixel to the right and one pixel down.
struct RayWithDifferentials {
  Ray ray, dx, dy;
};

// The camera of a scene, ready to generate rays. Thread-safe (const).
class CameraModel {
 public:
  explicit CameraModel(const Camera& camera);
  // Ray through image position (px, py) in pixels (pixel (i, j) spans [i, i+1) x [j, j+1), row 0
  // at the top).
  RayWithDifferentials generate(double px, double py) const;

 private:
  Camera camera_;
  Vec3 forward_, right_, up_;
  double half_height_ = 1.0;  // perspective: tan(fov / 2); orthographic: half the view height
};

// What a camera ray sees on the object.
struct SurfaceHit {
  double t = 0.0;
  Vec3 position;
  Vec3 tangent;             // unit, along +u (texture x: right)
  Vec3 bitangent;           // unit, texture up (along -v: rows go down)
  Vec3 normal;              // unit, outward, = tangent x bitangent
  double u = 0.0, v = 0.0;  // texture coordinates in [0, 1)
  Vec3 dpdu, dpdv;          // partial derivatives of the position (world units per unit uv)
};

// The object of a scene. Thread-safe (const).
class ObjectModel {
 public:
  explicit ObjectModel(const Object& object);
  // Nearest hit with t > 1e-9 (world units) or false.
  bool intersect(const Ray& ray, SurfaceHit* hit) const;

 private:
  Object object_;
  double bend_ = 0.0;         // bent_quad: bend angle in radians
  double bend_radius_ = 0.0;  // bent_quad: cylinder radius (size / bend)
  bool intersectPlane(const Ray& ray, SurfaceHit* hit) const;
  bool intersectSphere(const Ray& ray, SurfaceHit* hit) const;
  bool intersectCylinder(const Ray& ray, SurfaceHit* hit) const;
};

// The Gaussian footprint of the pixel in texels of the map (x, y, sigma), from the differentials
// of `rays` on the tangent plane of `hit`: the pixel filter of std pixel_sigma (pixels) mapped by
// the 2x2 Jacobian J = d(texel)/d(pixel), made isotropic with sigma^2 = pixel_sigma^2 tr(J J^T) / 2.
// The centre wraps into [0, width) x [0, height) (maps are tileable), or with wrap = false runs over
// the whole surface, uv_scale map sizes across (unbounded assets: Wang tiles, tiny examples).
// sigma >= min_sigma.
runtime::Footprint pixelFootprint(const RayWithDifferentials& rays, const SurfaceHit& hit, double pixel_sigma,
                                  int map_width, int map_height, double uv_scale, double min_sigma = 1e-3,
                                  bool wrap = true);

}  // namespace glintbake::bake::render
