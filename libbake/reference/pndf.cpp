// SPDX-License-Identifier: Apache-2.0
// The per-flake closed form and the point evaluation of the reference P-NDF (see pndf.h).
#include <glintbake/format/numbers.h>
#include <glintbake/reference/pndf.h>

#include "footprint_flakes.h"

#include <glintbake/bake/result.h>

#include <cmath>

namespace glintbake::reference {
FlakeLobe flakeLobe(const FlakeSet& set, const Flake& flake, double ux, double uy, const Footprint& fp,
                    double sigma_r) {
  // Yan et al. 2016: the product of the footprint Gaussian and the flake's 4D Gaussian, integrated
  // over u, is a spatial Gaussian in u_k times a normal Gaussian in s (closed form in pndf.h).
  const double sh2 = set.sigma_h * set.sigma_h;
  const double sp2 = fp.sigma * fp.sigma;
  const double v = sh2 + sp2;
  const double dx = fp.x - ux;  // u_Q - u_k
  const double dy = fp.y - uy;

  FlakeLobe lobe;
  lobe.weight = set.area / (kTwoPi * v) * std::exp(-(dx * dx + dy * dy) / (2.0 * v));

  const double* j = flake.jacobian;  // row-major 2x2
  const double t = sh2 / v;
  lobe.mean[0] = flake.n[0] + t * (j[0] * dx + j[1] * dy);
  lobe.mean[1] = flake.n[1] + t * (j[2] * dx + j[3] * dy);

  // C_k = sigma_r^2 I + c J J^T, c = sigma_h^2 sigma_p^2 / (sigma_h^2 + sigma_p^2).
  const double c = sh2 * sp2 / v;
  const double sr2 = sigma_r * sigma_r;
  lobe.cov[0] = sr2 + c * (j[0] * j[0] + j[1] * j[1]);
  lobe.cov[1] = c * (j[0] * j[2] + j[1] * j[3]);
  lobe.cov[2] = sr2 + c * (j[2] * j[2] + j[3] * j[3]);
  return lobe;
}

double lobeDensity(const FlakeLobe& lobe, double sx, double sy) {
  const double xx = lobe.cov[0];
  const double xy = lobe.cov[1];
  const double yy = lobe.cov[2];
  const double det = xx * yy - xy * xy;
  const double dx = sx - lobe.mean[0];
  const double dy = sy - lobe.mean[1];
  const double q = (yy * dx * dx - 2.0 * xy * dx * dy + xx * dy * dy) / det;
  return lobe.weight / (kTwoPi * std::sqrt(det)) * std::exp(-0.5 * q);
}

void footprintLobes(const FlakeSet& set, const Footprint& fp, double sigma_r, std::vector<FlakeLobe>* lobes) {
  GLINTBAKE_CHECK(fp.sigma > 0.0 && sigma_r > 0.0);
  lobes->clear();
  detail::forEachFlakeInFootprint(set, fp, [&](const Flake& flake, double ux, double uy) {
    lobes->push_back(flakeLobe(set, flake, ux, uy, fp, sigma_r));
  });
}

std::vector<FlakeLobe> footprintLobes(const FlakeSet& set, const Footprint& fp, double sigma_r) {
  std::vector<FlakeLobe> lobes;
  footprintLobes(set, fp, sigma_r, &lobes);
  return lobes;
}

double footprintWeight(const FlakeSet& set, const Footprint& fp) {
  GLINTBAKE_CHECK(fp.sigma > 0.0);
  double total = 0.0;
  // The weight does not depend on sigma_r; any positive value will do.
  detail::forEachFlakeInFootprint(set, fp, [&](const Flake& flake, double ux, double uy) {
    total += flakeLobe(set, flake, ux, uy, fp, kDefaultSigmaR).weight;
  });
  return total;
}

double evalPndf(const FlakeSet& set, const Footprint& fp, double sx, double sy, double sigma_r) {
  GLINTBAKE_CHECK(fp.sigma > 0.0 && sigma_r > 0.0);
  double d = 0.0;
  detail::forEachFlakeInFootprint(set, fp, [&](const Flake& flake, double ux, double uy) {
    d += lobeDensity(flakeLobe(set, flake, ux, uy, fp, sigma_r), sx, sy);
  });
  return d;
}

}  // namespace glintbake::reference
