// SPDX-License-Identifier: Apache-2.0
// Flakes of the reference evaluator: the per-texel (or per sub-sample) 4D Gaussian elements of a
// normal map, built exactly as the "Flake model" of formats/SPEC.md defines them (Yan et al. 2016,
// "Position-Normal Distributions for Efficient Rendering of Specular Microstructure", section 4).
//
// This is the slow, obviously-correct definition that every fast path (libbake/ndf, runtime/) is
// checked against. Everything is double precision. It shares no code with the fast paths.
//
// Coordinates (formats/SPEC.md): positions u in texels, texel (column c, row r) centred at
// (c + 0.5, r + 0.5), y grows downwards; normals in the tangent frame x = right, y = up (green up).
#pragma once

#include <glintbake/bake/io/normal_map.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace glintbake::reference {

// One flake k: a 4D Gaussian element
//   G_k(u, s) = c_k exp(-|u - u_k|^2 / (2 sigma_h^2)) exp(-|s - n_k - J_k (u - u_k)|^2 / (2 sigma_r^2)).
struct Flake {
  double u[2];         // position u_k in texels (inside the map: [0, width) x [0, height))
  double n[2];         // s-plane normal n_k = (n_x, n_y): bilinear interpolation at u_k, not renormalised
  double jacobian[4];  // J_k = d(n_x, n_y)/d(u_x, u_y), row-major: {dnx/dux, dnx/duy, dny/dux, dny/duy},
                       // per texel (u_y grows downwards, n_y points up)
};

// All flakes of a map at a given sub-sampling rate. Flakes lie on the fine grid of
// (width * rate) x (height * rate) points, stored row-major with fine row 0 at the top:
// flake (fine column fc, fine row fr) is flakes[fr * width * rate + fc], at
// u = ((fc + 0.5) / rate, (fr + 0.5) / rate).
struct FlakeSet {
  int width = 0;   // map size in texels
  int height = 0;
  bake::Wrap wrap = bake::Wrap::kRepeat;  // repeat: the flake pattern is periodic with the map size
  int rate = 1;          // sub-samples per texel side
  double step = 1.0;     // flake spacing in texels: 1 / rate
  double area = 1.0;     // A_k = step^2 texel^2
  double sigma_h = 0.0;  // spatial std of every flake in texels: step * 1.5 / sqrt(12)
  std::vector<Flake> flakes;

  int fineWidth() const { return width * rate; }
  int fineHeight() const { return height * rate; }
  const Flake& at(int fine_column, int fine_row) const {
    return flakes[size_t(fine_row) * size_t(fineWidth()) + size_t(fine_column)];
  }
};

// Largest accepted rate (sub-samples per texel side).
constexpr int kMaxRate = 16;

// The s-plane normal of the map at position u (texels): bilinear interpolation of the texels'
// (n_x, n_y) with texel centres at +0.5, neighbours outside the map fetched with the map's wrap
// mode (repeat: modulo; clamp: nearest edge texel). Not renormalised.
// Requires a non-empty map. Thread-safe (reads only).
void interpolateNormal(const bake::NormalMap& map, double ux, double uy, double n_out[2]);

// Builds every flake of the map per the flake model: n_k by interpolateNormal at u_k and J_k by
// central differences of that interpolant with a step of one texel,
//   J[:, 0] = (n(u + (1, 0)) - n(u - (1, 0))) / 2,   J[:, 1] = (n(u + (0, 1)) - n(u - (0, 1))) / 2.
// For rate 1 this is the neighbour difference at texel centres.
// Requires 1 <= rate <= kMaxRate and a non-empty map whose normals vector holds width*height*3
// floats (checked: aborts otherwise, a programmer error). The map's values must be finite (ingest
// guarantees it). Memory: 80 bytes per flake (width * height * rate^2 flakes).
// Thread-safe; uses one thread.
FlakeSet buildFlakes(const bake::NormalMap& map, int rate = 1);

}  // namespace glintbake::reference
