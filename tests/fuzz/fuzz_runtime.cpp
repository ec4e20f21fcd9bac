// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: every runtime NDF asset open path (ndf-pyramid, tensor-ndf, with or without
// flakes) on arbitrary, re-sealed container bytes, then every query on the opened asset at
// footprints inside, at the edge of and far outside its map. Any crash, sanitizer report, leak or
// non-finite answer with an ok status is a bug; bounded memory is enforced by libFuzzer's -rss_limit_mb.
#include <glintbake/runtime/ndf_source.h>

#include "reseal.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace {

using namespace glintbake::runtime;

void query(const NdfSource& ndf) {
  const MapSize size = ndf.mapSize();
  const FootprintRange range = ndf.footprintRange();
  const double sigmas[] = {0.3, range.pyramid_min_sigma, range.exact_max_sigma, range.pyramid_max_sigma, 1e6};
  const double xs[] = {0.0, 0.5 * size.width, double(size.width), -1e9};
  const int res = ndf.resolution();
  std::vector<float> image(res > 0 && res <= 1024 ? size_t(res) * size_t(res) : 0);
  for (double sigma : sigmas) {
    // Images only up to the exact flakes' range and at the pyramid's finest level: wider ones
    // integrate every lobe of a window that can hold thousands of periods of a tiny map, seconds
    // under the fuzzer's instrumentation, and run the same code as the narrower ones.
    const bool with_image =
        !image.empty() && (sigma <= range.exact_max_sigma || sigma <= range.pyramid_min_sigma || sigma <= 0.3);
    for (double x : xs) {
      Footprint f;
      f.x = x;
      f.y = 0.25 * size.height;
      f.sigma = sigma;
      double v = 0.0;
      SPoint s;
      s.x = 0.1;
      s.y = -0.2;
      if (ndf.eval(f, s, &v) == RuntimeStatus::kOk && !std::isfinite(v)) __builtin_trap();
      SRect r;
      (void)ndf.average(f, r, &v);
      (void)ndf.mass(f, &v);
      NdfSample smp;
      if (ndf.sample(f, 0.3, 0.7, &smp) == RuntimeStatus::kOk) (void)ndf.pdf(f, smp.s, &v);
      if (with_image) (void)ndf.image(f, image.data(), image.size());
    }
  }
}

void check(const uint8_t* data, size_t size) {
  std::unique_ptr<NdfSource> ndf;
  if (openNdfAssetMemory(data, size, &ndf) == RuntimeStatus::kOk && ndf) query(*ndf);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<uint8_t> resealed = glintbake::fuzz::reseal(data, size);
  check(resealed.data(), resealed.size());
  return 0;
}
