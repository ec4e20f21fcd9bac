// SPDX-License-Identifier: Apache-2.0
// Scene JSON parsing and validation (schemas/scene.schema.json).
#include <glintbake/bake/render/scene.h>

#include <glintbake/format/json_depth.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace glintbake::bake::render {
namespace {

using Json = nlohmann::json;

// Thrown inside the parser and turned into a kInvalidInput error at the top.
struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void fail(const std::string& message) { throw SceneError(message); }

void checkKeys(const Json& j, const std::string& where, std::initializer_list<const char*> allowed) {
  if (!j.is_object()) fail(where + " must be an object");
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok) fail(where + " has an unknown field \"" + it.key() + "\"");
  }
}

double number(const Json& j, const char* key, const std::string& where, double fallback, double lo, double hi) {
  if (!j.contains(key)) return fallback;
  const Json& v = j.at(key);
  if (!v.is_number()) fail(where + "." + key + " must be a number");
  const double x = v.get<double>();
  if (!std::isfinite(x) || x < lo || x > hi) {
    std::ostringstream s;
    s << where << "." << key << " must be in [" << lo << ", " << hi << "]";
    fail(s.str());
  }
  return x;
}

int integer(const Json& j, const char* key, const std::string& where, int fallback, int lo, int hi) {
  if (!j.contains(key)) return fallback;
  const Json& v = j.at(key);
  if (!v.is_number_integer()) fail(where + "." + key + " must be an integer");
  const long long x = v.get<long long>();
  if (x < lo || x > hi)
    fail(where + "." + key + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return int(x);
}

Vec3d vec3(const Json& v, const std::string& name) {
  if (!v.is_array() || v.size() != 3) fail(name + " must be an array of 3 numbers");
  Vec3d out{};
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number() || !std::isfinite(v[i].get<double>())) fail(name + " must be an array of 3 numbers");
    out[i] = v[i].get<double>();
  }
  return out;
}

Vec3d vec3(const Json& j, const char* key, const std::string& where, const Vec3d& fallback) {
  if (!j.contains(key)) return fallback;
  return vec3(j.at(key), where + "." + key);
}

Vec3d color(const Json& j, const char* key, const std::string& where, const Vec3d& fallback) {
  const Vec3d c = vec3(j, key, where, fallback);
  for (double x : c) {
    if (x < 0.0) fail(where + "." + key + " must not be negative");
  }
  return c;
}

Vec3d requireVec3(const Json& j, const char* key, const std::string& where) {
  if (!j.contains(key)) fail(where + "." + key + " is required");
  return vec3(j.at(key), where + "." + key);
}

