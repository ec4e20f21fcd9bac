// SPDX-License-Identifier: Apache-2.0
/* Renders a glinty plane lit by a point light with the glintbake C API and writes a PPM image.
 *   render_small ASSET.gbk OUT.ppm [SIZE]
 * The plane z = 0 carries the asset's map once over [0, 1]^2; an orthographic camera looks straight
 * down, so one pixel covers width / SIZE texels and the footprint's sigma is half of that (a pixel
 * filter of that std). The light sits above the plane's centre. */
#include <glintbake/runtime/glintbake_ndf_c.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char** argv) {
  if (argc < 3) { fprintf(stderr, "usage: render_small ASSET.gbk OUT.ppm [SIZE]\n"); return 1; }
  const int size = argc > 3 ? atoi(argv[3]) : 64;
  gb_ndf_asset* asset = NULL;
  gb_open_error error;
  if (gb_ndf_asset_open_ex(argv[1], &asset, &error) != GB_OK) {
    fprintf(stderr, "render_small: %s: error-%04d: %s\n", argv[1], (int)error.message_id, error.message);
    return 3;
  }
  int32_t width = 0, height = 0;
  gb_ndf_asset_map(asset, &width, &height, NULL);
  const double texels_per_pixel = (double)width / size, sigma = 0.5 * texels_per_pixel;
  const double light[3] = {0.5, 0.5, 0.6}, view[3] = {0.0, 0.0, 1.0}; /* view: towards the camera */
  float* rgb = malloc(sizeof(float) * 3 * size * size);
  if (!rgb || size < 1) return 1;
  double sum = 0.0;
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i) {
      const double u = (i + 0.5) / size, v = (j + 0.5) / size; /* plane position, y down as texels */
      double l[3] = {light[0] - u, light[1] - v, light[2]};
      const double dist2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2], inv = 1.0 / sqrt(dist2);
      for (int k = 0; k < 3; ++k) l[k] *= inv;
      /* Half vector; the tangent frame is x right (+u), y UP (-v: texel rows grow downwards), z out. */
      double h[3] = {l[0] + view[0], l[1] + view[1], l[2] + view[2]};
      const double hn = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
      for (int k = 0; k < 3; ++k) h[k] /= hn;
      double d_s = 0.0; /* density per unit s-plane area at s = (h_x, h_y) */
      if (gb_ndf_asset_eval(asset, u * width, v * height, sigma, h[0], -h[1], &d_s) != GB_OK) d_s = 0.0;
      /* The microfacet BRDF D(h) / (4 cos_i cos_o) (no shadowing, no Fresnel) times cos_i and the
       * light's inverse-square falloff; D per solid angle of h is D_s * cos(theta_h). */
      const double radiance = d_s * h[2] / (4.0 * view[2] * dist2);
      float* p = rgb + 3 * (j * size + i);
      p[0] = p[1] = p[2] = (float)(radiance * 0.2);
      sum += radiance;
    }
  FILE* out = fopen(argv[2], "wb");
  if (!out) { fprintf(stderr, "render_small: cannot write %s\n", argv[2]); return 2; }
  fprintf(out, "P6\n%d %d\n255\n", size, size);
  for (int n = 0; n < 3 * size * size; ++n) {
    const double c = rgb[n] <= 0.0f ? 0.0 : pow(rgb[n] > 1.0f ? 1.0 : rgb[n], 1.0 / 2.2); /* display gamma */
    fputc((int)(c * 255.0 + 0.5), out);
  }
  fclose(out);
  free(rgb);
  gb_ndf_asset_close(asset);
  printf("render_small: %dx%d, sigma %.3g texels, mean radiance %.4g (runtime %s)\n", size, size, sigma,
         sum / (size * size), gb_version_string());
  return sum > 0.0 ? 0 : 4;
}
