// SPDX-License-Identifier: Apache-2.0
// Bin-averaged NDF images of the reference: the rectangle integral, the flat-map Gaussian,
// normalisation, orientation under rotation and mirroring, and agreement with point evaluation.
#include <glintbake/format/numbers.h>
#include <glintbake/reference/pndf.h>

#include "test_maps.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace glintbake::reference {
namespace {

// Probability of [a, b] under N(mean, sigma^2), written independently of the library.
double axisMass(double a, double b, double mean, double sigma) {
  return 0.5 * (std::erf((b - mean) / (sigma * std::sqrt(2.0))) - std::erf((a - mean) / (sigma * std::sqrt(2.0))));
}

double imageIntegral(const std::vector<double>& image, int res) {
  double sum = 0.0;
  for (double v : image) sum += v;
  return sum * (2.0 / res) * (2.0 / res);
}

TEST(ReferenceBinImage, RectangleIntegralOfADiagonalGaussianIsAnErfProduct) {
  const double mean[2] = {0.1, -0.05};
  const double cov[3] = {0.02 * 0.02, 0.0, 0.007 * 0.007};
  const double rects[3][4] = {{0.09, 0.12, -0.06, -0.04}, {0.05, 0.2, -0.2, 0.1}, {0.14, 0.3, -0.052, -0.049}};
  for (const auto& r : rects) {
    const double expected = axisMass(r[0], r[1], mean[0], 0.02) * axisMass(r[2], r[3], mean[1], 0.007);
    EXPECT_NEAR(gaussianRectangleIntegral(mean, cov, r[0], r[1], r[2], r[3]), expected, 1e-12);
  }
}

TEST(ReferenceBinImage, RectangleIntegralOfACorrelatedGaussianMatchesBruteForce) {
  // A thin lobe along the diagonal (eigenvalues 0.005^2 and about 0.08^2).
  const double mean[2] = {0.02, 0.01};
  const double a = 0.0032, b = 0.0031;
  const double cov[3] = {a, b, a};
  const double det = a * a - b * b;
  const double x0 = -0.03, x1 = 0.05, y0 = -0.02, y1 = 0.04;
  const int n = 1600;  // midpoint rule, step 5e-5 (1% of the narrow std)
  double brute = 0.0;
  for (int j = 0; j < n; ++j) {
    const double dy = y0 + (j + 0.5) * (y1 - y0) / n - mean[1];
    for (int i = 0; i < n; ++i) {
      const double dx = x0 + (i + 0.5) * (x1 - x0) / n - mean[0];
      brute += std::exp(-0.5 * (a * dx * dx - 2 * b * dx * dy + a * dy * dy) / det);
    }
  }
  brute *= (x1 - x0) * (y1 - y0) / (n * double(n)) / (2 * kPi * std::sqrt(det));
  EXPECT_NEAR(gaussianRectangleIntegral(mean, cov, x0, x1, y0, y1), brute, 2e-5 * brute);
  // The whole plane holds all the mass.
  EXPECT_NEAR(gaussianRectangleIntegral(mean, cov, -10, 10, -10, 10), 1.0, 1e-12);
}

TEST(ReferenceBinImage, FlatMapGivesBinAveragedIntrinsicGaussian) {
  const FlakeSet set = buildFlakes(testing::constantMap(16, 16, 0.0, 0.0));
  for (double sigma_r : {0.005, 0.03}) {
    const int res = 64;
    const std::vector<double> image = binAveragedImage(set, {5.3, 7.1, 2.0}, sigma_r, res);
    const double bin = 2.0 / res;
    std::vector<double> expected(image.size());
    for (int j = 0; j < res; ++j) {
      for (int i = 0; i < res; ++i) {
        expected[size_t(j) * res + i] = axisMass(-1 + i * bin, -1 + (i + 1) * bin, 0.0, sigma_r) *
                                        axisMass(1 - (j + 1) * bin, 1 - j * bin, 0.0, sigma_r) / (bin * bin);
      }
    }
    const double peak = *std::max_element(expected.begin(), expected.end());
    double l1 = 0.0, l1_error = 0.0;
    for (size_t k = 0; k < image.size(); ++k) {
      l1 += expected[k];
      l1_error += std::fabs(image[k] - expected[k]);
      // Every bin holding a visible share of the peak, to 1e-3 relative.
      if (expected[k] > 1e-6 * peak) {
        EXPECT_NEAR(image[k], expected[k], 1e-3 * expected[k]) << "bin " << k;
      }
    }
    EXPECT_LT(l1_error / l1, 1e-6);
  }
}

TEST(ReferenceBinImage, WrappedMapImagesIntegrateToOne) {
  const FlakeSet set = buildFlakes(testing::wavyMap(32, 24, 0.25));
  const Footprint footprints[] = {
      {0.2, 0.4, 1.0}, {16.0, 12.0, 2.0}, {31.7, 3.3, 4.0}, {7.5, 23.9, 8.0}, {20.0, 5.0, 16.0}};
  for (const Footprint& fp : footprints) {
    // Coarser bins for the widest footprint keep the test short (the cost grows with the number of
    // bins every lobe reaches).
    const int res = fp.sigma > 8.0 ? 32 : 64;
    const std::vector<double> image = binAveragedImage(set, fp, 0.005, res);
    EXPECT_NEAR(imageIntegral(image, res), 1.0, 1e-3) << "sigma " << fp.sigma;
  }
}

TEST(ReferenceBinImage, BinsOutsideTheUnitDiskAreZero) {
  // Normals near the rim spill over it; only bins with centres inside the disk keep their mass.
  const FlakeSet set = buildFlakes(testing::constantMap(4, 4, 0.96, 0.0));
  const int res = 32;
  const std::vector<double> image = binAveragedImage(set, {2.0, 2.0, 1.0}, 0.03, res);
  double inside = 0.0;
  for (int j = 0; j < res; ++j) {
    for (int i = 0; i < res; ++i) {
      const double cx = -1 + (i + 0.5) * 2.0 / res, cy = 1 - (j + 0.5) * 2.0 / res;
      if (cx * cx + cy * cy > 1.0) {
        EXPECT_EQ(image[size_t(j) * res + i], 0.0);
      } else {
        inside += image[size_t(j) * res + i];
      }
    }
  }
  EXPECT_GT(inside, 0.0);
}

// Rotating the picture of a map clockwise turns its NDF image clockwise: bin (i, j) -> (R-1-j, i).
TEST(ReferenceBinImage, RotatedMapGivesRotatedNdf) {
  for (bake::Wrap wrap : {bake::Wrap::kRepeat, bake::Wrap::kClamp}) {
    const bake::NormalMap map = testing::wavyMap(24, 16, 0.3, wrap);
    const bake::NormalMap rotated = testing::rotateClockwise(map);
    for (int rate : {1, 2}) {
      const FlakeSet a = buildFlakes(map, rate);
      const FlakeSet b = buildFlakes(rotated, rate);
      const Footprint fp = {5.25, 3.5, 2.5};
      const Footprint fp_rotated = {map.height - fp.y, fp.x, fp.sigma};
      const int res = 48;
      const std::vector<double> ia = binAveragedImage(a, fp, 0.01, res);
      const std::vector<double> ib = binAveragedImage(b, fp_rotated, 0.01, res);
      double peak = *std::max_element(ia.begin(), ia.end());
      ASSERT_GT(peak, 0.0);
      for (int j = 0; j < res; ++j) {
        for (int i = 0; i < res; ++i) {
          ASSERT_NEAR(ib[size_t(i) * res + (res - 1 - j)], ia[size_t(j) * res + i], 1e-9 * peak)
              << "wrap " << bake::wrapString(wrap) << " rate " << rate << " bin " << i << "," << j;
        }
      }
      // The image is not symmetric, so the test would notice a wrong orientation.
      double asymmetry = 0.0;
      for (size_t k = 0; k < ia.size(); ++k) asymmetry += std::fabs(ia[k] - ib[k]);
      EXPECT_GT(asymmetry, 1e-2 * peak);
    }
  }
}

TEST(ReferenceBinImage, MirroredMapGivesMirroredNdf) {
  const bake::NormalMap map = testing::wavyMap(20, 12, 0.3, bake::Wrap::kClamp);
  const FlakeSet a = buildFlakes(map);
  const FlakeSet b = buildFlakes(testing::mirrorHorizontally(map));
  const Footprint fp = {3.0, 6.5, 2.0};
  const Footprint fp_mirrored = {map.width - fp.x, fp.y, fp.sigma};
  const int res = 40;
  const std::vector<double> ia = binAveragedImage(a, fp, 0.01, res);
  const std::vector<double> ib = binAveragedImage(b, fp_mirrored, 0.01, res);
  const double peak = *std::max_element(ia.begin(), ia.end());
  for (int j = 0; j < res; ++j) {
    for (int i = 0; i < res; ++i) {
      ASSERT_NEAR(ib[size_t(j) * res + (res - 1 - i)], ia[size_t(j) * res + i], 1e-9 * peak) << i << "," << j;
    }
  }
}

TEST(ReferenceBinImage, BinAveragesAgreeWithSupersampledPointValues) {
  const FlakeSet set = buildFlakes(testing::wavyMap(16, 16, 0.3), 2);
  const Footprint fp = {6.2, 9.7, 1.0};
  const double sigma_r = 0.02;
  const int res = 16;
  const std::vector<double> image = binAveragedImage(set, fp, sigma_r, res);
  // The bins holding the most mass plus one in the tail.
  std::vector<size_t> order(image.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return image[x] > image[y]; });
  std::vector<size_t> bins(order.begin(), order.begin() + 5);
  bins.push_back(order[12]);
  const double bin = 2.0 / res;
  const int n = 128;  // midpoint supersampling per axis
  for (size_t k : bins) {
    const int i = int(k % res), j = int(k / res);
    double sum = 0.0;
    for (int b = 0; b < n; ++b) {
      const double sy = 1 - j * bin - (b + 0.5) * bin / n;
      for (int a = 0; a < n; ++a) sum += evalPndf(set, fp, -1 + i * bin + (a + 0.5) * bin / n, sy, sigma_r);
    }
    const double brute = sum / (double(n) * n);
    EXPECT_GT(brute, 0.0);
    EXPECT_NEAR(image[k], brute, 1e-4 * brute) << "bin " << i << "," << j;
  }
}

TEST(ReferenceBinImage, IdenticalForEveryThreadCount) {
  const FlakeSet set = buildFlakes(testing::wavyMap(32, 32, 0.3));
  const Footprint fp = {11.0, 4.0, 3.0};
  std::vector<double> one, two;
  tbb::task_arena(1).execute([&] { one = binAveragedImage(set, fp, 0.005, 64); });
  tbb::task_arena(2).execute([&] { two = binAveragedImage(set, fp, 0.005, 64); });
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(double)), 0);
}

}  // namespace
}  // namespace glintbake::reference
