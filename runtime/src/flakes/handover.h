// Loading the flakes section of an NDF asset and answering footprints across the hand-over from
// the flakes to the asset's pyramid (internal to the runtime; formats/SPEC.md 10.5).
//  - sigma <= flakes_up_to: the flakes alone (exact);
//  - sigma >= pyramid_from: the pyramid alone;
//  - in between: (1 - t) flakes + t pyramid, t = ln(sigma / flakes_up_to) / ln(pyramid_from /
//    flakes_up_to). eval, average, image and mass blend linearly; sample picks a path in proportion
//    to its weighted mass, so pdf = blended eval / blended mass exactly as for the other paths.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/kinds/flakes.h>
#include <glintbake/runtime/flake_ndf.h>
#include <glintbake/runtime/ndf_source.h>

#include <memory>

namespace glintbake::runtime {

// Reads and checks the flakes section (index `section` of the reader) and builds its evaluator at
// image resolution `resolution`. kInvalidAsset for a record the check refuses or non-finite
// normals, kOutOfMemory. Safe on untrusted input.
RuntimeStatus loadFlakes(const format::Reader& reader, int section, int resolution, std::unique_ptr<FlakeNdf>* flakes,
                         format::FlakesRecord* record);

// An NDF source that answers small footprints from the flakes and the others from a pyramid.
class HandoverNdf final : public NdfSource {
 public:
  HandoverNdf(std::unique_ptr<FlakeNdf> flakes, std::unique_ptr<NdfSource> pyramid, double flakes_up_to,
              double pyramid_from);

  format::AssetKind kind() const override { return pyramid_->kind(); }
  int resolution() const override { return pyramid_->resolution(); }
  // The pyramid's range, with the flakes exact up to flakes_up_to and the band up to pyramid_from.
  FootprintRange footprintRange() const override;
  MapSize mapSize() const override { return pyramid_->mapSize(); }
  MapWrap wrap() const override { return pyramid_->wrap(); }
  RuntimeStatus eval(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus average(const Footprint& footprint, const SRect& rect, double* value) const override;
  RuntimeStatus sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  RuntimeStatus pdf(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus mass(const Footprint& footprint, double* value) const override;
  RuntimeStatus image(const Footprint& footprint, float* out, size_t out_count) const override;

 private:
  // Weight of the pyramid for a footprint: 0 on the flakes' side, 1 on the pyramid's.
  double pyramidWeight(double sigma) const;
  template <typename Query>
  RuntimeStatus blend(const Footprint& footprint, double* value, Query&& query) const;

  std::unique_ptr<FlakeNdf> flakes_;
  std::unique_ptr<NdfSource> pyramid_;
  double flakes_up_to_, pyramid_from_, inv_log_band_;
};

}  // namespace glintbake::runtime
