// SPDX-License-Identifier: Apache-2.0
// Assets with a flakes section (formats/SPEC.md 10.5) through openNdfAsset: the flakes answer small
// footprints exactly, the pyramid large ones, and the band between blends them with sample, pdf,
// eval and mass consistent; a flakes section of another map is refused.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/flakes.h>
#include <glintbake/format/numbers.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/flake_ndf.h>
#include <glintbake/runtime/lobe_ndf.h>
#include <glintbake/runtime/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>

#include "../../stats/chi_square.h"
#include "flakes_asset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace glintbake {
namespace {

using runtime::Footprint;
using runtime::RuntimeStatus;
using runtime::SPoint;

// Writes an ndf-pyramid of `map` (sigma0 4, stride 8, 2 levels, R 32) with the flakes of `flakes_map`
// and the default hand-over for `lobes` lobes per tile, or `handover` when given.
std::string writeAsset(const bake::NormalMap& map, const bake::NormalMap& flakes_map, const std::string& name,
                       bool with_flakes = true, int lobes = 0, const bake::ndf::FlakesHandover* handover = nullptr) {
  const bake::ndf::PyramidOptions o = glintbake::testing::smallPyramid(32, 2);
  if (!with_flakes) return glintbake::testing::writePyramidAsset(map, o, name, nullptr);
  auto section = bake::ndf::flakesSectionBytes(flakes_map, 1, o.splat.sigma_r,
                                               handover ? *handover : bake::ndf::defaultHandover(o.sigma0, lobes));
  EXPECT_TRUE(section.ok());
  return glintbake::testing::writePyramidAsset(map, o, name, section.ok() ? &section.value() : nullptr);
}

bake::NormalMap beckmann(int size, uint64_t seed) {
  bake::MapParams p;
  p.size = size;
  p.seed = seed;
  return bake::generateMap(bake::MapKind::kBeckmann, p);
}

// `count` samples of the asset at fp: each sample's pdf is pdf(s), and pdf x mass = eval.
void expectSamplesMatchPdf(const runtime::NdfSource& asset, const Footprint& fp, double mass, uint64_t seed,
                           int count) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < count; ++i) {
    runtime::NdfSample smp;
    ASSERT_EQ(asset.sample(fp, u(rng), u(rng), &smp), RuntimeStatus::kOk);
    double pdf = -1.0, e = -1.0;
    ASSERT_EQ(asset.pdf(fp, smp.s, &pdf), RuntimeStatus::kOk);
    ASSERT_EQ(asset.eval(fp, smp.s, &e), RuntimeStatus::kOk);
    EXPECT_EQ(pdf, smp.pdf);
    EXPECT_NEAR(pdf * mass, e, 1e-12 * e);
  }
}

