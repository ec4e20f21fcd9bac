// The flakes section of NDF assets (formats/SPEC.md 10.5): the normal map a pyramid is baked from,
// at float32 precision, so that the runtime answers small footprints exactly from its flakes
// (Yan et al. 2016) and hands over to the pyramid above them.
#pragma once

#include <glintbake/bake/io/normal_map.h>
#include <glintbake/bake/result.h>
#include <glintbake/format/container.h>

#include <cstdint>

namespace glintbake::bake::ndf {

// Footprints (std, texels) the flakes answer alone, and from which the pyramid answers alone; the
// two are blended linearly in log(sigma) in between.
struct FlakesHandover {
  double flakes_up_to = 0.0;
  double pyramid_from = 0.0;
};

// The default hand-over for a pyramid whose finest level has footprint std sigma0 (texels): the
// flakes answer every footprint up to max(4, sigma0), where the finest level is exact, and the
// pyramid takes over across a band of half an octave (to sqrt(2) times that).
FlakesHandover defaultHandover(double sigma0);

// Appends the flakes section (key 0) to a container: the map's (n_x, n_y) as float32, its wrap
// mode, rate (1..16) and sigma_r, and the hand-over. The record is checked by
// format::checkFlakesRecord before it is written. *bytes (may be null) receives the raw section size.
// Errors: kBadArgument (a record the check refuses: map too large, rate, sigma_r or hand-over out of
// range), kIo (the writer failed).
BakeStatus writeFlakesSection(format::Writer& writer, const NormalMap& map, int rate, double sigma_r,
                              const FlakesHandover& handover, uint64_t* bytes);

}  // namespace glintbake::bake::ndf
