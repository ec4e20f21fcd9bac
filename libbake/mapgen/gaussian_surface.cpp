// SPDX-License-Identifier: Apache-2.0
// Gaussian random surfaces (beckmann and brushed maps): white Gaussian noise circularly convolved
// with a separable Gaussian kernel, differentiated analytically, with slopes scaled to the target
// standard deviation by the exact variance of the discrete filter.
#include "mapgen/generators.h"
#include "mapgen/random.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace glintbake::bake::mapgen {
namespace {

// A 1D periodic filter: taps at offsets t (texels) with the Gaussian g(t) = exp(-t^2 / (2 s^2))
// and its derivative g'(t) = -t / s^2 g(t). When the kernel (radius ceil(4 s)) is wider than the
// period n, taps are folded onto [0, n): the periodic kernel sum_m g(t + m n), exactly what a
// circular convolution applies.
struct PeriodicKernel {
  std::vector<int> offsets;
  std::vector<double> g, dg;

  double sumSquares(const std::vector<double>& k) const {
    double s = 0.0;
    for (double v : k) s += v * v;
    return s;
  }
};

PeriodicKernel makeKernel(double sigma, int n) {
  const int radius = int(std::ceil(4.0 * sigma));
  PeriodicKernel k;
  if (2 * radius + 1 <= n) {
    for (int t = -radius; t <= radius; ++t) {
      const double g = std::exp(-double(t) * t / (2.0 * sigma * sigma));
      k.offsets.push_back(t);
      k.g.push_back(g);
      k.dg.push_back(-double(t) / (sigma * sigma) * g);
    }
    return k;
  }
  k.offsets.resize(size_t(n));
  k.g.assign(size_t(n), 0.0);
  k.dg.assign(size_t(n), 0.0);
  for (int t = 0; t < n; ++t) k.offsets[size_t(t)] = t;
  for (int t = -radius; t <= radius; ++t) {
    const double g = std::exp(-double(t) * t / (2.0 * sigma * sigma));
    const size_t slot = size_t(((t % n) + n) % n);
    k.g[slot] += g;
    k.dg[slot] += -double(t) / (sigma * sigma) * g;
  }
  return k;
}

inline int wrapIndex(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

}  // namespace

NormalMap gaussianSurface(int size, uint64_t seed, double kernel_sigma_x, double kernel_sigma_y, double slope_std_x,
                          double slope_std_y) {
  const int n = size;
  const size_t texels = size_t(n) * size_t(n);
  const PeriodicKernel kx = makeKernel(kernel_sigma_x, n);
  const PeriodicKernel ky = makeKernel(kernel_sigma_y, n);

  // White noise, one standard normal per texel, indexed by texel so any thread draws the same.
  std::vector<float> noise(texels);
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& rows) {
    for (int r = rows.begin(); r != rows.end(); ++r) {
      for (int c = 0; c < n; ++c) {
        const uint64_t index = uint64_t(r) * uint64_t(n) + uint64_t(c);
        noise[size_t(index)] = float(gaussian(seed, kStreamNoise, index));
      }
    }
  });

  // Pass 1, along x: smooth (a) and derivative (b) of each row.
  std::vector<float> smooth_x(texels), deriv_x(texels);
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& rows) {
    for (int r = rows.begin(); r != rows.end(); ++r) {
      const float* w = &noise[size_t(r) * size_t(n)];
      for (int c = 0; c < n; ++c) {
        double a = 0.0, b = 0.0;
        for (size_t k = 0; k < kx.offsets.size(); ++k) {
          const double v = w[wrapIndex(c - kx.offsets[k], n)];
          a += kx.g[k] * v;
          b += kx.dg[k] * v;
        }
        smooth_x[size_t(r) * size_t(n) + size_t(c)] = float(a);
        deriv_x[size_t(r) * size_t(n) + size_t(c)] = float(b);
      }
    }
  });
  noise = std::vector<float>();

  // Exact slope variances of the filtered unit-variance noise: the filters are separable, so
  // Var(dh/dx) = sum(g'_x^2) sum(g_y^2) and Var(dh/drow) = sum(g_x^2) sum(g'_y^2).
  const double var_x = kx.sumSquares(kx.dg) * ky.sumSquares(ky.g);
  const double var_row = kx.sumSquares(kx.g) * ky.sumSquares(ky.dg);
  // A one-texel period has no slope at all; leave it flat rather than divide by zero.
  const double scale_x = var_x > 1e-30 ? slope_std_x / std::sqrt(var_x) : 0.0;
  const double scale_row = var_row > 1e-30 ? slope_std_y / std::sqrt(var_row) : 0.0;

  // Pass 2, along rows; converts the slopes to normals. Rows grow downwards and tangent y points
  // up, so dh/dy_up = -dh/drow.
  NormalMap map;
  map.width = n;
  map.height = n;
  map.wrap = Wrap::kRepeat;
  map.normals.resize(texels * 3);
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& rows) {
    std::vector<double> sx(static_cast<size_t>(n)), srow(static_cast<size_t>(n));
    for (int r = rows.begin(); r != rows.end(); ++r) {
      std::fill(sx.begin(), sx.end(), 0.0);
      std::fill(srow.begin(), srow.end(), 0.0);
      for (size_t k = 0; k < ky.offsets.size(); ++k) {
        const size_t src = size_t(wrapIndex(r - ky.offsets[k], n)) * size_t(n);
        const double g = ky.g[k], dg = ky.dg[k];
        for (int c = 0; c < n; ++c) {
          sx[size_t(c)] += g * deriv_x[src + size_t(c)];
          srow[size_t(c)] += dg * smooth_x[src + size_t(c)];
        }
      }
      for (int c = 0; c < n; ++c) {
        slopeToNormal(scale_x * sx[size_t(c)], -scale_row * srow[size_t(c)], map.at(c, r));
      }
    }
  });
  return map;
}

}  // namespace glintbake::bake::mapgen