double length(const Vec3d& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

std::string text(const Json& j, const char* key, const std::string& where, const std::string& fallback) {
  if (!j.contains(key)) return fallback;
  if (!j.at(key).is_string()) fail(where + "." + key + " must be a string");
  return j.at(key).get<std::string>();
}

std::string resolve(const std::string& path, const std::string& base_dir) {
  if (path.empty() || path[0] == '/' || base_dir.empty()) return path;
  return base_dir + "/" + path;
}

Camera parseCamera(const Json& j) {
  const std::string w = "camera";
  checkKeys(j, w,
            {"type", "position", "look_at", "up", "fov_degrees", "ortho_height", "width", "height", "pixel_sigma"});
  Camera c;
  const std::string type = text(j, "type", w, "perspective");
  if (type == "perspective") {
    c.type = CameraType::kPerspective;
  } else if (type == "orthographic") {
    c.type = CameraType::kOrthographic;
  } else {
    fail("camera.type must be \"perspective\" or \"orthographic\"");
  }
  c.position = vec3(j, "position", w, c.position);
  c.look_at = vec3(j, "look_at", w, c.look_at);
  c.up = vec3(j, "up", w, c.up);
  c.fov_degrees = number(j, "fov_degrees", w, c.fov_degrees, 1e-3, 170.0);
  c.ortho_height = number(j, "ortho_height", w, c.ortho_height, 1e-9, 1e9);
  c.width = integer(j, "width", w, c.width, 1, 8192);
  c.height = integer(j, "height", w, c.height, 1, 8192);
  c.pixel_sigma = number(j, "pixel_sigma", w, c.pixel_sigma, 1e-3, 4.0);
  const Vec3d dir{c.look_at[0] - c.position[0], c.look_at[1] - c.position[1], c.look_at[2] - c.position[2]};
  if (!(length(dir) > 0.0)) fail("camera.look_at must differ from camera.position");
  const Vec3d cr{dir[1] * c.up[2] - dir[2] * c.up[1], dir[2] * c.up[0] - dir[0] * c.up[2],
                 dir[0] * c.up[1] - dir[1] * c.up[0]};
  if (!(length(cr) > 1e-12 * length(dir) * length(c.up))) fail("camera.up must not be parallel to the view direction");
  return c;
}

Object parseObject(const Json& j) {
  const std::string w = "object";
  checkKeys(j, w, {"type", "center", "size", "radius", "bend_degrees", "uv_scale"});
  Object o;
  const std::string type = text(j, "type", w, "plane");
  if (type == "plane") {
    o.type = ObjectType::kPlane;
  } else if (type == "sphere") {
    o.type = ObjectType::kSphere;
  } else if (type == "bent_quad") {
    o.type = ObjectType::kBentQuad;
  } else {
    fail("object.type must be \"plane\", \"sphere\" or \"bent_quad\"");
  }
  o.center = vec3(j, "center", w, o.center);
  o.size = number(j, "size", w, o.size, 1e-9, 1e9);
  o.radius = number(j, "radius", w, o.radius, 1e-9, 1e9);
  o.bend_degrees = number(j, "bend_degrees", w, o.bend_degrees, 0.0, 350.0);
  o.uv_scale = number(j, "uv_scale", w, o.uv_scale, 1e-6, 1e6);
  return o;
}

Material parseMaterial(const Json& j, const std::string& base_dir) {
  const std::string w = "material";
  checkKeys(j, w, {"normal_map", "asset", "map_size", "sigma_r", "rate", "shadowing", "alpha", "fresnel"});
  Material m;
  m.normal_map = resolve(text(j, "normal_map", w, ""), base_dir);
  m.asset = resolve(text(j, "asset", w, ""), base_dir);
  if (j.contains("map_size")) {
    const Json& s = j.at("map_size");
    if (!s.is_array() || s.size() != 2 || !s[0].is_number_integer() || !s[1].is_number_integer() ||
        s[0].get<long long>() < 1 || s[1].get<long long>() < 1 || s[0].get<long long>() > (1 << 20) ||
        s[1].get<long long>() > (1 << 20)) {
      fail("material.map_size must be [width, height] in texels, each in [1, 1048576]");
    }
    m.map_width = s[0].get<int>();
    m.map_height = s[1].get<int>();
  }
  m.sigma_r = number(j, "sigma_r", w, m.sigma_r, 1e-6, 1.0);
  m.rate = integer(j, "rate", w, m.rate, 1, 16);
  const std::string shadowing = text(j, "shadowing", w, "ggx");
  if (shadowing == "ggx") {
    m.shadowing = ShadowingModel::kGgx;
  } else if (shadowing == "beckmann") {
    m.shadowing = ShadowingModel::kBeckmann;
  } else {
    fail("material.shadowing must be \"ggx\" or \"beckmann\"");
  }
  m.alpha = number(j, "alpha", w, m.alpha, 1e-4, 4.0);
  if (j.contains("fresnel")) {
    const Json& f = j.at("fresnel");
    const std::string fw = "material.fresnel";
    checkKeys(f, fw, {"type", "f0", "eta", "k"});
    const std::string type = text(f, "type", fw, "conductor");
    if (type == "none") {
      m.fresnel = FresnelType::kNone;
    } else if (type == "schlick") {
      m.fresnel = FresnelType::kSchlick;
    } else if (type == "conductor") {
      m.fresnel = FresnelType::kConductor;
    } else {
      fail("material.fresnel.type must be \"none\", \"schlick\" or \"conductor\"");
    }
    m.f0 = color(f, "f0", fw, m.f0);
    for (double x : m.f0) {
      if (x > 1.0) fail("material.fresnel.f0 must be in [0, 1]");
    }
    m.eta = color(f, "eta", fw, m.eta);
    m.k = color(f, "k", fw, m.k);
    for (double x : m.eta) {
      if (!(x > 0.0)) fail("material.fresnel.eta must be positive");
    }
  }
  return m;
}

Light parseLight(const Json& j, size_t index) {
  const std::string w = "lights[" + std::to_string(index) + "]";
  if (!j.is_object() || !j.contains("type") || !j.at("type").is_string()) fail(w + ".type is required");
  const std::string type = j.at("type").get<std::string>();
  Light l;
  if (type == "point") {
    checkKeys(j, w, {"type", "position", "intensity"});
    l.type = LightType::kPoint;
    l.position = requireVec3(j, "position", w);
    l.color = color(j, "intensity", w, l.color);
  } else if (type == "directional") {
    checkKeys(j, w, {"type", "direction", "irradiance"});
    l.type = LightType::kDirectional;
    l.direction = requireVec3(j, "direction", w);
    if (!(length(l.direction) > 0.0)) fail(w + ".direction must not be zero");
    l.color = color(j, "irradiance", w, l.color);
  } else if (type == "rectangle") {
    checkKeys(j, w, {"type", "corner", "edge_u", "edge_v", "radiance"});
    l.type = LightType::kPolygon;
    const Vec3d c = requireVec3(j, "corner", w), eu = requireVec3(j, "edge_u", w), ev = requireVec3(j, "edge_v", w);
    l.vertices = {c,
                  {c[0] + eu[0], c[1] + eu[1], c[2] + eu[2]},
                  {c[0] + eu[0] + ev[0], c[1] + eu[1] + ev[1], c[2] + eu[2] + ev[2]},
                  {c[0] + ev[0], c[1] + ev[1], c[2] + ev[2]}};
    l.color = color(j, "radiance", w, l.color);
  } else if (type == "polygon") {
    checkKeys(j, w, {"type", "vertices", "radiance"});
    l.type = LightType::kPolygon;
    if (!j.contains("vertices") || !j.at("vertices").is_array()) fail(w + ".vertices is required");
    const Json& vs = j.at("vertices");
    if (vs.size() < 3 || vs.size() > 64) fail(w + ".vertices must hold 3 to 64 points");
    for (size_t i = 0; i < vs.size(); ++i)
      l.vertices.push_back(vec3(vs[i], w + ".vertices[" + std::to_string(i) + "]"));
    l.color = color(j, "radiance", w, l.color);
  } else if (type == "sg") {
    checkKeys(j, w, {"type", "axis", "sharpness", "amplitude"});
    l.type = LightType::kSphericalGaussian;
    l.direction = requireVec3(j, "axis", w);
    if (!(length(l.direction) > 0.0)) fail(w + ".axis must not be zero");
    l.sharpness = number(j, "sharpness", w, l.sharpness, 1e-6, 1e7);
    l.color = color(j, "amplitude", w, l.color);
  } else if (type == "uniform") {
    checkKeys(j, w, {"type", "radiance"});
    l.type = LightType::kUniform;
    l.color = color(j, "radiance", w, l.color);
  } else {
    fail(w + ".type must be point, directional, rectangle, polygon, sg or uniform");
  }
  if (l.type == LightType::kPolygon) {
    // Non-degenerate: the fan triangles must have area.
    const Vec3d& a = l.vertices[0];
    double area2 = 0.0;
    for (size_t i = 1; i + 1 < l.vertices.size(); ++i) {
      const Vec3d& b = l.vertices[i];
      const Vec3d& c = l.vertices[i + 1];
      const Vec3d e1{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      area2 +=
          length(Vec3d{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]});
    }
    if (!(area2 > 0.0)) fail(w + " has zero area");
  }
  return l;
}

}  // namespace

