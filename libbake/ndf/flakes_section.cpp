// Writing the flakes section of NDF assets (see flakes_section.h).
#include <glintbake/bake/ndf/flakes_section.h>

#include <glintbake/format/kinds/flakes.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace glintbake::bake::ndf {

FlakesHandover defaultHandover(double sigma0) {
  FlakesHandover h;
  h.flakes_up_to = std::max(4.0, sigma0);
  h.pyramid_from = h.flakes_up_to * std::sqrt(2.0);
  return h;
}

BakeStatus writeFlakesSection(format::Writer& writer, const NormalMap& map, int rate, double sigma_r,
                              const FlakesHandover& handover, uint64_t* bytes) {
  format::FlakesRecord rec;
  rec.map_width = uint32_t(std::max(map.width, 0));
  rec.map_height = uint32_t(std::max(map.height, 0));
  rec.wrap = map.wrap == Wrap::kRepeat ? 0u : 1u;
  rec.rate = uint32_t(std::max(rate, 0));
  rec.sigma_r = sigma_r;
  rec.flakes_up_to = handover.flakes_up_to;
  rec.pyramid_from = handover.pyramid_from;
  const uint64_t size = format::flakesSectionSize(rec);
  if (const char* why = format::checkFlakesRecord(rec, size)) return makeError(ErrorCode::kBadArgument, why);
  std::vector<uint8_t> section;
  try {
    section.resize(size_t(size));
  } catch (const std::bad_alloc&) {
    return makeError(ErrorCode::kRuntime, "out of memory for the flakes section");
  }
  std::memcpy(section.data(), &rec, sizeof(rec));
  float* normals = reinterpret_cast<float*>(section.data() + sizeof(rec));
  const size_t texels = size_t(map.width) * size_t(map.height);
  for (size_t t = 0; t < texels; ++t) {
    normals[t * 2 + 0] = map.normals[t * 3 + 0];
    normals[t * 2 + 1] = map.normals[t * 3 + 1];
  }
  if (format::ContainerStatus s = writer.addSection(format::kSectionFlakes, 0, section.data(), section.size());
      s != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, std::string("cannot write the flakes section: ") + format::statusString(s));
  if (bytes) *bytes = size;
  return okStatus();
}

}  // namespace glintbake::bake::ndf
