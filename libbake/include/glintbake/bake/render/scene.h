// SPDX-License-Identifier: Apache-2.0
// Scenes of the reference renderer (glintref render): one camera, one object, one material and a
// list of lights, read from a JSON file that follows schemas/scene.schema.json.
//
// World space is right-handed with y up; lengths are in arbitrary world units. File paths in the
// scene (normal_map, asset) are relative to the scene file's directory unless absolute.
#pragma once

#include <glintbake/bake/result.h>

#include <array>
#include <string>
#include <vector>

namespace glintbake::bake::render {

using Vec3d = std::array<double, 3>;

enum class CameraType { kPerspective, kOrthographic };

struct Camera {
  CameraType type = CameraType::kPerspective;
  Vec3d position{0.0, 2.0, 3.0};
  Vec3d look_at{0.0, 0.0, 0.0};
  Vec3d up{0.0, 1.0, 0.0};
  double fov_degrees = 40.0;  // perspective: full vertical field of view, (0, 170)
  double ortho_height = 2.0;  // orthographic: world height of the view, > 0
  int width = 128;            // pixels, [1, 8192]
  int height = 128;
  // Standard deviation of the Gaussian pixel filter, in pixels: the pixel footprint on the surface
  // is this Gaussian carried through the ray differentials. (0, 4]
  double pixel_sigma = 0.5;
};

enum class ObjectType { kPlane, kSphere, kBentQuad };

// The object and its texture parameterisation (u, v) in [0, 1)^2, v growing downwards in the image
// of the normal map (row 0 at v = 0):
//  - plane: the square of side `size` in y = center.y, u along +x, v along +z;
//  - sphere: radius `radius`, u = longitude (increasing clockwise seen from +y), v = polar angle
//    from +y divided by pi;
//  - bent_quad: a strip of a cylinder around an axis parallel to z, of arc length and width
//    `size`, bent by `bend_degrees` (0 = flat, the plane), bulging towards +y; u across the bend.
// uv_scale repeats the map: texel position = (u, v) * map size * uv_scale (maps are tileable).
struct Object {
  ObjectType type = ObjectType::kPlane;
  Vec3d center{0.0, 0.0, 0.0};
  double size = 2.0;           // plane, bent_quad: > 0
  double radius = 1.0;         // sphere: > 0
  double bend_degrees = 60.0;  // bent_quad: [0, 350]
  double uv_scale = 1.0;       // > 0
};

enum class FresnelType { kNone, kSchlick, kConductor };
enum class ShadowingModel { kGgx, kBeckmann };

struct Material {
  std::string normal_map;  // for --ndf reference (resolved path; empty when absent)
  std::string asset;       // for --ndf asset (resolved path; empty when absent)
  int map_width = 0;       // texels; 0 = from the normal map (required without one)
  int map_height = 0;
  double sigma_r = 0.005;  // intrinsic roughness of the reference flakes, (0, 1]
  int rate = 1;            // reference flakes per texel side, [1, 16]
  ShadowingModel shadowing = ShadowingModel::kGgx;
  double alpha = 0.1;  // base roughness: Smith shadowing, and D of --ndf smooth; [1e-4, 4]
  FresnelType fresnel = FresnelType::kConductor;
  Vec3d f0{0.95, 0.64, 0.54};  // Schlick reflectance at normal incidence (default: copper-like)
  Vec3d eta{0.2, 0.92, 1.1};   // conductor IOR (default: gold, approx. RGB)
  Vec3d k{3.9, 2.45, 2.14};
};

enum class LightType { kPoint, kDirectional, kPolygon, kSphericalGaussian, kUniform };

// Lights. Radiometric values are linear RGB:
//  - point: intensity (W/sr-like units) at `position`, falling off as 1/d^2;
//  - directional: irradiance on a surface facing `direction` (the direction towards the light);
//  - polygon (also "rectangle" in the file: corner, edge_u, edge_v): a planar convex polygon of
//    uniform radiance, emitting from both sides;
//  - sg: the environment a exp(lambda (axis . v - 1)) (axis in world space; amplitude = radiance);
//  - uniform: a constant environment radiance (the white furnace).
struct Light {
  LightType type = LightType::kPoint;
  Vec3d position{0.0, 2.0, 0.0};
  Vec3d direction{0.0, 1.0, 0.0};
  Vec3d color{1.0, 1.0, 1.0};   // intensity, irradiance, radiance or amplitude by type
  std::vector<Vec3d> vertices;  // polygon, in order (3 to 64 vertices)
  double sharpness = 100.0;     // sg: lambda > 0
};

struct Scene {
  Camera camera;
  Object object;
  Material material;
  std::vector<Light> lights;
  Vec3d background{0.0, 0.0, 0.0};  // radiance of camera rays that miss the object
};

// Parses and validates a scene document (JSON text). `base_dir` resolves relative paths ("" =
// current directory). Errors: kInvalidInput (malformed JSON, a missing or out-of-range field:
// the message names the field, e.g. "camera.width must be in [1, 8192]").
Result<Scene> parseScene(const std::string& json_text, const std::string& base_dir);

// Reads and parses a scene file (kIo when it cannot be read).
Result<Scene> loadScene(const std::string& path);

}  // namespace glintbake::bake::render
