// SPDX-License-Identifier: Apache-2.0
// TensorNdf queries: values at pyramid centres against the factors, trilinear blending against
// NdfPyramid on the reconstructed images, range averages against the mean of eval(), and the
// agreement of pdf * mass with eval() (non-negative assets) or its measured gap (plain CP).
#include "tensor_assets.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <thread>

namespace glintbake::runtime::testing {
namespace {

Footprint footprint(double x, double y, double sigma) {
  Footprint f;
  f.x = x;
  f.y = y;
  f.sigma = sigma;
  return f;
}

double binCentreX(int i, int res) { return -1.0 + (i + 0.5) * 2.0 / res; }
double binCentreY(int j, int res) { return 1.0 - (j + 0.5) * 2.0 / res; }

TEST(TensorNdf, DescribesTheAsset) {
  const TensorNdf& t = assets().nonneg;
  ASSERT_TRUE(t.isOpen());
  EXPECT_EQ(t.resolution(), 32);
  EXPECT_EQ(t.levelCount(), 3);
  ASSERT_NE(t.info(), nullptr);
  EXPECT_EQ(t.info()->block, 16u);
  EXPECT_EQ(t.info()->blocks_per_side, 2u);
  EXPECT_NE(t.info()->flags & kTensorFlagNonNegative, 0u);
  EXPECT_EQ(assets().plain.info()->flags & kTensorFlagNonNegative, 0u);
  EXPECT_GT(t.groupCount(), 0);
  EXPECT_GT(t.blocksKept(), 0u);
  EXPECT_LE(t.blocksKept(), uint64_t(16 + 4 + 4) * 4);
  EXPECT_GT(t.memoryBytes(), 0u);
  EXPECT_EQ(t.level(0)->grid_width, 4u);
  EXPECT_EQ(t.level(2)->grid_width, 2u);
  EXPECT_EQ(t.level(3), nullptr);
  EXPECT_EQ(t.group(t.groupCount()), nullptr);
  EXPECT_EQ(t.indexEntry(0, 4, 0, 0), nullptr);
  EXPECT_EQ(t.indexEntry(0, 0, 0, 4), nullptr);
}

// At level 0's sigma the footprint blend is bilinear over level 0, so at its centres it returns
// the stored model (above level 0 the blend is a Gaussian mean of several centres, checked against
// NdfPyramid below).
TEST(TensorNdf, EvalAtCentresEqualsTheFactors) {
  for (const TensorNdf* t : {&assets().nonneg, &assets().plain}) {
    const int res = t->resolution();
    for (int l = 0; l < 1; ++l) {
      const NdfLevelRecord& r = *t->level(l);
      for (uint32_t cj = 0; cj < r.grid_height; ++cj) {
        for (uint32_t ci = 0; ci < r.grid_width; ++ci) {
          const std::vector<double> model = modelImage(*t, l, int(ci), int(cj));
          const double peak = *std::max_element(model.begin(), model.end());
          const Footprint fp = footprint(r.origin_x + ci * r.stride_x, r.origin_y + cj * r.stride_y, r.sigma_texels);
          for (int j = 0; j < res; ++j) {
            for (int i = 0; i < res; ++i) {
              double v = -1.0;
              ASSERT_EQ(t->eval(fp, SPoint{binCentreX(i, res), binCentreY(j, res)}, &v), RuntimeStatus::kOk);
              const double expected = std::max(0.0, model[size_t(j) * res + i]);
              ASSERT_NEAR(v, expected, 1e-5 * peak)
                  << "level " << l << " centre " << ci << "," << cj << " bin " << i << "," << j;
            }
          }
        }
      }
    }
  }
}

TEST(TensorNdf, BlendingMatchesNdfPyramid) {
  const TensorNdf& t = assets().nonneg;
  const std::string path = writeReconstructedPyramid(t, "blend");
  NdfPyramid ref;
  ASSERT_EQ(ref.open(path.c_str()), RuntimeStatus::kOk);
  const int res = t.resolution();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(-40.0, 110.0), sig(0.0, 40.0), sp(-1.05, 1.05);
  std::vector<float> img_t(size_t(res) * res), img_r(size_t(res) * res);
  for (int q = 0; q < 200; ++q) {
    const Footprint fp = footprint(pos(rng), pos(rng), sig(rng));
    ASSERT_EQ(t.image(fp, img_t.data(), img_t.size()), RuntimeStatus::kOk);
    ASSERT_EQ(ref.image(fp, img_r.data(), img_r.size()), RuntimeStatus::kOk);
    const float peak = *std::max_element(img_r.begin(), img_r.end());
    for (size_t n = 0; n < img_t.size(); ++n) ASSERT_NEAR(img_t[n], img_r[n], 2e-5 * peak) << "bin " << n;
    for (int k = 0; k < 20; ++k) {
      const SPoint s{sp(rng), sp(rng)};
      double a = -1.0, b = -1.0;
      ASSERT_EQ(t.eval(fp, s, &a), RuntimeStatus::kOk);
      ASSERT_EQ(ref.eval(fp, s, &b), RuntimeStatus::kOk);
      ASSERT_NEAR(a, b, 2e-5 * peak);
    }
    double ma = 0.0, mb = 0.0;
    ASSERT_EQ(t.mass(fp, &ma), RuntimeStatus::kOk);
    ASSERT_EQ(ref.mass(fp, &mb), RuntimeStatus::kOk);
    EXPECT_NEAR(ma, mb, 1e-5 * mb);
  }
  std::remove(path.c_str());
}

// An asset with exact levels (rank-B groups, one per block) blends like any other: its answers
// equal NdfPyramid's on a pyramid of its own reconstructed images at every footprint, and well
// above the top level, where only exact levels answer, they equal the uncompressed pyramid's.
TEST(TensorNdf, ExactLevelsBlendLikeTheUncompressedPyramid) {
  const TensorNdf& t = assets().exact;
  ASSERT_EQ(t.levelCount(), 3);
  EXPECT_EQ(int(t.info()->max_rank), 16);  // the exact groups have rank B = 16
  const std::string recon_path = writeReconstructedPyramid(t, "exact_blend");
  const std::string plain_path = tempPath("exact.pyramid.gbk");
  {
    format::Writer w;
    ASSERT_EQ(w.open(plain_path, format::AssetKind::kNdfPyramid, 1), format::ContainerStatus::kOk);
    ASSERT_TRUE(bake::ndf::buildNdfPyramid(tinyMap(), tinyPyramid(), w, nullptr).ok());
    ASSERT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
    ASSERT_EQ(w.finish(), format::ContainerStatus::kOk);
  }
  NdfPyramid recon, plain;
  ASSERT_EQ(recon.open(recon_path.c_str()), RuntimeStatus::kOk);
  ASSERT_EQ(plain.open(plain_path.c_str()), RuntimeStatus::kOk);
  const int res = t.resolution();
  const double top = t.level(2)->sigma_texels;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> pos(-40.0, 110.0), sig(0.0, 60.0), sp(-1.05, 1.05);
  std::vector<float> img_t(size_t(res) * res), img_r(size_t(res) * res);
  auto compare = [&](const NdfPyramid& ref, const Footprint& fp) {
    ASSERT_EQ(t.image(fp, img_t.data(), img_t.size()), RuntimeStatus::kOk);
    ASSERT_EQ(ref.image(fp, img_r.data(), img_r.size()), RuntimeStatus::kOk);
    const float peak = *std::max_element(img_r.begin(), img_r.end());
    for (size_t n = 0; n < img_t.size(); ++n) ASSERT_NEAR(img_t[n], img_r[n], 1e-5 * peak) << "bin " << n;
    for (int k = 0; k < 10; ++k) {
      const SPoint s{sp(rng), sp(rng)};
      double a = -1.0, b = -1.0;
      ASSERT_EQ(t.eval(fp, s, &a), RuntimeStatus::kOk);
      ASSERT_EQ(ref.eval(fp, s, &b), RuntimeStatus::kOk);
      ASSERT_NEAR(a, b, 1e-5 * peak);
    }
  };
  for (int q = 0; q < 60; ++q) compare(recon, footprint(pos(rng), pos(rng), sig(rng)));
  // Level 0 (compressed) answers while its spread is at most NdfPyramidBlend::kMaxSpread: up to
  // sqrt(6^2 + 16^2 / 6 + (2.5 x 16)^2) = 41.0 texels = 1.71 x top.
  std::uniform_real_distribution<double> above(1.75 * top, 80.0);
  for (int q = 0; q < 30; ++q) compare(plain, footprint(pos(rng), pos(rng), above(rng)));
  // Answering from the first exact level only (what the loader does when the lobes stand in for
  // the compressed level 0), the asset equals the uncompressed pyramid restricted alike at every
  // footprint, and reports that level as where the pyramid starts.
  TensorNdf restricted;
  ASSERT_EQ(restricted.openMemory(assets().exact_bytes.data(), assets().exact_bytes.size()), RuntimeStatus::kOk);
  const double level1 = restricted.level(1)->sigma_texels;
  restricted.answerFromSigma(level1);
  plain.answerFromSigma(level1);
  EXPECT_EQ(restricted.footprintRange().pyramid_min_sigma, level1);
  EXPECT_EQ(plain.footprintRange().pyramid_min_sigma, level1);
  for (int q = 0; q < 60; ++q) {
    const Footprint fp = footprint(pos(rng), pos(rng), sig(rng));
    ASSERT_EQ(restricted.image(fp, img_t.data(), img_t.size()), RuntimeStatus::kOk);
    ASSERT_EQ(plain.image(fp, img_r.data(), img_r.size()), RuntimeStatus::kOk);
    const float peak = *std::max_element(img_r.begin(), img_r.end());
    for (size_t n = 0; n < img_t.size(); ++n) ASSERT_NEAR(img_t[n], img_r[n], 1e-5 * peak) << "sigma " << fp.sigma;
  }
  // Past the top level the restriction keeps the top level.
  restricted.answerFromSigma(1e9);
  EXPECT_EQ(restricted.footprintRange().pyramid_min_sigma, top);
  std::remove(recon_path.c_str());
  std::remove(plain_path.c_str());
}

// Exact average of the piecewise-constant eval() over a rectangle, bin by bin.
double meanOfEval(const TensorNdf& t, const Footprint& fp, const SRect& r) {
  const int res = t.resolution();
  const double bin = 2.0 / res;
  double integral = 0.0;
  for (int j = 0; j < res; ++j) {
    const double hy = std::min(1.0 - j * bin, r.y1) - std::max(1.0 - (j + 1) * bin, r.y0);
    if (hy <= 0.0) continue;
    for (int i = 0; i < res; ++i) {
      const double hx = std::min(-1.0 + (i + 1) * bin, r.x1) - std::max(-1.0 + i * bin, r.x0);
      if (hx <= 0.0) continue;
      double v = 0.0;
      EXPECT_EQ(t.eval(fp, SPoint{binCentreX(i, res), binCentreY(j, res)}, &v), RuntimeStatus::kOk);
      integral += hx * hy * v;
    }
  }
  return integral / ((r.x1 - r.x0) * (r.y1 - r.y0));
}

// Compressed blocks (the non-negative asset) and exact blocks (the asset with exact levels, whose
// range sums read only the columns a rectangle covers) alike.
class TensorNdfAverage : public ::testing::TestWithParam<bool> {};

TEST_P(TensorNdfAverage, EqualsMeanOfEval) {
  const TensorNdf& t = GetParam() ? assets().exact : assets().nonneg;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> pos(0.0, 64.0), sig(1.0, 40.0), c(-1.1, 1.1), w(0.001, 1.2);
  double worst = 0.0;
  int compared = 0;
  for (int q = 0; q < 400; ++q) {
    const Footprint fp = footprint(pos(rng), pos(rng), sig(rng));
    SRect r;
    r.x0 = c(rng);
    r.y0 = c(rng);
    r.x1 = r.x0 + w(rng);
    r.y1 = r.y0 + w(rng);
    if (q == 0) r = SRect{};  // the whole plane: mass / 4
    double avg = -1.0;
    ASSERT_EQ(t.average(fp, r, &avg), RuntimeStatus::kOk);
    const double expected = meanOfEval(t, fp, r);
    ASSERT_GE(avg, 0.0);
    // Float32 prefix sums: a range sum carries a rounding error of a few ulps of the block's
    // column totals, which is what the absolute term (4e-7 of the plane's mean density, mass / 4)
    // allows for on small averages.
    EXPECT_LE(std::fabs(avg - expected), 1e-5 * expected + 1e-7) << "query " << q;
    if (expected < 1e-2) continue;
    worst = std::max(worst, std::fabs(avg - expected) / expected);
    ++compared;
  }
  std::printf("[ figures  ] average vs mean of eval: %d rectangles, worst relative difference %.3g\n", compared, worst);
  EXPECT_GT(compared, 100);
  // Invalid rectangles and footprints are rejected.
  double v = 0.0;
  SRect empty;
  empty.x1 = empty.x0;
  EXPECT_EQ(t.average(footprint(1, 1, 1), empty, &v), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(t.average(footprint(1, 1, NAN), SRect{}, &v), RuntimeStatus::kInvalidArgument);
}

INSTANTIATE_TEST_SUITE_P(TensorNdf, TensorNdfAverage, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& i) {
                           return i.param ? "ExactLevels" : "Compressed";
                         });

// pdf * mass against eval at the sampled points; returns the mean relative gap.
double pdfEvalGap(const TensorNdf& t, const Footprint& fp, int n, uint64_t seed, double* worst) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double total = 0.0, sum = 0.0;
  *worst = 0.0;
  EXPECT_EQ(t.mass(fp, &total), RuntimeStatus::kOk);
  for (int k = 0; k < n; ++k) {
    NdfSample s;
    EXPECT_EQ(t.sample(fp, u(rng), u(rng), &s), RuntimeStatus::kOk);
    double v = 0.0;
    EXPECT_EQ(t.eval(fp, s.s, &v), RuntimeStatus::kOk);
    const double gap = v > 0.0 ? std::fabs(s.pdf * total - v) / v : 1.0;
    sum += gap;
    *worst = std::max(*worst, gap);
  }
  return sum / n;
}

TEST(TensorNdf, PdfTimesMassEqualsEvalForNonNegativeAssets) {
  for (const TensorNdf* asset : {&assets().nonneg, &assets().exact}) {
    const TensorNdf& t = *asset;
    double worst_all = 0.0;
    for (const Footprint& fp : {footprint(20, 30, 6), footprint(3, 60, 11), footprint(40, 40, 30)}) {
      double m = 0.0;
      ASSERT_EQ(t.mass(fp, &m), RuntimeStatus::kOk);
      EXPECT_NEAR(m, 1.0, 2e-2);  // repeat map: every footprint's NDF is (nearly) normalised
      double worst = 0.0;
      const double mean = pdfEvalGap(t, fp, 4000, 3, &worst);
      EXPECT_LT(mean, 1e-5);
      // The descent's probabilities are differences of the stored float32 prefix sums: a bin
      // holding a thousandth of its block's column carries a relative error of about 1e3 float
      // ulps (6e-5) there.
      EXPECT_LT(worst, 3e-4);
      worst_all = std::max(worst_all, worst);
    }
    std::printf("[ figures  ] non-negative CP%s: worst |pdf*mass - eval| / eval = %.3g\n",
                asset == &assets().exact ? " with exact levels" : "", worst_all);
  }
}

TEST(TensorNdf, PlainCpGapsAreMeasured) {
  const TensorNdf& t = assets().plain;
  // Negative mass of the unclamped model at every centre of every level.
  double negative = 0.0, absolute = 0.0;
  for (int l = 0; l < t.levelCount(); ++l) {
    for (uint32_t j = 0; j < t.level(l)->grid_height; ++j) {
      for (uint32_t i = 0; i < t.level(l)->grid_width; ++i) {
        for (double v : modelImage(t, l, int(i), int(j))) {
          negative += std::max(0.0, -v);
          absolute += std::fabs(v);
        }
      }
    }
  }
  double worst = 0.0, mean = 0.0;
  const Footprint fps[] = {footprint(20, 30, 6), footprint(3, 60, 11), footprint(40, 40, 30)};
  for (const Footprint& fp : fps) mean += pdfEvalGap(t, fp, 4000, 9, &worst) / 3.0;
  std::printf(
      "[ figures  ] plain CP (rank 16): negative mass fraction before clamping %.3g; mean |pdf*mass - eval| / "
      "eval %.3g (worst %.3g)\n",
      negative / absolute, mean, worst);
  EXPECT_TRUE(std::isfinite(mean));
  EXPECT_LT(negative / absolute, 0.2);
  EXPECT_LT(mean, 0.2);
}

TEST(TensorNdf, ValuesAreNeverNegativeAndZeroOutsideTheSquare) {
  const TensorNdf& t = assets().plain;
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> pos(-100.0, 200.0), sig(0.0, 80.0), sp(-1.0, 1.0);
  for (int q = 0; q < 2000; ++q) {
    const Footprint fp = footprint(pos(rng), pos(rng), sig(rng));
    double v = -1.0;
    ASSERT_EQ(t.eval(fp, SPoint{sp(rng), sp(rng)}, &v), RuntimeStatus::kOk);
    ASSERT_GE(v, 0.0);
    ASSERT_EQ(t.pdf(fp, SPoint{sp(rng), sp(rng)}, &v), RuntimeStatus::kOk);
    ASSERT_GE(v, 0.0);
  }
  double v = -1.0;
  EXPECT_EQ(t.eval(footprint(1, 1, 5), SPoint{1.5, 0.0}, &v), RuntimeStatus::kOk);
  EXPECT_EQ(v, 0.0);
  EXPECT_EQ(t.pdf(footprint(1, 1, 5), SPoint{0.0, -1.01}, &v), RuntimeStatus::kOk);
  EXPECT_EQ(v, 0.0);
  EXPECT_EQ(t.eval(footprint(1, 1, 5), SPoint{NAN, 0.0}, &v), RuntimeStatus::kInvalidArgument);
  EXPECT_EQ(t.eval(footprint(1, 1, -1), SPoint{0.0, 0.0}, &v), RuntimeStatus::kInvalidArgument);
  NdfSample s;
  EXPECT_EQ(t.sample(footprint(1, 1, 5), 1.0, 0.5, &s), RuntimeStatus::kInvalidArgument);
  TensorNdf closed;
  EXPECT_EQ(closed.eval(footprint(1, 1, 5), SPoint{0, 0}, &v), RuntimeStatus::kInvalidArgument);
}

TEST(TensorNdf, Float16FactorsMatchFloat32) {
  const bake::NormalMap map = tinyMap();
  const std::vector<uint8_t> half = packAsset(map, true, 16, "half", 1);
  TensorNdf h;
  ASSERT_EQ(h.openMemory(half.data(), half.size()), RuntimeStatus::kOk);
  EXPECT_EQ(h.info()->precision, 1u);
  const TensorNdf& f = assets().nonneg;
  const int res = f.resolution();
  std::vector<float> a(size_t(res) * res), b(size_t(res) * res);
  for (const Footprint& fp : {footprint(20, 30, 6), footprint(50, 9, 14)}) {
    ASSERT_EQ(f.image(fp, a.data(), a.size()), RuntimeStatus::kOk);
    ASSERT_EQ(h.image(fp, b.data(), b.size()), RuntimeStatus::kOk);
    double err = 0.0, norm = 0.0;
    for (size_t n = 0; n < a.size(); ++n) {
      err += (double(a[n]) - b[n]) * (double(a[n]) - b[n]);
      norm += double(a[n]) * a[n];
    }
    EXPECT_LT(std::sqrt(err / norm), 5e-3);
  }
}

TEST(TensorNdf, ClampMapsClampTheCentreGrid) {
  const std::vector<uint8_t> bytes = packAsset(tinyMap(bake::MapKind::kBeckmann, true), true, 8, "clamp");
  TensorNdf t;
  ASSERT_EQ(t.openMemory(bytes.data(), bytes.size()), RuntimeStatus::kOk);
  EXPECT_EQ(t.level(0)->wrap, 1u);
  const std::string path = writeReconstructedPyramid(t, "clamp");
  NdfPyramid ref;
  ASSERT_EQ(ref.open(path.c_str()), RuntimeStatus::kOk);
  const int res = t.resolution();
  std::vector<float> a(size_t(res) * res), b(size_t(res) * res);
  for (const Footprint& fp : {footprint(-10, 3, 6), footprint(70, 80, 9), footprint(63, 1, 20)}) {
    ASSERT_EQ(t.image(fp, a.data(), a.size()), RuntimeStatus::kOk);
    ASSERT_EQ(ref.image(fp, b.data(), b.size()), RuntimeStatus::kOk);
    const float peak = *std::max_element(b.begin(), b.end());
    for (size_t n = 0; n < a.size(); ++n) ASSERT_NEAR(a[n], b[n], 2e-5 * peak);
  }
  std::remove(path.c_str());
}

TEST(TensorNdf, ConcurrentQueriesGiveTheSingleThreadedAnswers) {
  const TensorNdf& t = assets().plain;
  constexpr int kQueries = 2000;
  auto run = [&](uint64_t seed, std::vector<double>* out) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> pos(0.0, 64.0), sig(1.0, 40.0), u(0.0, 1.0);
    for (int q = 0; q < kQueries; ++q) {
      const Footprint fp = footprint(pos(rng), pos(rng), sig(rng));
      NdfSample s;
      double v = 0.0, a = 0.0;
      if (t.sample(fp, u(rng), u(rng), &s) != RuntimeStatus::kOk) s = NdfSample{};
      t.eval(fp, s.s, &v);
      SRect r;
      r.x0 = s.s.x - 0.1;
      r.x1 = s.s.x + 0.1;
      r.y0 = s.s.y - 0.2;
      r.y1 = s.s.y + 0.05;
      t.average(fp, r, &a);
      out->insert(out->end(), {s.s.x, s.s.y, s.pdf, v, a});
    }
  };
  std::vector<double> serial[2], threaded[2];
  run(1, &serial[0]);
  run(2, &serial[1]);
  std::thread first(run, 1, &threaded[0]), second(run, 2, &threaded[1]);
  first.join();
  second.join();
  EXPECT_EQ(serial[0], threaded[0]);
  EXPECT_EQ(serial[1], threaded[1]);
}

}  // namespace
}  // namespace glintbake::runtime::testing
