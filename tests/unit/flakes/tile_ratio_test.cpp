// SPDX-License-Identifier: Apache-2.0
// The clustered path's tile ratio (formats/SPEC.md 10.5): the version-3 trailer of the flakes
// record, its checks in the format library, the validator and the runtime loader, the runtime's
// setter, and the writer's choice (bake::ndf::chooseLobeTileRatio): finer tiles for a map of dense
// fine scratches whose tiles hold more distinct normals than a tile keeps lobes, the default where
// the lobes stay close or where no footprint the lobes answer is probed.
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/flakes_section.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/format/container.h>
#include <glintbake/format/kinds/flakes.h>
#include <glintbake/format/validate.h>
#include <glintbake/reference/pndf.h>
#include <glintbake/runtime/lobe_ndf.h>
#include <glintbake/runtime/ndf_source.h>
#include <glintbake/runtime/texel_source.h>

#include "flakes_asset.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

namespace glintbake {
namespace {

using runtime::RuntimeStatus;

bake::NormalMap denseScratches(int size) {
  bake::MapParams p;
  p.size = size;
  p.seed = 13;
  p.density = 8.0;
  p.width = 1.0;
  p.scratch_slope = 1.5;
  return bake::generateMap(bake::MapKind::kScratches, p);
}

bake::NormalMap beckmann(int size, double alpha, double cell) { return testing::beckmannMap(size, alpha, cell, 7); }

// A hand-over whose lobes answer every probe footprint (up to the pyramid from 64 texels); the
// tests narrow it.
bake::ndf::FlakesHandover wideLobes() {
  bake::ndf::FlakesHandover h = bake::ndf::defaultHandover(32.0, 16);
  h.lobes_up_to = 45.0;
  h.pyramid_from = 64.0;
  return h;
}

uint32_t chosenRatio(const bake::NormalMap& map, const bake::ndf::FlakesHandover& h,
                     uint64_t max_probe_flakes = bake::ndf::kLobeProbeMaxFlakes) {
  const runtime::InterleavedTexels texels(map.width, map.height, map.wrap == bake::Wrap::kRepeat, map.normals.data(),
                                          3);
  return bake::ndf::chooseLobeTileRatio(texels, 1, reference::kDefaultSigmaR, h.lobes_per_tile, h.pyramid_from,
                                        max_probe_flakes);
}

TEST(LobeTileRatio, TrailerIsCheckedAndReadWithTheRecord) {
  format::FlakesRecord rec;
  rec.map_width = 4;
  rec.map_height = 2;
  rec.sigma_r = 0.005;
  rec.flakes_up_to = 4.0;
  rec.pyramid_from = 8.0;
  EXPECT_EQ(rec.version, 3u);
  EXPECT_EQ(format::flakesSectionSize(rec), 64u + 4u * 2u * 8u + 8u);
  EXPECT_EQ(format::checkFlakesRecord(rec, 64 + 64 + 8), nullptr);
  EXPECT_NE(format::checkFlakesRecord(rec, 64 + 64), nullptr);  // the trailer is missing
  std::vector<uint8_t> section(64 + 64 + 8, 0);
  std::memcpy(section.data(), &rec, sizeof(rec));
  format::FlakesTrailer t;
  t.tile_ratio_milli = 175;
  std::memcpy(section.data() + section.size() - 8, &t, sizeof(t));
  uint32_t milli = 0;
  ASSERT_TRUE(format::flakesTileRatio(rec, section.data(), section.size(), &milli));
  EXPECT_EQ(milli, 175u);
  for (const format::FlakesTrailer bad :
       {format::FlakesTrailer{61, 0}, format::FlakesTrailer{1001, 0}, format::FlakesTrailer{350, 1}}) {
    EXPECT_NE(format::checkFlakesTrailer(bad), nullptr);
    std::memcpy(section.data() + section.size() - 8, &bad, sizeof(bad));
    EXPECT_FALSE(format::flakesTileRatio(rec, section.data(), section.size(), &milli));
  }
  EXPECT_EQ(format::checkFlakesTrailer(format::FlakesTrailer{62, 0}), nullptr);
  EXPECT_EQ(format::checkFlakesTrailer(format::FlakesTrailer{1000, 0}), nullptr);
  // Version 2 has no trailer: the default.
  rec.version = 2;
  EXPECT_EQ(format::flakesSectionSize(rec), 64u + 4u * 2u * 8u);
  ASSERT_TRUE(format::flakesTileRatio(rec, section.data(), 64 + 64, &milli));
  EXPECT_EQ(milli, format::kDefaultFlakesTileRatioMilli);
}

// An ndf-pyramid of `map` with its flakes and `handover`; `trailer` (when not 0) overwrites the
// section's tile ratio as written, out of range if need be.
std::string assetWith(const bake::NormalMap& map, const bake::ndf::FlakesHandover& handover, const std::string& name,
                      uint32_t trailer = 0) {
  const bake::ndf::PyramidOptions o = glintbake::testing::smallPyramid(16, 1);
  auto section = bake::ndf::flakesSectionBytes(map, 1, o.splat.sigma_r, handover);
  EXPECT_TRUE(section.ok());
  std::vector<uint8_t> bytes = section.ok() ? section.value() : std::vector<uint8_t>();
  if (trailer != 0 && bytes.size() >= 8) std::memcpy(bytes.data() + bytes.size() - 8, &trailer, 4);
  return glintbake::testing::writePyramidAsset(map, o, name, &bytes);
}

bool hasMessage(const format::ValidationReport& r, int code) {
  for (const auto& m : r.messages)
    if (m.id == code) return true;
  return false;
}

TEST(LobeTileRatio, ReadersRefuseATrailerOutOfRange) {
  const bake::NormalMap map = beckmann(24, 0.3, 0.0);
  bake::ndf::FlakesHandover h = bake::ndf::defaultHandover(4.0, 16);
  h.tile_ratio_milli = 250;  // as given: no probe
  const std::string good = assetWith(map, h, "tile_ratio_good.gbk");
  const std::string bad = assetWith(map, h, "tile_ratio_bad.gbk", 5000);
  EXPECT_FALSE(hasMessage(format::validateFile(good), 4008));
  EXPECT_TRUE(hasMessage(format::validateFile(bad), 4008));
  std::unique_ptr<runtime::NdfSource> asset;
  EXPECT_EQ(runtime::openNdfAsset(good.c_str(), &asset), RuntimeStatus::kOk);
  EXPECT_EQ(runtime::openNdfAsset(bad.c_str(), &asset), RuntimeStatus::kInvalidAsset);
}

TEST(LobeTileRatio, FinerRatiosAnswerFromFinerTiles) {
  const bake::NormalMap map = beckmann(96, 0.3, 0.0);
  const runtime::InterleavedTexels texels(map.width, map.height, true, map.normals.data(), 3);
  runtime::LobeNdf lobes;
  EXPECT_EQ(lobes.setTileRatio(0.35), RuntimeStatus::kInvalidArgument);  // not built
  ASSERT_EQ(lobes.build(texels, 1, reference::kDefaultSigmaR, 16, 32), RuntimeStatus::kOk);
  EXPECT_EQ(lobes.tileRatio(), runtime::kDefaultLobeTileRatio);
  EXPECT_EQ(lobes.tileFor(24.0), 8);  // 0.35 x 24 = 8.4
  ASSERT_EQ(lobes.setTileRatio(0.175), RuntimeStatus::kOk);
  EXPECT_EQ(lobes.tileFor(24.0), 4);
  EXPECT_EQ(lobes.tileFor(48.0), 8);
  for (double bad : {0.0, 0.05, 1.5, -0.35}) EXPECT_EQ(lobes.setTileRatio(bad), RuntimeStatus::kInvalidArgument) << bad;
  EXPECT_EQ(lobes.tileRatio(), 0.175);
  // Eval, mass and the image stay consistent at the finer ratio (eval integrates to the mass).
  const runtime::Footprint fp{40.5, 17.25, 24.0};
  double mass = 0.0;
  ASSERT_EQ(lobes.mass(fp, &mass), RuntimeStatus::kOk);
  std::vector<float> img(32 * 32);
  ASSERT_EQ(lobes.image(fp, img.data(), img.size()), RuntimeStatus::kOk);
  double held = 0.0;
  for (float b : img) held += double(b) * (2.0 / 32) * (2.0 / 32);
  EXPECT_NEAR(held, mass, 2e-3 * mass);
}

TEST(LobeTileRatio, DenseFineScratchesGetFinerTiles) {
  // Scratches a texel wide, 8 per 1000 texel^2: an 8 x 8 tile crosses more distinct normals than
  // it keeps lobes, and at 24-32 texels the NDF is close to the whole map's, so the blur shows.
  bake::ndf::FlakesHandover h = wideLobes();
  h.lobes_up_to = 32.0;
  h.pyramid_from = 40.0;  // (probes at 24 and 32 texels)
  EXPECT_LT(chosenRatio(denseScratches(160), h), format::kDefaultFlakesTileRatioMilli);
  // Same map, but the pyramid answers from 16 texels: no probe footprint, the default.
  bake::ndf::FlakesHandover early = wideLobes();
  early.lobes_up_to = 11.3;
  early.pyramid_from = 16.0;
  EXPECT_EQ(chosenRatio(denseScratches(160), early), format::kDefaultFlakesTileRatioMilli);
  // Without lobes, the default.
  bake::ndf::FlakesHandover none = wideLobes();
  none.lobes_per_tile = 0;
  EXPECT_EQ(chosenRatio(denseScratches(160), none), format::kDefaultFlakesTileRatioMilli);
}

TEST(LobeTileRatio, SmoothlyVaryingGlintsKeepTheDefault) {
  // Broad bumps (a 48-texel kernel): within a tile the normals vary smoothly, so 16 lobes hold
  // them, and across the map the NDF varies strongly. The lobes answer up to 32 texels and blend
  // into the pyramid below 45, as above a first exact level of 32 texels.
  bake::ndf::FlakesHandover h = wideLobes();
  h.lobes_up_to = 32.0;
  h.pyramid_from = 45.0;
  EXPECT_EQ(chosenRatio(beckmann(192, 0.6, 48.0), h), format::kDefaultFlakesTileRatioMilli);
}

TEST(LobeTileRatio, LargeMapsAreProbedOnAWindowAtTheirCentre) {
  // Broad bumps with dense fine scratches in the middle ninth: probed whole, the positions spread
  // over the map see mostly the bumps and keep the default; probed within a bound of 128^2 flakes,
  // the window at the centre (texels 128-255 on either axis, on the 128-texel grid) holds only the
  // scratches, and the choice is that of the window on its own as a clamped map.
  bake::NormalMap map = beckmann(384, 0.6, 48.0);
  const bake::NormalMap scratches = denseScratches(128);
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) std::memcpy(map.at(128 + x, 128 + y), scratches.at(x, y), 3 * sizeof(float));
  bake::NormalMap window = scratches;
  window.wrap = bake::Wrap::kClamp;
  bake::ndf::FlakesHandover h = wideLobes();
  h.lobes_up_to = 32.0;
  h.pyramid_from = 40.0;
  const uint32_t cropped = chosenRatio(map, h, 128 * 128);
  EXPECT_LT(cropped, format::kDefaultFlakesTileRatioMilli);
  EXPECT_EQ(cropped, chosenRatio(window, h));
  EXPECT_EQ(chosenRatio(map, h), format::kDefaultFlakesTileRatioMilli);
}

}  // namespace
}  // namespace glintbake
