// SPDX-License-Identifier: Apache-2.0
// Image comparison for renders (glintref compare) and PNG previews for reports.
#pragma once

#include <glintbake/bake/result.h>

#include <string>
#include <vector>

namespace glintbake::bake::render {

// A float RGB image, row 0 at the top.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width * height * 3
};

// Reads any image OpenImageIO reads (EXR, PNG, ...) as float RGB: one channel is replicated, alpha
// and further channels are dropped. Errors: kIo (cannot open or read), kInvalidInput (no pixels,
// non-finite values, more than 2^28 pixels).
Result<RgbImage> loadRgbImage(const std::string& path);

// Error metrics of `test` against `reference` over every channel of every pixel:
//   rmse          = sqrt(mean((t - r)^2))
//   relative_mse  = sum((t - r)^2) / sum(r^2)          (0 when both are zero)
//   psnr          = 20 log10(peak / rmse), peak = the reference's largest value (or 1 when it is 0);
//                   infinite for identical images (reported as +inf / null in JSON)
//   max_abs_error = max |t - r|
struct CompareMetrics {
  double rmse = 0.0;
  double relative_mse = 0.0;
  double psnr = 0.0;
  double max_abs_error = 0.0;
  double peak = 1.0;
  size_t differing_values = 0;  // values with t != r
};

// kBadArgument when the sizes differ.
Result<CompareMetrics> compareImages(const RgbImage& test, const RgbImage& reference);

// A heat map of the per-pixel error sqrt(mean over channels of (t - r)^2), scaled so that
// `scale` maps to the top of a blue-cyan-green-yellow-red ramp (larger errors saturate). scale 0
// picks 4 x the image RMSE: glint images have a few huge errors that a max-scaled map would turn
// into a blue field with one red dot.
// Returns width * height * 3 values in [0, 1]. The images must have the same size.
std::vector<float> errorHeatMap(const RgbImage& test, const RgbImage& reference, double scale = 0.0);

// A display version of a linear HDR image: multiplied by `exposure`, clamped to [0, 1], encoded with
// the sRGB transfer function. Returns width * height * 3 values in [0, 1].
std::vector<float> tonemapSrgb(const RgbImage& image, double exposure = 1.0);

}  // namespace glintbake::bake::render
