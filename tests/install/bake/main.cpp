// SPDX-License-Identifier: Apache-2.0
// A consumer of an installed glintbake::bake and glintbake::reference: generates a small normal
// map, writes it with the image library the baker uses, and builds the reference flakes of it.
#include <glintbake/bake/io/image_io.h>
#include <glintbake/bake/mapgen/mapgen.h>
#include <glintbake/reference/flakes.h>

#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  if (argc != 2) return 1;
  namespace bake = glintbake::bake;
  bake::MapParams params;
  params.size = 16;
  const bake::NormalMap map = bake::generateMap(bake::MapKind::kBeckmann, params);
  if (!bake::writeNormalMap(argv[1], map)) return 2;
  const glintbake::reference::FlakeSet flakes = glintbake::reference::buildFlakes(map);
  if (flakes.flakes.size() != 16u * 16u) return 3;
  std::printf("bake consumer ok: %zu flakes, map written to %s\n", flakes.flakes.size(), argv[1]);
  return 0;
}
