// SPDX-License-Identifier: Apache-2.0
// Small ndf-pyramid assets with a flakes section (formats/SPEC.md 10.5), and the maps they are
// made of, shared by the tests of this directory.
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/format/container.h>

#include "../temp_dir.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::testing {

// A Beckmann-like map of the procedural generator (bake/mapgen): roughness alpha, kernel std cell.
inline bake::NormalMap beckmannMap(int size, double alpha, double cell, uint64_t seed) {
  bake::MapParams p;
  p.size = size;
  p.seed = seed;
  p.alpha = alpha;
  p.cell = cell;
  return bake::generateMap(bake::MapKind::kBeckmann, p);
}

// A map of sharp flakes of the procedural generator: cells of mean size `cell` texels, each of one
// normal within `cone_degrees` of the z axis.
inline bake::NormalMap flakesMap(int size, double cell, double cone_degrees, uint64_t seed) {
  bake::MapParams p;
  p.size = size;
  p.seed = seed;
  p.cell = cell;
  p.cone_degrees = cone_degrees;
  return bake::generateMap(bake::MapKind::kFlakes, p);
}

// The pyramid of these assets: sigma0 4, stride 8, `levels` levels of R x R images.
inline bake::ndf::PyramidOptions smallPyramid(int res, int levels) {
  bake::ndf::PyramidOptions o;
  o.splat.ndf_res = res;
  o.stride0 = 8;
  o.sigma0 = 4;
  o.levels = levels;
  return o;
}

// Writes the pyramid `o` of `map` and then `flakes` (the bytes of a flakes section; none when
// null) to the process's temporary directory as `name`; returns its path.
inline std::string writePyramidAsset(const bake::NormalMap& map, const bake::ndf::PyramidOptions& o,
                                     const std::string& name, const std::vector<uint8_t>* flakes) {
  const std::string path = processTempDir() + name;
  format::Writer w;
  EXPECT_EQ(w.open(path, format::AssetKind::kNdfPyramid, 3), format::ContainerStatus::kOk);
  EXPECT_TRUE(bake::ndf::buildNdfPyramid(map, o, w, nullptr).ok());
  if (flakes) {
    EXPECT_EQ(w.addSection(format::kSectionFlakes, 0, flakes->data(), flakes->size()), format::ContainerStatus::kOk);
  }
  EXPECT_EQ(w.addMetadata("{}"), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  return path;
}

}  // namespace glintbake::testing
