// SPDX-License-Identifier: Apache-2.0
// NdfPyramid on hand-made containers: exact centre values, trilinear weights, range averages,
// sampling (pdf consistency and a chi-square test), the C API, and malformed assets.
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/ndf_pyramid_blend.h>
#include <glintbake/runtime/glintbake_ndf_c.h>
#include <glintbake/runtime/ndf_pyramid.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <thread>
#include <vector>
#include "../temp_dir.h"

namespace glintbake::runtime {
namespace {

constexpr int kRes = 16;
constexpr int kMap = 64;

// Deterministic positive test image of centre (i, j) of level l: a smooth bump whose position
// depends on the centre, plus a floor, normalised to unit mass. Zero outside the unit disk.
std::vector<float> testImage(int l, int i, int j) {
  std::vector<float> img(size_t(kRes) * kRes);
  const double h = 2.0 / kRes;
  const double cx = -0.5 + 0.13 * i + 0.05 * l, cy = 0.4 - 0.11 * j;
  double sum = 0.0;
  for (int y = 0; y < kRes; ++y) {
    for (int x = 0; x < kRes; ++x) {
      const double sx = -1 + (x + 0.5) * h, sy = 1 - (y + 0.5) * h;
      double v = 0.0;
      if (sx * sx + sy * sy <= 1.0) v = 0.05 + std::exp(-((sx - cx) * (sx - cx) + (sy - cy) * (sy - cy)) / 0.08);
      img[size_t(y) * kRes + x] = float(v);
      sum += v;
    }
  }
  for (float& v : img) v = float(v / (sum * h * h));
  return img;
}

struct LevelSpec {
  int grid;
  double sigma;
};

// The mass over [0, width] of a normalised 1-D Gaussian of std s centred at c.
double massOverWidth(double c, double s, double width) {
  return 0.5 * std::erfc((c - width) / (s * std::sqrt(2.0))) - 0.5 * std::erfc(c / (s * std::sqrt(2.0)));
}
// The same over [0, kMap].
double massOverMap(double c, double s) { return massOverWidth(c, s, kMap); }
// A stored footprint's spatial std at rate 1: sigma_l with the flakes' own sigma_h = 1.5 / sqrt 12.
double storedStd(double sigma) { return std::sqrt(sigma * sigma + 1.5 * 1.5 / 12.0); }

// Writes a pyramid container over a kMap^2 map with the given levels and region size. With
// footprint_mass, each centre's image holds the mass its footprint keeps over the map (as a
// baker writes a clamped map's images) instead of 1.
std::vector<uint8_t> makePyramid(const std::vector<LevelSpec>& levels, int region, uint32_t wrap = 0,
                                 const std::string& path = "", bool footprint_mass = false) {
  const std::string file = path.empty() ? glintbake::testing::processTempDir() + "rt_pyramid.gbk" : path;
  format::Writer w;
  EXPECT_EQ(w.open(file, format::AssetKind::kNdfPyramid, 1), format::ContainerStatus::kOk);
  for (size_t l = 0; l < levels.size(); ++l) {
    NdfLevelRecord rec;
    rec.level = uint32_t(l);
    rec.ndf_res = kRes;
    rec.grid_width = rec.grid_height = uint32_t(levels[l].grid);
    rec.region_size = uint32_t(region);
    rec.regions_x = rec.regions_y = uint32_t((levels[l].grid + region - 1) / region);
    rec.wrap = wrap;
    rec.map_width = rec.map_height = kMap;
    rec.stride_x = rec.stride_y = double(kMap) / levels[l].grid;
    rec.origin_x = rec.origin_y = 0.5 * rec.stride_x;
    rec.sigma_texels = levels[l].sigma;
    rec.sigma_r = 0.005;
    EXPECT_EQ(w.addSection(format::kSectionNdfLevel, l, &rec, sizeof(rec)), format::ContainerStatus::kOk);
    for (uint32_t ry = 0; ry < rec.regions_y; ++ry) {
      for (uint32_t rx = 0; rx < rec.regions_x; ++rx) {
        const int cw = std::min(region, levels[l].grid - int(rx) * region);
        const int ch = std::min(region, levels[l].grid - int(ry) * region);
        format::ImageSectionHeader hdr;
        hdr.width = hdr.height = kRes;
        hdr.channels = 1;
        hdr.layers = uint32_t(cw * ch);
        std::vector<uint8_t> bytes(sizeof(hdr));
        std::memcpy(bytes.data(), &hdr, sizeof(hdr));
        for (int k = 0; k < cw * ch; ++k) {
          const int i = int(rx) * region + k % cw, j = int(ry) * region + k / cw;
          std::vector<float> img = testImage(int(l), i, j);
          if (footprint_mass) {
            const double s = storedStd(levels[l].sigma);
            const double m =
                massOverMap(rec.origin_x + i * rec.stride_x, s) * massOverMap(rec.origin_y + j * rec.stride_y, s);
            for (float& v : img) v = float(v * m);
          }
          const uint8_t* p = reinterpret_cast<const uint8_t*>(img.data());
          bytes.insert(bytes.end(), p, p + img.size() * 4);
        }
        EXPECT_EQ(w.addSection(format::kSectionNdfChunk, (uint64_t(l) << 32) | (ry * rec.regions_x + rx), bytes.data(),
                               bytes.size()),
                  format::ContainerStatus::kOk);
      }
    }
  }
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  std::ifstream f(file, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

const std::vector<LevelSpec> kLevels = {{8, 2.0}, {4, 4.0}, {2, 8.0}};

class NdfPyramidTest : public ::testing::Test {
 protected:
  void SetUp() override {
    bytes_ = makePyramid(kLevels, 3);
    ASSERT_EQ(pyr_.openMemory(bytes_.data(), bytes_.size()), RuntimeStatus::kOk);
  }
  std::vector<uint8_t> bytes_;
  NdfPyramid pyr_;
};

Footprint fp(double x, double y, double sigma) {
  Footprint f;
  f.x = x;
  f.y = y;
  f.sigma = sigma;
  return f;
}

TEST_F(NdfPyramidTest, CentreQueriesReturnTheStoredImagesExactly) {
  // At level 0's sigma the blend is bilinear over level 0: its centres return the stored images.
  ASSERT_EQ(pyr_.levelCount(), 3);
  ASSERT_EQ(pyr_.resolution(), kRes);
  std::vector<float> out(kRes * kRes);
  const NdfLevelRecord* rec = pyr_.level(0);
  for (int j = 0; j < kLevels[0].grid; ++j) {
    for (int i = 0; i < kLevels[0].grid; ++i) {
      const double x = rec->origin_x + i * rec->stride_x, y = rec->origin_y + j * rec->stride_y;
      ASSERT_EQ(pyr_.image(fp(x, y, kLevels[0].sigma), out.data(), out.size()), RuntimeStatus::kOk);
      EXPECT_EQ(out, testImage(0, i, j)) << "centre " << i << "," << j;
      // Point queries at bin centres too.
      double v = 0.0;
      ASSERT_EQ(pyr_.eval(fp(x, y, kLevels[0].sigma), SPoint{-1 + 9.5 * 2.0 / kRes, 1 - 6.5 * 2.0 / kRes}, &v),
                RuntimeStatus::kOk);
      EXPECT_EQ(float(v), testImage(0, i, j)[6 * kRes + 9]);
    }
  }
}

// The weight of centre i for a footprint at continuous centre index g: the Gaussian of std tau
// (strides) integrated against the centre's tent, here by brute-force quadrature (independent of
// the closed form in the blend), normalised over the centres.
std::vector<double> tentGaussianWeights(double g, double tau, int n) {
  std::vector<double> w(size_t(n), 0.0);
  const int steps = 40000;
  const double lo = g - 10 * tau - 2, hi = g + 10 * tau + 2, h = (hi - lo) / steps;
  for (int k = 0; k < steps; ++k) {
    const double c = lo + (k + 0.5) * h;
    const double gauss = std::exp(-0.5 * (c - g) * (c - g) / (tau * tau));
    const int i0 = int(std::floor(c));
    const double f = c - i0;
    w[size_t(((i0 % n) + n) % n)] += gauss * (1 - f);
    w[size_t((((i0 + 1) % n) + n) % n)] += gauss * f;
  }
  double total = 0.0;
  for (double v : w) total += v;
  for (double& v : w) v /= total;
  return w;
}

TEST_F(NdfPyramidTest, GaussianBlendOfTheFinestSufficientLevel) {
  // sigma 6 over level 0 (sigma 2, stride 8): tau'^2 = 36 - 4 - 64 / 6, spread 0.58 strides, so
  // level 0 answers alone with the tent-integrated Gaussian weights of its centres.
  const double x = 4.0 + 8.0 * 2 + 2.0, y = 4.0 + 8.0 * 5 + 6.0;  // level 0: i = 2.25, j = 5.75
  const double sigma = 6.0, tau = std::sqrt(36.0 - 4.0 - 64.0 / 6.0) / 8.0;
  const SPoint s{-1 + 7.5 * 2.0 / kRes, 1 - 8.5 * 2.0 / kRes};
  const int bin = 8 * kRes + 7;
  auto at = [&](int l, int i, int j) { return double(testImage(l, i, j)[bin]); };
  const std::vector<double> wx = tentGaussianWeights(2.25, tau, 8), wy = tentGaussianWeights(5.75, tau, 8);
  double expected = 0.0;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) expected += wx[size_t(i)] * wy[size_t(j)] * double(testImage(0, i, j)[bin]);
  double v = 0.0;
  ASSERT_EQ(pyr_.eval(fp(x, y, sigma), s, &v), RuntimeStatus::kOk);
  EXPECT_NEAR(v, expected, 2e-3 * expected);
  // Below level 0 it is level 0; far above the top level of this repeating map it is the mean of
  // the top level's centres.
  double below = 0.0, at0 = 0.0, above = 0.0;
  ASSERT_EQ(pyr_.eval(fp(x, y, 0.1), s, &below), RuntimeStatus::kOk);
  ASSERT_EQ(pyr_.eval(fp(x, y, 2.0), s, &at0), RuntimeStatus::kOk);
  ASSERT_EQ(pyr_.eval(fp(x, y, 1000.0), s, &above), RuntimeStatus::kOk);
  EXPECT_EQ(below, at0);
  double mean = 0.0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) mean += 0.25 * double(testImage(2, i, j)[bin]);
  EXPECT_NEAR(above, mean, 1e-6 * mean);
  // Repeat wrap: a query one map period away is identical; the grid wraps between the last and
  // first centres.
  double shifted = 0.0;
  ASSERT_EQ(pyr_.eval(fp(x + kMap, y - 2 * kMap, sigma), s, &shifted), RuntimeStatus::kOk);
  EXPECT_NEAR(shifted, v, 1e-12 * v);
  double seam = 0.0;
  ASSERT_EQ(pyr_.eval(fp(kMap, 4.0, 2.0), s, &seam), RuntimeStatus::kOk);  // midway between centres 7 and 0
  EXPECT_NEAR(seam, 0.5 * (at(0, 7, 0) + at(0, 0, 0)), 1e-6 * seam);
}

TEST_F(NdfPyramidTest, BlendIsContinuousInSigma) {
  // Across the switch from one level to the next the weights change smoothly: the largest change
  // between neighbouring sigmas of a sweep halves with the step (a jump would not).
  const SPoint s{-1 + 7.5 * 2.0 / kRes, 1 - 8.5 * 2.0 / kRes};
  auto worstStep = [&](double ratio) {
    double prev = -1.0, worst = 0.0;
    for (double sigma = 2.0; sigma < 40.0; sigma *= ratio) {
      double v = 0.0;
      EXPECT_EQ(pyr_.eval(fp(21.0, 43.0, sigma), s, &v), RuntimeStatus::kOk);
      if (prev > 0.0) worst = std::max(worst, std::fabs(v - prev) / prev);
      prev = v;
    }
    return worst;
  };
  const double coarse = worstStep(1.002), fine = worstStep(1.001);
  EXPECT_LT(coarse, 2e-2);
  EXPECT_LT(fine, 0.6 * coarse);
}

TEST_F(NdfPyramidTest, RepeatBlendOfFarAndSeamPositionsMatchesTheReducedPosition) {
  // Positions many periods away (beyond 1e9 texels the blend reduces with std::floor instead of
  // its integer path), just below a period (rounding of the reduction lands on either side of the
  // seam) and negative ones give the image of the position reduced into [0, map) exactly (fmod
  // is exact); the tolerance covers the rounding of the reduction at 2^31 texels.
  const SPoint s{-1 + 9.5 * 2.0 / kRes, 1 - 6.5 * 2.0 / kRes};
  const double positions[] = {-3.75,        -64000.0 + 5.25, 1e9 + 5.25,         64.0 * 33554432.0 + 5.25,
                              64.0 - 1e-13, -1e-300,         -64.0 * 1e7 - 1e-9, 17.5};
  for (double sigma : {1.0, 2.828, 8.0}) {
    for (double x : positions) {
      double reduced = std::fmod(x, double(kMap));
      if (reduced < 0.0) reduced += kMap;
      if (reduced >= kMap) reduced -= kMap;
      double v = 0.0, expect = 0.0;
      ASSERT_EQ(pyr_.eval(fp(x, 20.0, sigma), s, &v), RuntimeStatus::kOk);
      ASSERT_EQ(pyr_.eval(fp(reduced, 20.0, sigma), s, &expect), RuntimeStatus::kOk);
      EXPECT_NEAR(v, expect, 1e-6 * expect) << "x " << x << " sigma " << sigma;
      ASSERT_EQ(pyr_.eval(fp(20.0, x, sigma), s, &v), RuntimeStatus::kOk);
      ASSERT_EQ(pyr_.eval(fp(20.0, reduced, sigma), s, &expect), RuntimeStatus::kOk);
      EXPECT_NEAR(v, expect, 1e-6 * expect) << "y " << x << " sigma " << sigma;
    }
  }
}

TEST_F(NdfPyramidTest, RangeAveragesAreExactForPiecewiseConstantImages) {
  const Footprint f = fp(20.0, 33.0, 3.0);
  std::vector<float> img(kRes * kRes);
  ASSERT_EQ(pyr_.image(f, img.data(), img.size()), RuntimeStatus::kOk);
  const double h = 2.0 / kRes;
  // Bin-aligned rectangle: mean of its bins.
  SRect r;
  r.x0 = -1 + 3 * h;
  r.x1 = -1 + 7 * h;
  r.y1 = 1 - 2 * h;
  r.y0 = 1 - 5 * h;
  double expect = 0.0;
  for (int j = 2; j < 5; ++j)
    for (int i = 3; i < 7; ++i) expect += img[size_t(j) * kRes + i];
  expect /= 12.0;
  double v = 0.0;
  ASSERT_EQ(pyr_.average(f, r, &v), RuntimeStatus::kOk);
  EXPECT_NEAR(v, expect, 1e-6 * expect);
  // Inside one bin: the bin value. Whole plane: mass / 4.
  r.x0 = -1 + 3.2 * h;
  r.x1 = -1 + 3.7 * h;
  r.y0 = 1 - 2.9 * h;
  r.y1 = 1 - 2.1 * h;
  ASSERT_EQ(pyr_.average(f, r, &v), RuntimeStatus::kOk);
  EXPECT_NEAR(v, img[2 * kRes + 3], 1e-6 * v);
  double m = 0.0;
  ASSERT_EQ(pyr_.mass(f, &m), RuntimeStatus::kOk);
  EXPECT_NEAR(m, 1.0, 1e-5);
  r = SRect();
  r.x0 = -2;
  r.x1 = 2;
  r.y0 = -2;
  r.y1 = 2;
  ASSERT_EQ(pyr_.average(f, r, &v), RuntimeStatus::kOk);
  EXPECT_NEAR(v, m / 16.0, 1e-6);
}

TEST_F(NdfPyramidTest, SamplePdfEqualsPdfAndEval) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Footprint f = fp(37.0, 11.0, 5.0);
  double m = 0.0;
  ASSERT_EQ(pyr_.mass(f, &m), RuntimeStatus::kOk);
  for (int k = 0; k < 2000; ++k) {
    NdfSample smp;
    ASSERT_EQ(pyr_.sample(f, u(rng), u(rng), &smp), RuntimeStatus::kOk);
    double p = 0.0, e = 0.0;
    ASSERT_EQ(pyr_.pdf(f, smp.s, &p), RuntimeStatus::kOk);
    ASSERT_EQ(pyr_.eval(f, smp.s, &e), RuntimeStatus::kOk);
    ASSERT_GT(smp.pdf, 0.0);
    EXPECT_DOUBLE_EQ(smp.pdf, p);
    EXPECT_NEAR(p, e / m, 1e-12 * p);
  }
  NdfSample smp;
  EXPECT_EQ(pyr_.sample(f, 1.0, 0.5, &smp), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(pyr_.sample(f, std::nan(""), 0.5, &smp), RuntimeStatus::kInvalidArgument);
}

// Queries are const and thread-safe: several threads hammering eval, average, sample, pdf and mass
// on one shared asset get exactly the answers of one thread (run under TSan in CI).
TEST_F(NdfPyramidTest, ConcurrentQueriesOnOneSharedAssetMatchSerial) {
  constexpr int kThreads = 4, kQueries = 300;
  const auto run = [this](int seed, std::vector<double>* out) {
    std::mt19937_64 rng{uint64_t(seed)};
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < kQueries; ++k) {
      const Footprint f = fp(kMap * u(rng), kMap * u(rng), 1.0 + 10.0 * u(rng));
      double e = 0.0, a = 0.0, p = 0.0, m = 0.0;
      SRect r;
      r.x0 = -0.5 + 0.4 * u(rng);
      r.x1 = r.x0 + 0.5;
      r.y0 = -0.5 + 0.4 * u(rng);
      r.y1 = r.y0 + 0.5;
      NdfSample smp;
      SPoint s;
      s.x = 0.6 * u(rng) - 0.3;
      s.y = 0.6 * u(rng) - 0.3;
      out->push_back(double(pyr_.eval(f, s, &e)) + e);
      out->push_back(double(pyr_.average(f, r, &a)) + a);
      out->push_back(double(pyr_.mass(f, &m)) + m);
      const RuntimeStatus st = pyr_.sample(f, u(rng), u(rng), &smp);
      out->push_back(double(st) + (st == RuntimeStatus::kOk ? smp.s.x + smp.s.y + smp.pdf : 0.0));
      if (st == RuntimeStatus::kOk) out->push_back(double(pyr_.pdf(f, smp.s, &p)) + p);
    }
  };
  std::vector<std::vector<double>> serial(kThreads), threaded(kThreads);
  for (int t = 0; t < kThreads; ++t) run(t, &serial[size_t(t)]);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) threads.emplace_back(run, t, &threaded[size_t(t)]);
  for (auto& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(serial[size_t(t)], threaded[size_t(t)]) << "thread " << t;
}

TEST_F(NdfPyramidTest, SamplerPassesChiSquare) {
  // Histogram of samples over the bins against the blended image's bin masses.
  const Footprint f = fp(29.0, 45.0, 3.3);
  std::vector<float> img(kRes * kRes);
  ASSERT_EQ(pyr_.image(f, img.data(), img.size()), RuntimeStatus::kOk);
  double m = 0.0;
  ASSERT_EQ(pyr_.mass(f, &m), RuntimeStatus::kOk);
  const int n = 200000;
  std::vector<double> counts(kRes * kRes, 0.0);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double h = 2.0 / kRes;
  for (int k = 0; k < n; ++k) {
    NdfSample smp;
    ASSERT_EQ(pyr_.sample(f, u(rng), u(rng), &smp), RuntimeStatus::kOk);
    const int i = std::min(kRes - 1, int((smp.s.x + 1) / h)), j = std::min(kRes - 1, int((1 - smp.s.y) / h));
    counts[size_t(j) * kRes + i] += 1.0;
  }
  double chi2 = 0.0;
  int dof = -1;
  for (int b = 0; b < kRes * kRes; ++b) {
    const double expected = n * img[size_t(b)] * h * h / m;
    if (expected == 0.0) {
      EXPECT_EQ(counts[size_t(b)], 0.0) << "sample in an empty bin";
      continue;
    }
    chi2 += (counts[size_t(b)] - expected) * (counts[size_t(b)] - expected) / expected;
    ++dof;
  }
  // Accept below the 1e-4 upper quantile (Wilson-Hilferty: about dof + 3.72 sqrt(2 dof) + 8).
  const double limit = dof + 3.72 * std::sqrt(2.0 * dof) + 8.0;
  std::printf("[ measured ] chi-square %.1f with %d degrees of freedom (limit %.1f)\n", chi2, dof, limit);
  EXPECT_LT(chi2, limit);
}

// The blend's ramp F(z) = z Phi(z) + phi(z), interpolated from a table, against the closed form;
// and the weights it gives against the closed form's second differences.
TEST(NdfPyramidBlendWeights, RampAndWeightsMatchTheClosedForm) {
  auto exact = [](double z) {
    return z * 0.5 * std::erfc(-z / std::sqrt(2.0)) + 0.39894228040143267794 * std::exp(-0.5 * z * z);
  };
  const format::NdfRamp& ramp = format::NdfRamp::table();
  double worst = 0.0;
  for (int k = -12000; k <= 12000; ++k) {
    const double z = k * 7.3e-4 + 1e-5;  // off the nodes, past both ends
    worst = std::max(worst, std::fabs(ramp(z) - exact(z)));
  }
  EXPECT_LT(worst, 1e-10);
  // Weights of one axis (16 centres, repeating, stride 4) at spreads up to the level's limit, and
  // at the wider spreads of a top level (whose window wraps onto the same centres several times).
  format::NdfBlendAxis axis;
  axis.set(64.0, 2.0, 4.0, 16, true, 2.0);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(0.0, 64.0);
  double worst_w = 0.0;
  for (const double max_extra : {6.0, 330.0}) {
    std::uniform_real_distribution<double> extra(0.1, max_extra);
    const double max_spread = max_extra > 100.0 ? 1e300 : format::NdfPyramidBlend::kMaxSpread;
    for (int q = 0; q < 500; ++q) {
      const double p = pos(rng), sigma_l = 2.0, sigma = std::sqrt(sigma_l * sigma_l + 4.0 * 4.0 / 6.0 + extra(rng));
      int idx[format::kMaxBlendAxis];
      double w[format::kMaxBlendAxis];
      const int n = axis.gaussianWeights(p, sigma, sigma_l, max_spread, idx, w);
      // The same weights from the closed form: tau * second differences of F, wrapped and normalised.
      const double tau = std::min(axis.spread(sigma, sigma_l), max_spread), g = (p - 2.0) / 4.0;
      double ref[16] = {}, total = 0.0;
      for (int i = int(std::floor(g - 3.5 * tau - 1.0)); i <= int(std::floor(g + 3.5 * tau + 1.0)) + 1; ++i) {
        const double d = (g - i) / tau;
        const double wi = tau * (exact(d + 1.0 / tau) - 2.0 * exact(d) + exact(d - 1.0 / tau));
        if (!(wi > 0.0)) continue;
        ref[((i % 16) + 16) % 16] += wi;
        total += wi;
      }
      double sum = 0.0;
      bool seen[16] = {};
      for (int e = 0; e < n; ++e) {
        ASSERT_FALSE(seen[idx[e]]) << "centre " << idx[e] << " listed twice";
        seen[idx[e]] = true;
        worst_w = std::max(worst_w, std::fabs(w[e] - ref[idx[e]] / total));
        sum += w[e];
      }
      // Only the far tail, below the ramp's precision, may be left out.
      for (int k = 0; k < 16; ++k) EXPECT_TRUE(seen[k] || ref[k] < 1e-8 * total) << "centre " << k << " left out";
      EXPECT_NEAR(sum, 1.0, 1e-12);
    }
  }
  EXPECT_LT(worst_w, 1e-8);
  std::printf("[ figures  ] ramp error %.2g, weight error %.2g\n", worst, worst_w);
}

// A strip narrower than a stride has one centre across it at every level, spread to any width,
// so only the spread along the strip picks the level: a 5 x 700 strip at 45 texels is answered by
// its level of sigma 16 (spread 1.25 strides along it), not by the level above the footprint
// (sigma 64) that the width's spread (8 strides of 5 texels) would pick. Across the strip the
// centre weighs 1 on a repeating map, and on a clamped one the footprint's mass across the strip
// relative to the centre's (the edge falloff spread to the footprint's width).
TEST(NdfPyramidBlendWeights, AStripSpreadsAlongItsLengthOnly) {
  auto records = [](uint32_t wrap) {
    std::vector<format::NdfLevelRecord> r(3);
    const uint32_t grid[3] = {22, 11, 5};
    for (int l = 0; l < 3; ++l) {
      r[l].level = uint32_t(l);
      r[l].ndf_res = 8;
      r[l].grid_width = 1;
      r[l].grid_height = grid[l];
      r[l].wrap = wrap;
      r[l].map_width = 5;
      r[l].map_height = 700;
      r[l].stride_x = 5.0;
      r[l].stride_y = 700.0 / grid[l];
      r[l].origin_x = 2.5;
      r[l].origin_y = r[l].stride_y / 2.0;
      r[l].sigma_texels = 16.0 * (1 << l);
      r[l].sigma_r = 0.005;
    }
    return r;
  };
  for (const uint32_t wrap : {0u, 1u}) {
    const std::vector<format::NdfLevelRecord> r = records(wrap);
    format::NdfPyramidBlend blend;
    blend.init(r.data(), 3);
    const double sigma = 45.0, y = 350.0;
    int level = -1;
    double total = 0.0;
    blend.blend(2.5, y, sigma, [&](int l, size_t, double w) {
      if (level < 0) level = l;
      EXPECT_EQ(l, level);
      total += w;
    });
    EXPECT_EQ(level, 0);
    if (wrap == 1) {
      const double across = massOverWidth(2.5, storedStd(sigma), 5.0) / massOverWidth(2.5, storedStd(16.0), 5.0);
      EXPECT_NEAR(total / across, 1.0, 0.02) << "clamped: " << total << " against " << across;
    } else {
      EXPECT_NEAR(total, 1.0, 1e-9);
      // Along the strip the weights are those of one repeating axis of 22 centres.
      format::NdfBlendAxis axis;
      axis.set(700.0, r[0].origin_y, r[0].stride_y, 22, true, 16.0);
      EXPECT_NEAR(axis.spread(sigma, 16.0), 1.25, 0.01);
      int idx[format::kMaxBlendAxis];
      double w[format::kMaxBlendAxis];
      const int n = axis.gaussianWeights(y, sigma, 16.0, format::NdfPyramidBlend::kMaxSpread, idx, w);
      std::vector<double> expected(22, 0.0), got(22, 0.0);
      for (int e = 0; e < n; ++e) expected[size_t(idx[e])] = w[e];
      blend.blend(2.5, y, sigma, [&](int, size_t c, double wc) { got[c] += wc; });
      for (int k = 0; k < 22; ++k) EXPECT_NEAR(got[size_t(k)], expected[size_t(k)], 1e-12) << k;
    }
  }
}

// Wang-tiles tile assets hold their edge centres beyond the edges (holdEdges).
TEST(NdfPyramidClamp, HeldEdgesUseTheEdgeCentres) {
  const std::vector<uint8_t> bytes = makePyramid({{4, 4.0}}, 2, 1);
  NdfPyramid p;
  ASSERT_EQ(p.openMemory(bytes.data(), bytes.size()), RuntimeStatus::kOk);
  p.holdEdges();
  std::vector<float> a(kRes * kRes);
  ASSERT_EQ(p.image(fp(-30.0, 200.0, 4.0), a.data(), a.size()), RuntimeStatus::kOk);
  EXPECT_EQ(a, testImage(0, 0, 3));
}

// On a clamped map there is no surface beyond the edges: a footprint keeps the mass it has over
// the map, prod_axes (Phi((W - u) / s) - Phi(-u / s)), s^2 = sigma^2 + sigma_h^2, wherever it lies
// and however wide it is, from the finest level's sigma up (the stored images hold their own
// footprints' masses, as baked). The
// blend folds the centres beyond the edges onto the edge centres with that falloff; holding the
// edge centres instead gave masses up to 1 far outside the map (where the reference has none).
TEST(NdfPyramidClamp, FootprintsKeepTheMassTheyHaveOverTheMap) {
  const std::vector<LevelSpec> levels = {{8, 4.0}, {4, 8.0}, {2, 16.0}, {1, 32.0}, {1, 64.0}, {1, 128.0}};
  const std::vector<uint8_t> bytes = makePyramid(levels, 4, 1, "", true);
  NdfPyramid p;
  ASSERT_EQ(p.openMemory(bytes.data(), bytes.size()), RuntimeStatus::kOk);
  // Within the grid, at a centre of level 0 and a level-0 footprint: that centre's image.
  std::vector<float> a(kRes * kRes);
  ASSERT_EQ(p.image(fp(12.0, 20.0, 4.0), a.data(), a.size()), RuntimeStatus::kOk);
  std::vector<float> centre = testImage(0, 1, 2);
  const double s0 = storedStd(4.0), m0 = massOverMap(12.0, s0) * massOverMap(20.0, s0);
  for (size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], centre[k] * m0, 1e-6 * (1.0 + centre[k])) << k;
  // Footprints centred on the map, from twice the finest sigma (where the blend's Gaussian spreads
  // over the centres; closer to a level's own sigma the mass field is its centres' bilinearly,
  // sampled at the stride, within the map as beyond it): within a few percent of the truth. Beyond
  // the edges: never more than a trace above the truth. Holding the edge centres instead (the
  // old blend) gave 237 and 0.84: it kept their mass for footprints far wider than the map.
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> on_map(0.0, double(kMap)), off_map(-3.0 * kMap, 4.0 * kMap);
  std::uniform_real_distribution<double> log_sigma(std::log(8.0), std::log(2000.0));
  double worst = 0.0, worst_excess = 0.0;
  for (int q = 0; q < 4000; ++q) {
    const bool inside = q % 2 == 0;
    const double x = inside ? on_map(rng) : off_map(rng), y = inside ? on_map(rng) : off_map(rng);
    const double sigma = std::exp(log_sigma(rng));
    const double s = storedStd(sigma), truth = massOverMap(x, s) * massOverMap(y, s);
    double m = 0.0;
    ASSERT_EQ(p.mass(fp(x, y, sigma), &m), RuntimeStatus::kOk);
    if (inside) {
      worst = std::max(worst, std::fabs(m - truth) / truth);
    } else {
      worst_excess = std::max(worst_excess, m - truth);
    }
  }
  EXPECT_LT(worst, 0.03);
  EXPECT_LT(worst_excess, 0.005);
  std::printf("[ figures  ] clamped mass: worst relative error on the map %.3g, worst excess off it %.3g\n", worst,
              worst_excess);
}