TEST(Handover, FlakesBelowBandBlendAndPyramidAbove) {
  const bake::NormalMap map = beckmann(32, 4);
  std::unique_ptr<runtime::NdfSource> asset, pyramid;
  ASSERT_EQ(runtime::openNdfAsset(writeAsset(map, map, "h.gbk").c_str(), &asset), RuntimeStatus::kOk);
  ASSERT_EQ(runtime::openNdfAsset(writeAsset(map, map, "p.gbk", false).c_str(), &pyramid), RuntimeStatus::kOk);
  EXPECT_EQ(asset->kind(), format::AssetKind::kNdfPyramid);
  const runtime::FootprintRange r = asset->footprintRange();
  EXPECT_EQ(r.exact_max_sigma, 4.0);
  EXPECT_NEAR(r.handover_max_sigma, 4.0 * std::sqrt(2.0), 1e-12);
  EXPECT_EQ(r.pyramid_min_sigma, 4.0);
  EXPECT_EQ(pyramid->footprintRange().exact_max_sigma, 0.0);

  const reference::FlakeSet set = reference::buildFlakes(map, 1);
  const SPoint s{0.05, -0.03};
  // Exact below the band (sigma 0 included, as the limit of small footprints).
  for (double sigma : {1e-6, 1.0, 4.0}) {
    double v = 0.0;
    ASSERT_EQ(asset->eval({13.2, 7.7, sigma}, s, &v), RuntimeStatus::kOk);
    const double ref = reference::evalPndf(set, {13.2, 7.7, sigma}, s.x, s.y, reference::kDefaultSigmaR);
    EXPECT_NEAR(v, ref, 2e-5 * ref + 1e-9) << "sigma " << sigma;
  }
  double zero = 0.0, tiny = 0.0;
  ASSERT_EQ(asset->eval({13.2, 7.7, 0.0}, s, &zero), RuntimeStatus::kOk);
  ASSERT_EQ(asset->eval({13.2, 7.7, 1e-6}, s, &tiny), RuntimeStatus::kOk);
  EXPECT_NEAR(zero, tiny, 1e-6 * tiny + 1e-12);
  // The pyramid alone above the band.
  for (double sigma : {6.0, 12.0}) {
    double a = 0.0, b = 0.0;
    ASSERT_EQ(asset->eval({13.2, 7.7, sigma}, s, &a), RuntimeStatus::kOk);
    ASSERT_EQ(pyramid->eval({13.2, 7.7, sigma}, s, &b), RuntimeStatus::kOk);
    EXPECT_EQ(a, b);
  }
  // In the band: the blend of both paths, linear in log sigma, and consistent.
  const double sigma = 4.0 * std::pow(2.0, 0.25);  // halfway through the band in log sigma
  const Footprint fp{13.2, 7.7, sigma};
  double v = 0.0, p = 0.0, m = 0.0;
  ASSERT_EQ(asset->eval(fp, s, &v), RuntimeStatus::kOk);
  ASSERT_EQ(pyramid->eval(fp, s, &p), RuntimeStatus::kOk);
  const double f = reference::evalPndf(set, {fp.x, fp.y, sigma}, s.x, s.y, reference::kDefaultSigmaR);
  EXPECT_NEAR(v, 0.5 * f + 0.5 * p, 1e-4 * v);
  ASSERT_EQ(asset->mass(fp, &m), RuntimeStatus::kOk);
  expectSamplesMatchPdf(*asset, fp, m, 3, 200);
}