Result<Scene> parseScene(const std::string& json_text, const std::string& base_dir) {
  if (format::jsonNestingDepth(json_text) > size_t(format::kMaxJsonDepth)) {
    return makeError(ErrorCode::kInvalidInput,
                     "scene is nested deeper than " + std::to_string(format::kMaxJsonDepth) + " levels");
  }
  Json doc;
  try {
    doc = Json::parse(json_text);
  } catch (const Json::exception& e) {
    return makeError(ErrorCode::kInvalidInput, std::string("scene is not valid JSON: ") + e.what());
  }
  try {
    checkKeys(doc, "scene", {"$schema", "camera", "object", "material", "lights", "background"});
    Scene scene;
    if (!doc.contains("camera")) fail("scene.camera is required");
    if (!doc.contains("object")) fail("scene.object is required");
    if (!doc.contains("material")) fail("scene.material is required");
    scene.camera = parseCamera(doc.at("camera"));
    scene.object = parseObject(doc.at("object"));
    scene.material = parseMaterial(doc.at("material"), base_dir);
    if (doc.contains("lights")) {
      const Json& ls = doc.at("lights");
      if (!ls.is_array()) fail("scene.lights must be an array");
      if (ls.size() > 64) fail("scene.lights holds more than 64 lights");
      for (size_t i = 0; i < ls.size(); ++i) scene.lights.push_back(parseLight(ls[i], i));
    }
    scene.background = color(doc, "background", "scene", scene.background);
    return scene;
  } catch (const SceneError& e) {
    return makeError(ErrorCode::kInvalidInput, e.what());
  } catch (const Json::exception& e) {
    return makeError(ErrorCode::kInvalidInput, std::string("scene: ") + e.what());
  }
}

Result<Scene> loadScene(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return makeError(ErrorCode::kIo, "cannot read scene " + path);
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return makeError(ErrorCode::kIo, "cannot read scene " + path);
  const size_t slash = path.find_last_of('/');
  const std::string base = slash == std::string::npos ? std::string() : path.substr(0, slash);
  return parseScene(text.str(), base);
}

}  // namespace glintbake::bake::render
