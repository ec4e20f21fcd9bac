// SPDX-License-Identifier: Apache-2.0
// The shared surface of pyramid-shaped NDF assets (ndf-pyramid, tensor-ndf, and kinds built on
// the same footprint pyramid, formats/SPEC.md 10.1): opening a container once, the level records,
// the footprint range and map geometry, and the argument checks of every query. A kind implements
// only what differs: loading its sections and answering checked queries.
//
// Extending a kind: a subclass (or a wrapper holding a PyramidNdf) can answer some footprints
// from another source, e.g. footprints below footprintRange().pyramid_min_sigma exactly from
// stored flakes, by overriding the checked queries (eval, average, ...Checked) and forwarding the
// others to the base kind, and by overriding loadKind() to read its extra sections from the same
// reader after the base kind's.
#pragma once

#include <glintbake/format/container.h>
#include <glintbake/format/kinds/ndf_pyramid.h>
#include <glintbake/runtime/ndf_source.h>

#include <cstddef>

namespace glintbake::format {
class NdfPyramidBlend;
}

namespace glintbake::runtime {

// The level descriptor is the container's record (formats/SPEC.md 10.1, kinds/ndf_pyramid.h).
using format::kMaxNdfLevels;
using format::NdfLevelRecord;

class PyramidNdf : public NdfSource {
 public:
  // Loads a container of this kind. kIoError, kInvalidAsset, kWrongKind, kUnsupportedVersion,
  // kOutOfMemory. Safe on untrusted input.
  RuntimeStatus open(const char* path);
  // Same, from a caller buffer (only needed during the call).
  RuntimeStatus openMemory(const void* data, size_t size);
  // Same, from a reader opened by the caller (one open for a caller that reads other sections of
  // the file too); kWrongKind when the reader's kind is not kind(). On failure the asset is empty.
  RuntimeStatus load(const format::Reader& reader);
  bool isOpen() const { return loaded(); }

  int levelCount() const;
  // Descriptor of level l in [0, levelCount()), or null.
  const NdfLevelRecord* level(int l) const;

  // NdfSource, from the level records.
  int resolution() const override;
  FootprintRange footprintRange() const override;
  MapSize mapSize() const override;
  MapWrap wrap() const override;

  // NdfSource queries: the shared argument checks (ndf_source.h: kInvalidArgument when the asset
  // is not open, an output pointer is null, the footprint or s is not finite, sigma < 0, a
  // rectangle is empty, a uniform is outside [0, 1), or out_count < R * R), then the kind's
  // checked query.
  RuntimeStatus eval(const Footprint& footprint, const SPoint& s, double* value) const final;
  RuntimeStatus average(const Footprint& footprint, const SRect& rect, double* value) const final;
  RuntimeStatus sample(const Footprint& footprint, double u1, double u2, NdfSample* sample) const final;
  RuntimeStatus pdf(const Footprint& footprint, const SPoint& s, double* value) const final;
  RuntimeStatus mass(const Footprint& footprint, double* value) const final;
  RuntimeStatus image(const Footprint& footprint, float* out, size_t out_count) const final;
  // The blend uses the levels from the first whose sigma is at least `sigma` (NdfSource); the
  // footprint range reports that level as pyramid_min_sigma. Not thread-safe: call it before the
  // asset is shared. A later open() uses every level again.
  void answerFromSigma(double sigma) final;
  // On a clamped map the blend gives centres beyond the edges the edge centres' images scaled by
  // the mass their footprints keep over the map (formats/SPEC.md 10.1). holdEdges() makes it hold
  // the edge centres instead, as the tile assets of wang-tiles containers are read (10.7). Not
  // thread-safe, as answerFromSigma; a later open() falls off again.
  void holdEdges();

 protected:
  PyramidNdf() = default;

  // Loads the kind's sections from a reader of the right kind into fresh state; on failure the
  // caller resets. Called by open(), openMemory() and load().
  virtual RuntimeStatus loadKind(const format::Reader& reader) = 0;
  // Drops everything loaded (after this loaded() is false).
  virtual void reset() = 0;
  virtual bool loaded() const = 0;
  // The loaded level records, contiguous (count of them), or null when not loaded.
  virtual const NdfLevelRecord* levelRecords(int* count) const = 0;
  // The footprint blend of the loaded levels, or null when not loaded.
  virtual format::NdfPyramidBlend* blender() = 0;
  virtual const format::NdfPyramidBlend* blender() const = 0;

  // Queries on checked arguments (the asset is loaded, pointers are valid, the footprint is valid).
  virtual RuntimeStatus evalChecked(const Footprint& footprint, const SPoint& s, double* value) const = 0;
  virtual RuntimeStatus averageChecked(const Footprint& footprint, const SRect& rect, double* value) const = 0;
  virtual RuntimeStatus sampleChecked(const Footprint& footprint, double u1, double u2, NdfSample* sample) const = 0;
  virtual RuntimeStatus pdfChecked(const Footprint& footprint, const SPoint& s, double* value) const = 0;
  virtual RuntimeStatus massChecked(const Footprint& footprint, double* value) const = 0;
  virtual RuntimeStatus imageChecked(const Footprint& footprint, float* out) const = 0;
};

}  // namespace glintbake::runtime