TEST(NdfPyramidC, CApiMatchesTheClass) {
  const std::string path = glintbake::testing::processTempDir() + "rt_pyramid_c.gbk";
  makePyramid(kLevels, 4, 0, path);
  gb_ndf_asset* p = nullptr;
  ASSERT_EQ(gb_ndf_asset_open(path.c_str(), &p), GB_OK);
  int32_t res = 0, kind = 0;
  ASSERT_EQ(gb_ndf_asset_info(p, &kind, &res), GB_OK);
  EXPECT_EQ(res, kRes);
  EXPECT_EQ(kind, GB_KIND_NDF_PYRAMID);
  NdfPyramid cls;
  ASSERT_EQ(cls.open(path.c_str()), RuntimeStatus::kOk);
  EXPECT_EQ(cls.levelCount(), 3);
  double a = 0.0, b = 0.0, sx = 0.0, sy = 0.0, pdf = 0.0, pdf2 = 0.0;
  ASSERT_EQ(gb_ndf_asset_eval(p, 13.0, 50.0, 3.0, 0.1, -0.2, &a), GB_OK);
  ASSERT_EQ(cls.eval(fp(13.0, 50.0, 3.0), SPoint{0.1, -0.2}, &b), RuntimeStatus::kOk);
  EXPECT_EQ(a, b);
  ASSERT_EQ(gb_ndf_asset_sample(p, 13.0, 50.0, 3.0, 0.3, 0.6, &sx, &sy, &pdf), GB_OK);
  ASSERT_EQ(gb_ndf_asset_pdf(p, 13.0, 50.0, 3.0, sx, sy, &pdf2), GB_OK);
  EXPECT_EQ(pdf, pdf2);
  ASSERT_EQ(gb_ndf_asset_average(p, 13.0, 50.0, 3.0, -0.5, -0.5, 0.5, 0.5, &a), GB_OK);
  EXPECT_GT(a, 0.0);
  std::vector<float> img(kRes * kRes);
  EXPECT_EQ(gb_ndf_asset_image(p, 1.0, 2.0, 3.0, img.data(), img.size() - 1), GB_INVALID_ARGUMENT);
  EXPECT_EQ(gb_ndf_asset_image(p, 1.0, 2.0, 3.0, img.data(), img.size()), GB_OK);
  gb_ndf_asset_close(p);
  gb_ndf_asset* bad = nullptr;
  EXPECT_EQ(gb_ndf_asset_open("/nonexistent/none.gbk", &bad), GB_IO_ERROR);
  EXPECT_EQ(bad, nullptr);
  EXPECT_STREQ(gb_status_string(GB_WRONG_KIND), statusString(RuntimeStatus::kWrongKind));
  std::remove(path.c_str());
}

