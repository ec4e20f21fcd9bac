// SPDX-License-Identifier: Apache-2.0
// Loading the flakes section of an NDF asset and answering footprints across the hand-overs from
// the flakes to the clustered lobes and to the asset's pyramid (internal to the runtime;
// formats/SPEC.md 10.5). With f = flakes_up_to, a = kLobesBand f, b = lobes_up_to, p = pyramid_from:
//  - sigma <= f: the flakes alone (exact);
//  - with lobes: the flakes and the lobes blended over (f, a), the lobes alone over [a, b], the
//    lobes and the pyramid blended over (b, p);
//  - without lobes: the flakes and the pyramid blended over (f, p);
//  - sigma >= p: the pyramid alone.
// A blend is (1 - t) lower + t upper, t linear in log sigma across the band. eval, average, image
// and mass blend linearly; sample picks a path in proportion to its weighted mass, so pdf = blended
// eval / blended mass exactly as for the other paths. Inside a band the flakes' share is their
// NDF with the footprint weights truncated at kBandFlakeWindow standard deviations and scaled by
// the inverse of that disk's share of a Gaussian (BandFlakes), a few 1e-4 of the mass away from
// the exact path's 6-sigma window at (2/3)^2 of its area.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/kinds/flakes.h>
#include <glintbake/runtime/flake_ndf.h>
#include <glintbake/runtime/lobe_ndf.h>
#include <glintbake/runtime/ndf_source.h>

#include <memory>

namespace glintbake::runtime {

// The evaluators of a flakes section.
struct FlakePaths {
  std::unique_ptr<FlakeNdf> flakes;
  // Null when the record has no clustered path; its finest level uses `flakes` (declared after
  // them, so destroyed first).
  std::unique_ptr<LobeNdf> lobes;
  format::FlakesRecord record;
};

// Reads and checks the flakes section (index `section` of the reader) and builds its evaluators
// at image resolution `resolution`. kInvalidAsset for a record the check refuses or non-finite
// normals, kOutOfMemory. Safe on untrusted input.
RuntimeStatus loadFlakes(const format::Reader& reader, int section, int resolution, FlakePaths* paths);

// The flakes' window inside the hand-over bands, in standard deviations of the footprint weight.
constexpr double kBandFlakeWindow = 4.0;

// The flakes' share of a band: FlakeNdf with its footprint weights truncated at kBandFlakeWindow
// standard deviations (a disk) and scaled by 1 / (1 - e^-8), so that a footprint inside the map
// still integrates to 1. Every query is FlakeNdf's in that window (sample: a flake by its weight,
// then its Gaussian, pdf = eval / mass).
class BandFlakes final : public AccumulatingNdfSource {
 public:
  explicit BandFlakes(const FlakeNdf* flakes) : flakes_(flakes) {}
  format::AssetKind kind() const override { return format::AssetKind::kUnknown; }
  int resolution() const override { return flakes_->resolution(); }
  FootprintRange footprintRange() const override { return flakes_->footprintRange(); }
  MapSize mapSize() const override { return flakes_->mapSize(); }
  MapWrap wrap() const override { return flakes_->wrap(); }
  RuntimeStatus eval(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus average(const Footprint& footprint, const SRect& rect, double* value) const override;
  RuntimeStatus sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const override;
  RuntimeStatus pdf(const Footprint& footprint, const SPoint& s, double* value) const override;
  RuntimeStatus mass(const Footprint& footprint, double* value) const override;
  RuntimeStatus addImage(const Footprint& footprint, double weight, float* out, size_t out_count) const override;
  // sample() without its density (out->pdf = 0), for a blend that evaluates its own. known_mass,
  // when not null, is mass() of the footprint (the same bits), which saves weighing it again.
  RuntimeStatus draw(const Footprint& footprint, double u1, double u2, NdfSample* out,
                     const double* known_mass = nullptr) const;
  // The scale of the truncated sums.
  static double norm();

 private:
  const FlakeNdf* flakes_;
};

// An NDF source that answers small footprints from the flakes, mid-size ones from the clustered
// lobes (when present) and the others from a pyramid.
class HandoverNdf final : public NdfSource {
 public:
  HandoverNdf(FlakePaths paths, std::unique_ptr<NdfSource> pyramid);

  format::AssetKind kind() const override { return pyramid_->kind(); }
  int resolution() const override { return pyramid_->resolution(); }
  // The pyramid's range with the exact, clustered and hand-over bounds of the paths.
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
  // The two paths of a footprint and the weight t of the upper one (t = 0: the lower alone, no
  // upper; t = 1: the upper alone).
  struct Mix {
    const AccumulatingNdfSource* lower;
    const NdfSource* upper;
    double t;
  };
  Mix mixFor(double sigma) const;
  // The path that answers alone (t = 0 or 1), or null inside a band.
  static const NdfSource* onlyPath(const Mix& mix);
  template <typename Query>
  RuntimeStatus blend(const Footprint& footprint, double* value, Query&& query) const;

  FlakePaths paths_;
  BandFlakes band_flakes_;
  std::unique_ptr<NdfSource> pyramid_;
  double flakes_up_to_, lobes_from_, lobes_up_to_, pyramid_from_;
};

}  // namespace glintbake::runtime
