// SPDX-License-Identifier: Apache-2.0
// Small procedural normal maps for the reference tests (built in memory, no files).
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/format/numbers.h>

#include <cmath>
#include <vector>

namespace glintbake::reference::testing {

// A map with every texel set to the unit normal along (nx, ny, sqrt(1 - nx^2 - ny^2)).
inline bake::NormalMap constantMap(int width, int height, double nx, double ny, bake::Wrap wrap = bake::Wrap::kRepeat) {
  bake::NormalMap map;
  map.width = width;
  map.height = height;
  map.wrap = wrap;
  map.normals.resize(size_t(width) * size_t(height) * 3);
  const double nz = std::sqrt(1.0 - nx * nx - ny * ny);
  for (size_t t = 0; t < size_t(width) * size_t(height); ++t) {
    map.normals[t * 3 + 0] = float(nx);
    map.normals[t * 3 + 1] = float(ny);
    map.normals[t * 3 + 2] = float(nz);
  }
  return map;
}

// A bumpy, asymmetric, periodic map: normals of a height field that is a sum of sinusoids with
// integer numbers of periods across the map (so the map tiles seamlessly with wrap=repeat).
// `roughness` scales the slopes (0.3: slopes up to about 0.5).
inline bake::NormalMap wavyMap(int width, int height, double roughness = 0.3, bake::Wrap wrap = bake::Wrap::kRepeat) {
  struct Wave {
    int kx, ky;
    double amplitude, phase;
  };
  const Wave waves[] = {{1, 0, 1.0, 0.3}, {0, 1, 0.8, 1.1}, {2, 1, 0.5, 2.0}, {-1, 3, 0.35, 0.7}, {3, -2, 0.25, 4.1}};
  bake::NormalMap map;
  map.width = width;
  map.height = height;
  map.wrap = wrap;
  map.normals.resize(size_t(width) * size_t(height) * 3);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const double x = (c + 0.5) / width;
      const double y = (r + 0.5) / height;
      double gx = 0.0, gy = 0.0;  // gradient of the height per unit of x and y (y downwards)
      for (const Wave& w : waves) {
        const double arg = kTwoPi * (w.kx * x + w.ky * y) + w.phase;
        gx += w.amplitude * w.kx * std::cos(arg);
        gy += w.amplitude * w.ky * std::cos(arg);
      }
      // Tangent y points up, against the row direction.
      double n[3] = {-roughness * gx, roughness * gy, 1.0};
      const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      float* out = map.at(c, r);
      for (int k = 0; k < 3; ++k) out[k] = float(n[k] / len);
    }
  }
  return map;
}

// Rotates a map by 90 degrees clockwise as seen in an image viewer: texel (c, r) moves to
// (height - 1 - r, c) and the normal's projected direction turns with the picture,
// (n_x, n_y) -> (n_y, -n_x) (tangent y is up while rows go down).
inline bake::NormalMap rotateClockwise(const bake::NormalMap& in) {
  bake::NormalMap out;
  out.width = in.height;
  out.height = in.width;
  out.wrap = in.wrap;
  out.normals.resize(in.normals.size());
  for (int r = 0; r < in.height; ++r) {
    for (int c = 0; c < in.width; ++c) {
      const float* src = in.at(c, r);
      float* dst = out.at(in.height - 1 - r, c);
      dst[0] = src[1];
      dst[1] = -src[0];
      dst[2] = src[2];
    }
  }
  return out;
}

// Mirrors a map left-right: texel (c, r) moves to (width - 1 - c, r), n_x changes sign.
inline bake::NormalMap mirrorHorizontally(const bake::NormalMap& in) {
  bake::NormalMap out = in;
  for (int r = 0; r < in.height; ++r) {
    for (int c = 0; c < in.width; ++c) {
      const float* src = in.at(c, r);
      float* dst = out.at(in.width - 1 - c, r);
      dst[0] = -src[0];
      dst[1] = src[1];
      dst[2] = src[2];
    }
  }
  return out;
}

// Shifts a wrapped map like numpy.roll: texel (c, r) moves to ((c + dx) mod width, (r + dy) mod height).
inline bake::NormalMap roll(const bake::NormalMap& in, int dx, int dy) {
  bake::NormalMap out = in;
  for (int r = 0; r < in.height; ++r) {
    for (int c = 0; c < in.width; ++c) {
      const float* src = in.at(c, r);
      float* dst = out.at((c + dx) % in.width, (r + dy) % in.height);
      for (int k = 0; k < 3; ++k) dst[k] = src[k];
    }
  }
  return out;
}

// Tiles a map tx x ty times.
inline bake::NormalMap tile(const bake::NormalMap& in, int tx, int ty) {
  bake::NormalMap out;
  out.width = in.width * tx;
  out.height = in.height * ty;
  out.wrap = in.wrap;
  out.normals.resize(size_t(out.width) * size_t(out.height) * 3);
  for (int r = 0; r < out.height; ++r) {
    for (int c = 0; c < out.width; ++c) {
      const float* src = in.at(c % in.width, r % in.height);
      float* dst = out.at(c, r);
      for (int k = 0; k < 3; ++k) dst[k] = src[k];
    }
  }
  return out;
}

}  // namespace glintbake::reference::testing
