// SPDX-License-Identifier: Apache-2.0
// A consumer of an installed glintbake::render: compares two small images.
#include <glintbake/bake/render/image_compare.h>

#include <cstdio>

int main() {
  namespace render = glintbake::bake::render;
  render::RgbImage a, b;
  a.width = b.width = 2;
  a.height = b.height = 2;
  a.rgb.assign(12, 0.5f);
  b.rgb.assign(12, 0.5f);
  b.rgb[0] = 1.0f;
  const auto metrics = render::compareImages(a, b);
  if (!metrics || metrics.value().differing_values != 1) return 2;
  std::printf("render consumer ok: rmse %.4f\n", metrics.value().rmse);
  return 0;
}