TEST(Handover, FlakesLobesAndPyramidBlendConsistently) {
  const bake::NormalMap map = beckmann(32, 4);
  std::unique_ptr<runtime::NdfSource> asset, pyramid;
  ASSERT_EQ(runtime::openNdfAsset(writeAsset(map, map, "l.gbk", true, 16).c_str(), &asset), RuntimeStatus::kOk);
  ASSERT_EQ(runtime::openNdfAsset(writeAsset(map, map, "q.gbk", false).c_str(), &pyramid), RuntimeStatus::kOk);
  // sigma0 4: flakes to 4, the lobes alone at 4 sqrt(2), the pyramid alone from 8.
  const runtime::FootprintRange r = asset->footprintRange();
  EXPECT_EQ(r.exact_max_sigma, 4.0);
  EXPECT_NEAR(r.clustered_min_sigma, 4.0 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(r.clustered_max_sigma, 4.0 * std::sqrt(2.0), 1e-12);
  EXPECT_EQ(r.handover_max_sigma, 8.0);
  const SPoint s{0.05, -0.03};
  double a = 0.0, b = 0.0;
  ASSERT_EQ(asset->eval({13.2, 7.7, 9.0}, s, &a), RuntimeStatus::kOk);
  ASSERT_EQ(pyramid->eval({13.2, 7.7, 9.0}, s, &b), RuntimeStatus::kOk);
  EXPECT_EQ(a, b);
  // Both bands (flakes to lobes, lobes to pyramid) and the flakes and the pyramid alone: sample,
  // pdf, eval and mass agree, and the mass stays that of a footprint inside the map.
  for (double sigma : {2.0, 4.7, 6.8, 9.0}) {
    const Footprint fp{13.2, 7.7, sigma};
    double m = 0.0;
    ASSERT_EQ(asset->mass(fp, &m), RuntimeStatus::kOk);
    EXPECT_NEAR(m, 1.0, 0.01) << sigma;
    expectSamplesMatchPdf(*asset, fp, m, 5, 200);
  }
}

// The reference P-NDF with the footprint weights truncated at `window` standard deviations and
// scaled by the inverse of that disk's share of a Gaussian: the flakes' share of a hand-over band
// (runtime kBandFlakeWindow = 4).
double bandReference(const reference::FlakeSet& set, const Footprint& fp, SPoint s, double window = 4.0) {
  const reference::Footprint rfp{fp.x, fp.y, fp.sigma};
  const double v = set.sigma_h * set.sigma_h + fp.sigma * fp.sigma;
  const double peak = set.area / (kTwoPi * v), cut = window * window / 2.0;
  double sum = 0.0;
  for (const reference::FlakeLobe& lobe : reference::footprintLobes(set, rfp, reference::kDefaultSigmaR)) {
    if (std::log(peak / lobe.weight) <= cut) sum += reference::lobeDensity(lobe, s.x, s.y);
  }
  return sum / (1.0 - std::exp(-cut));
}

// Between the flakes and the lobes that answer from the exact flakes in their narrower window, the
// asset evaluates both from one traversal: the blend of the flakes in a 4-sigma window and of the
// lobes evaluated apart, at points where the NDF matters and anywhere, near the map's edges too
// (periodic windows).
TEST(Handover, FlakesToLobesBandIsTheBlendOfBothPaths) {
  const bake::NormalMap map = beckmann(32, 9);
  std::unique_ptr<runtime::NdfSource> asset;
  ASSERT_EQ(runtime::openNdfAsset(writeAsset(map, map, "band.gbk", true, 16).c_str(), &asset), RuntimeStatus::kOk);
  const runtime::InterleavedTexels texels(map.width, map.height, map.wrap == bake::Wrap::kRepeat, map.normals.data(),
                                          3);
  const reference::FlakeSet set = reference::buildFlakes(map, 1);
  runtime::LobeNdf lobes;
  ASSERT_EQ(lobes.build(texels, 1, 0.005, 16, 32), RuntimeStatus::kOk);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int compared = 0;
  for (double sigma : {4.2, 4.7, 5.4}) {
    const double t = std::log(sigma / 4.0) / std::log(std::sqrt(2.0));
    for (int i = 0; i < 120; ++i) {
      const Footprint fp{i % 3 == 0 ? 0.3 : u(rng) * 32.0, i % 5 == 0 ? 31.8 : u(rng) * 32.0, sigma};
      SPoint s{u(rng) * 1.2 - 0.6, u(rng) * 1.2 - 0.6};
      if (i % 2 == 0) {
        runtime::NdfSample smp;
        ASSERT_EQ(asset->sample(fp, u(rng), u(rng), &smp), RuntimeStatus::kOk);
        s = smp.s;
      }
      double v = -1.0, l = -1.0;
      ASSERT_EQ(asset->eval(fp, s, &v), RuntimeStatus::kOk);
      ASSERT_EQ(lobes.eval(fp, s, &l), RuntimeStatus::kOk);
      const double expected = (1.0 - t) * bandReference(set, fp, s) + t * l;
      EXPECT_NEAR(v, expected, 2e-5 * expected + 1e-6)  // the flake path against the reference
          << "sigma " << sigma << " at (" << fp.x << ", " << fp.y << ")";
      compared += expected > 1e-3;
    }
  }
  EXPECT_GT(compared, 150);  // most of them where the NDF is not negligible
}

// Inside the flakes-to-lobes band (the flakes in their 4-sigma window): samples follow the pdf
// (chi-square against the image) and averages are the image's bins.
TEST(Handover, BandSamplesFollowThePdfAndAveragesTheImage) {
  const bake::NormalMap map = beckmann(32, 9);
  std::unique_ptr<runtime::NdfSource> asset;
  ASSERT_EQ(runtime::openNdfAsset(writeAsset(map, map, "bandimg.gbk", true, 16).c_str(), &asset), RuntimeStatus::kOk);
  const int res = asset->resolution();
  const Footprint fp{20.3, 11.6, 4.7};
  std::vector<float> img(size_t(res) * res);
  ASSERT_EQ(asset->image(fp, img.data(), img.size()), RuntimeStatus::kOk);
  double mass = 0.0;
  ASSERT_EQ(asset->mass(fp, &mass), RuntimeStatus::kOk);
  EXPECT_NEAR(mass, 1.0, 0.01);
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  struct S {
    double sx, sy;
  };
  std::vector<S> samples;
  for (int i = 0; i < 20000; ++i) {
    runtime::NdfSample smp;
    ASSERT_EQ(asset->sample(fp, u(rng), u(rng), &smp), RuntimeStatus::kOk);
    samples.push_back({smp.s.x, smp.s.y});
  }
  const std::vector<double> image(img.begin(), img.end());
  const stats::ChiSquareResult r = stats::chiSquareNdfTest(samples, image, res, mass);
  EXPECT_GT(r.p_value, 0.01) << r.message;
  const double bin = 2.0 / res;
  for (int j = 6; j < res - 6; j += 5) {
    for (int i = 6; i < res - 6; i += 5) {
      const runtime::SRect rect{-1.0 + i * bin, 1.0 - (j + 1) * bin, -1.0 + (i + 1) * bin, 1.0 - j * bin};
      double avg = 0.0;
      ASSERT_EQ(asset->average(fp, rect, &avg), RuntimeStatus::kOk);
      EXPECT_NEAR(avg, img[size_t(j) * res + i], 1e-4 * avg + 1e-6);
    }
  }
}

// Where a compressed pyramid takes over from the lobes: above its first level from which every
// level is faithful (sqrt(2) and 2 times that level's sigma), at that level's own sigma when it is
// stored exactly, and nowhere (the lobes answer everything) when no level is faithful.
TEST(Handover, CompressedPyramidsHandOverAtTheirFirstFaithfulLevel) {
  const double sigmas[4] = {8, 16, 32, 64};
  const double mixed[4] = {2.0, 1.5, 0.5, 0.2};
  bake::ndf::FlakesHandover h = bake::ndf::compressedHandover(sigmas, mixed, 4, 1.0, 16);
  EXPECT_DOUBLE_EQ(h.flakes_up_to, 4.0);
  EXPECT_EQ(h.lobes_per_tile, 16);
  EXPECT_DOUBLE_EQ(h.lobes_up_to, 32.0 * std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(h.pyramid_from, 64.0);
  const bool exact[4] = {false, false, true, true};
  h = bake::ndf::compressedHandover(sigmas, mixed, 4, 1.0, 16, exact);
  EXPECT_DOUBLE_EQ(h.lobes_up_to, 32.0);
  EXPECT_DOUBLE_EQ(h.pyramid_from, 32.0 * std::sqrt(2.0));
  // An exact level whose blend the probe finds unfaithful hands over as a compressed one does, and
  // the level above is probed next; the probe is asked for those levels only, in order.
  std::vector<int> asked;
  auto probe = [&asked](int losing_up_to) {
    return [&asked, losing_up_to](int level) {
      asked.push_back(level);
      return level <= losing_up_to;
    };
  };
  h = bake::ndf::compressedHandover(sigmas, mixed, 4, 1.0, 16, exact, probe(-1));
  EXPECT_DOUBLE_EQ(h.lobes_up_to, 32.0);
  EXPECT_DOUBLE_EQ(h.pyramid_from, 32.0 * std::sqrt(2.0));
  EXPECT_EQ(asked, std::vector<int>({2}));
  asked.clear();
  h = bake::ndf::compressedHandover(sigmas, mixed, 4, 1.0, 16, exact, probe(2));
  EXPECT_DOUBLE_EQ(h.lobes_up_to, 32.0 * std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(h.pyramid_from, 64.0);
  EXPECT_EQ(asked, std::vector<int>({2, 3}));
  asked.clear();
  h = bake::ndf::compressedHandover(sigmas, mixed, 4, 1.0, 16, exact, probe(3));
  EXPECT_DOUBLE_EQ(h.lobes_up_to, 64.0 * std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(h.pyramid_from, 128.0);
  EXPECT_EQ(asked, std::vector<int>({2, 3}));
  asked.clear();
  // A compressed first faithful level is not probed.
  h = bake::ndf::compressedHandover(sigmas, mixed, 4, 1.0, 16, nullptr, probe(3));
  EXPECT_TRUE(asked.empty());
  const double none[4] = {2.0, 2.0, 2.0, 2.0};
  h = bake::ndf::compressedHandover(sigmas, none, 4, 1.0, 16);
  EXPECT_GE(h.lobes_up_to, 1e6);
  EXPECT_GE(h.pyramid_from, 1e6);
  // Every level faithful: as for an uncompressed pyramid.
  const double all[4] = {0.1, 0.1, 0.1, 0.1};
  h = bake::ndf::compressedHandover(sigmas, all, 4, 1.0, 16);
  EXPECT_DOUBLE_EQ(h.lobes_up_to, bake::ndf::defaultHandover(8.0, 16).lobes_up_to);
  EXPECT_DOUBLE_EQ(h.pyramid_from, bake::ndf::defaultHandover(8.0, 16).pyramid_from);
  // Without lobes the flakes hand over to the pyramid whatever the errors.
  h = bake::ndf::compressedHandover(sigmas, none, 4, 1.0, 0, exact);
  EXPECT_EQ(h.lobes_per_tile, 0);
  EXPECT_DOUBLE_EQ(h.flakes_up_to, bake::ndf::defaultHandover(8.0, 0).flakes_up_to);
}

// A record whose lobes answer every footprint (a compressed pyramid without a faithful level) on a
// map small enough that the lobes' window bounds them: the pyramid answers beyond that bound
// instead of the query failing, and the band below it stays consistent.
TEST(Handover, LobesBoundedByTheirWindowHandOverToThePyramid) {
  const bake::NormalMap map = beckmann(16, 6);
  bake::ndf::FlakesHandover h = bake::ndf::defaultHandover(4.0, 16);
  h.lobes_up_to = h.pyramid_from = 1e6;
  std::unique_ptr<runtime::NdfSource> asset, pyramid;
  ASSERT_EQ(runtime::openNdfAsset(writeAsset(map, map, "u.gbk", true, 16, &h).c_str(), &asset), RuntimeStatus::kOk);
  ASSERT_EQ(runtime::openNdfAsset(writeAsset(map, map, "v.gbk", false).c_str(), &pyramid), RuntimeStatus::kOk);
  runtime::LobeNdf lobes;
  const runtime::InterleavedTexels texels(map.width, map.height, true, map.normals.data(), 3);
  ASSERT_EQ(lobes.build(texels, 1, reference::kDefaultSigmaR, 16, 32), RuntimeStatus::kOk);
  const double limit = lobes.footprintRange().clustered_max_sigma;
  ASSERT_LT(limit, 1e5);
  const runtime::FootprintRange r = asset->footprintRange();
  EXPECT_DOUBLE_EQ(r.handover_max_sigma, limit);
  EXPECT_NEAR(r.clustered_max_sigma, limit / std::sqrt(2.0), 1e-6 * limit);
  const SPoint s{0.05, -0.03};
  for (double sigma : {limit, 3.0 * limit, 1e5}) {
    double a = -1.0, b = -2.0;
    ASSERT_EQ(asset->eval({5.2, 3.7, sigma}, s, &a), RuntimeStatus::kOk) << sigma;
    ASSERT_EQ(pyramid->eval({5.2, 3.7, sigma}, s, &b), RuntimeStatus::kOk) << sigma;
    EXPECT_EQ(a, b) << sigma;
  }
  // Inside the band below the bound: sample, pdf, eval and mass agree.
  const Footprint fp{5.2, 3.7, limit / std::pow(2.0, 0.25)};
  double m = 0.0;
  ASSERT_EQ(asset->mass(fp, &m), RuntimeStatus::kOk);
  EXPECT_NEAR(m, 1.0, 0.01);
  expectSamplesMatchPdf(*asset, fp, m, 7, 50);
}

TEST(Handover, SmallRepeatingMapsHandOverWhereTheFootprintIsFlat) {
  const bake::ndf::FlakesHandover d = bake::ndf::defaultHandover(8.0, 16);  // lobes to 11.3, pyramid from 16
  // A 16 x 16 repeating map: flat from 0.62 x 16 = 9.92 texels.
  bake::ndf::FlakesHandover h = bake::ndf::capAtFlatFootprint(d, 16, 12, true);
  EXPECT_DOUBLE_EQ(h.pyramid_from, 0.62 * 16);
  EXPECT_DOUBLE_EQ(h.lobes_up_to, 0.62 * 16 / std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(h.flakes_up_to, d.flakes_up_to);
  h = bake::ndf::capAtFlatFootprint(d, 9, 6, true);  // never below the lobes' start
  EXPECT_DOUBLE_EQ(h.pyramid_from, 4.0 * std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(h.lobes_up_to, 4.0 * std::sqrt(2.0));
  h = bake::ndf::capAtFlatFootprint(d, 20, 25, true);  // 15.5: the band ends there
  EXPECT_DOUBLE_EQ(h.pyramid_from, 0.62 * 25);
  EXPECT_DOUBLE_EQ(h.lobes_up_to, 0.62 * 25 / std::sqrt(2.0));
  // Unchanged: larger maps, clamped maps, lobes that answer every footprint, no lobes.
  for (const bake::ndf::FlakesHandover& same :
       {bake::ndf::capAtFlatFootprint(d, 64, 64, true), bake::ndf::capAtFlatFootprint(d, 16, 16, false)}) {
    EXPECT_EQ(same.pyramid_from, d.pyramid_from);
    EXPECT_EQ(same.lobes_up_to, d.lobes_up_to);
  }
  bake::ndf::FlakesHandover unbounded = d;
  unbounded.lobes_up_to = unbounded.pyramid_from = 1e6;
  EXPECT_EQ(bake::ndf::capAtFlatFootprint(unbounded, 16, 16, true).pyramid_from, 1e6);
  const bake::ndf::FlakesHandover none = bake::ndf::defaultHandover(8.0, 0);
  EXPECT_EQ(bake::ndf::capAtFlatFootprint(none, 16, 16, true).pyramid_from, none.pyramid_from);
  // The section records the capped hand-over whatever it is given.
  const bake::NormalMap map = beckmann(16, 8);
  auto bytes = bake::ndf::flakesSectionBytes(map, 1, reference::kDefaultSigmaR, d);
  ASSERT_TRUE(bytes.ok());
  format::FlakesRecord rec;
  std::memcpy(&rec, bytes.value().data(), sizeof(rec));
  EXPECT_DOUBLE_EQ(rec.pyramid_from, 0.62 * 16);
  EXPECT_DOUBLE_EQ(rec.lobes_up_to, 0.62 * 16 / std::sqrt(2.0));
}

// The top-left width x height texels of `map`, clamped at their edges.
bake::NormalMap clampedCrop(const bake::NormalMap& map, int width, int height) {
  bake::NormalMap out;
  out.width = width;
  out.height = height;
  out.wrap = bake::Wrap::kClamp;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) out.normals.insert(out.normals.end(), map.at(x, y), map.at(x, y) + 3);
  return out;
}

TEST(Handover, SmallClampedMapsAnswerFromTheirFlakesUntilTheFootprintIsFlat) {
  namespace nd = bake::ndf;
  const nd::FlakesHandover d = nd::defaultHandover(8.0, 16);
  // 37 x 23 texels, clamped: the flakes alone up to 2 x 37 texels, then the pyramid.
  const nd::FlakesHandover h = nd::fitHandoverToMap(d, 37, 23, false, 1);
  EXPECT_DOUBLE_EQ(h.flakes_up_to, 74.0);
  EXPECT_EQ(h.lobes_per_tile, 0);
  EXPECT_EQ(h.lobes_up_to, 0.0);
  EXPECT_DOUBLE_EQ(h.pyramid_from, 74.0 * std::sqrt(2.0));
  // Unchanged: more flakes than kSmallClampedMapFlakes (by size or by rate), a window past the
  // flakes' limit at that footprint (a strip 4000 texels long), flakes that already answer farther.
  nd::FlakesHandover farther = nd::defaultHandover(8.0, 0);
  farther.flakes_up_to = 100.0;
  farther.pyramid_from = 200.0;
  for (const auto& [given, fitted] : {std::pair{d, nd::fitHandoverToMap(d, 65, 64, false, 1)},
                                      std::pair{d, nd::fitHandoverToMap(d, 37, 23, false, 3)},
                                      std::pair{d, nd::fitHandoverToMap(d, 4000, 1, false, 1)},
                                      std::pair{farther, nd::fitHandoverToMap(farther, 37, 23, false, 1)}}) {
    EXPECT_EQ(fitted.flakes_up_to, given.flakes_up_to);
    EXPECT_EQ(fitted.lobes_per_tile, given.lobes_per_tile);
    EXPECT_EQ(fitted.lobes_up_to, given.lobes_up_to);
    EXPECT_EQ(fitted.pyramid_from, given.pyramid_from);
  }
  // Repeating maps: capAtFlatFootprint's rule.
  EXPECT_EQ(nd::fitHandoverToMap(d, 16, 12, true, 1).pyramid_from,
            nd::capAtFlatFootprint(d, 16, 12, true).pyramid_from);

  // An asset of a 30 x 20 clamped map, given the default hand-over, records the fitted one and
  // answers footprints as wide as the map from the flakes: the reference's values. (Its two-level
  // pyramid and lobes answered them before: median errors of these points 5% at 6 texels and
  // 21-36% at 12-60, up to 2.5x.)
  const bake::NormalMap map = clampedCrop(beckmann(32, 9), 30, 20);
  std::unique_ptr<runtime::NdfSource> asset;
  ASSERT_EQ(runtime::openNdfAsset(writeAsset(map, map, "small_clamped.gbk", true, 16).c_str(), &asset),
            RuntimeStatus::kOk);
  const runtime::FootprintRange r = asset->footprintRange();
  EXPECT_DOUBLE_EQ(r.exact_max_sigma, 60.0);
  EXPECT_DOUBLE_EQ(r.handover_max_sigma, 60.0 * std::sqrt(2.0));
  EXPECT_EQ(r.clustered_max_sigma, 0.0);
  const reference::FlakeSet set = reference::buildFlakes(map, 1);
  for (double sigma : {6.0, 12.0, 20.0, 40.0, 60.0}) {
    for (const Footprint& fp :
         {Footprint{15.0, 10.0, sigma}, Footprint{2.5, 18.0, sigma}, Footprint{-8.0, 4.0, sigma}}) {
      double m = 0.0;
      ASSERT_EQ(asset->mass(fp, &m), RuntimeStatus::kOk);
      // Points where this footprint's NDF is not negligible: its own samples.
      std::mt19937_64 rng(uint64_t(sigma * 100.0 + fp.x));
      std::uniform_real_distribution<double> u(0.0, 1.0);
      for (int i = 0; i < 4; ++i) {
        runtime::NdfSample smp;
        ASSERT_EQ(asset->sample(fp, u(rng), u(rng), &smp), RuntimeStatus::kOk);
        double v = 0.0;
        ASSERT_EQ(asset->eval(fp, smp.s, &v), RuntimeStatus::kOk);
        const double ref = reference::evalPndf(set, {fp.x, fp.y, sigma}, smp.s.x, smp.s.y, reference::kDefaultSigmaR);
        EXPECT_NEAR(v, ref, 2e-5 * ref + 1e-9) << "sigma " << sigma << " at " << fp.x << ", " << fp.y;
        EXPECT_NEAR(smp.pdf * m, v, 1e-12 * v);
      }
    }
  }
}

TEST(Handover, FlakesOfAnotherMapAreRefused) {
  const bake::NormalMap map = beckmann(32, 4), other = beckmann(16, 5);
  std::unique_ptr<runtime::NdfSource> asset;
  EXPECT_EQ(runtime::openNdfAsset(writeAsset(map, other, "x.gbk").c_str(), &asset), RuntimeStatus::kInvalidAsset);
  EXPECT_EQ(asset, nullptr);
}

}  // namespace
}  // namespace glintbake
