// SPDX-License-Identifier: Apache-2.0
// Image loading, error metrics, heat maps and display previews.
#include <glintbake/bake/render/image_compare.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace glintbake::bake::render {

Result<RgbImage> loadRgbImage(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    OIIO::geterror();
    return makeError(ErrorCode::kIo, "cannot open image " + path);
  }
  const OIIO::ImageSpec& spec = in->spec();
  const int w = spec.width, h = spec.height, c = spec.nchannels;
  if (w < 1 || h < 1 || c < 1) return makeError(ErrorCode::kInvalidInput, "image " + path + " has no pixels");
  if (double(w) * h > double(1 << 28)) return makeError(ErrorCode::kInvalidInput, "image " + path + " is too large");
  std::vector<float> all(size_t(w) * h * c);
  if (!in->read_image(0, 0, 0, c, OIIO::TypeDesc::FLOAT, all.data())) {
    in->geterror();
    return makeError(ErrorCode::kIo, "cannot read image " + path);
  }
  RgbImage img;
  img.width = w;
  img.height = h;
  img.rgb.resize(size_t(w) * h * 3);
  for (size_t p = 0; p < size_t(w) * h; ++p) {
    for (int k = 0; k < 3; ++k) {
      const float v = all[p * c + size_t(c >= 3 ? k : 0)];
      if (!std::isfinite(v)) return makeError(ErrorCode::kInvalidInput, "image " + path + " holds non-finite values");
      img.rgb[p * 3 + k] = v;
    }
  }
  return img;
}

Result<CompareMetrics> compareImages(const RgbImage& test, const RgbImage& reference) {
  if (test.width != reference.width || test.height != reference.height) {
    return makeError(ErrorCode::kBadArgument,
                     "the images differ in size (" + std::to_string(test.width) + "x" + std::to_string(test.height) +
                         " vs " + std::to_string(reference.width) + "x" + std::to_string(reference.height) + ")");
  }
  CompareMetrics m;
  double se = 0.0, ref2 = 0.0, peak = 0.0;
  for (size_t i = 0; i < reference.rgb.size(); ++i) {
    const double t = test.rgb[i], r = reference.rgb[i];
    const double d = t - r;
    se += d * d;
    ref2 += r * r;
    peak = std::max(peak, r);
    m.max_abs_error = std::max(m.max_abs_error, std::fabs(d));
    if (t != r) ++m.differing_values;
  }
  const double n = double(reference.rgb.size());
  m.rmse = std::sqrt(se / n);
  m.relative_mse = ref2 > 0.0 ? se / ref2 : (se > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  m.peak = peak > 0.0 ? peak : 1.0;
  m.psnr = m.rmse > 0.0 ? 20.0 * std::log10(m.peak / m.rmse) : std::numeric_limits<double>::infinity();
  return m;
}

std::vector<float> errorHeatMap(const RgbImage& test, const RgbImage& reference, double scale) {
  const size_t n = size_t(reference.width) * reference.height;
  std::vector<double> err(n, 0.0);
  double sum_sq = 0.0;
  for (size_t p = 0; p < n; ++p) {
    double s = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = double(test.rgb[p * 3 + k]) - reference.rgb[p * 3 + k];
      s += d * d;
    }
    err[p] = std::sqrt(s / 3.0);
    sum_sq += s / 3.0;
  }
  const double top = scale > 0.0 ? scale : 4.0 * std::sqrt(sum_sq / double(std::max<size_t>(1, n)));
  // Blue -> cyan -> green -> yellow -> red.
  static const float kRamp[5][3] = {{0, 0, 0.5f}, {0, 0.8f, 1}, {0, 0.8f, 0}, {1, 1, 0}, {1, 0, 0}};
  std::vector<float> out(n * 3, 0.0f);
  for (size_t p = 0; p < n; ++p) {
    const double x = top > 0.0 ? std::min(1.0, err[p] / top) * 4.0 : 0.0;
    const int i = std::min(3, int(x));
    const float f = float(x - i);
    for (int k = 0; k < 3; ++k) out[p * 3 + k] = kRamp[i][k] * (1.0f - f) + kRamp[i + 1][k] * f;
  }
  return out;
}

std::vector<float> tonemapSrgb(const RgbImage& image, double exposure) {
  std::vector<float> out(image.rgb.size());
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    const double v = std::min(1.0, std::max(0.0, image.rgb[i] * exposure));
    out[i] = float(v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055);
  }
  return out;
}

}  // namespace glintbake::bake::render