TEST(NdfPyramidInvalid, MalformedAssetsAreRejected) {
  const std::vector<uint8_t> good = makePyramid(kLevels, 3);
  NdfPyramid p;
  // Every truncation fails cleanly.
  for (size_t cut : {size_t(0), size_t(10), good.size() / 2, good.size() - 1}) {
    EXPECT_NE(p.openMemory(good.data(), cut), RuntimeStatus::kOk) << cut;
    EXPECT_FALSE(p.isOpen());
  }
  // Single flipped bytes anywhere: either rejected or (if the byte is unused) a valid pyramid.
  std::mt19937 rng(3);
  for (int k = 0; k < 200; ++k) {
    std::vector<uint8_t> bad = good;
    bad[rng() % bad.size()] ^= uint8_t(1 + rng() % 255);
    const RuntimeStatus s = p.openMemory(bad.data(), bad.size());
    if (s == RuntimeStatus::kOk) {
      double v = 0.0;
      EXPECT_EQ(p.eval(fp(1, 2, 3), SPoint{0, 0}, &v), RuntimeStatus::kOk);
    }
  }
  // Wrong asset kind.
  const std::string path = glintbake::testing::processTempDir() + "rt_wrong_kind.gbk";
  {
    format::Writer w;
    ASSERT_EQ(w.open(path, format::AssetKind::kLtcTable, 1), format::ContainerStatus::kOk);
    ASSERT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
    ASSERT_EQ(w.finish(), format::ContainerStatus::kOk);
  }
  EXPECT_EQ(p.open(path.c_str()), RuntimeStatus::kWrongKind);
  std::remove(path.c_str());
  // Queries on a closed pyramid and bad arguments.
  double v = 0.0;
  EXPECT_EQ(p.eval(fp(0, 0, 1), SPoint{0, 0}, &v), RuntimeStatus::kInvalidArgument);
  NdfPyramid ok;
  ASSERT_EQ(ok.openMemory(good.data(), good.size()), RuntimeStatus::kOk);
  EXPECT_EQ(ok.eval(fp(std::nan(""), 0, 1), SPoint{0, 0}, &v), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(ok.eval(fp(0, 0, -1), SPoint{0, 0}, &v), RuntimeStatus::kInvalidArgument);
  ASSERT_EQ(ok.eval(fp(0, 0, 1), SPoint{3, 0}, &v), RuntimeStatus::kOk);
  EXPECT_EQ(v, 0.0);
}

}  // namespace
}  // namespace glintbake::runtime
