// SPDX-License-Identifier: Apache-2.0
// Writing the flakes section of NDF assets (see flakes_section.h).
#include <glintbake/bake/ndf/flakes_section.h>

#include <glintbake/bake/ndf/flakes.h>
#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/ndf/splat.h>

#include <glintbake/format/kinds/flakes.h>
#include <glintbake/format/kinds/ndf_pyramid_blend.h>
#include <glintbake/runtime/flake_ndf.h>
#include <glintbake/runtime/lobe_ndf.h>
#include <glintbake/runtime/texel_source.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <new>
#include <string>
#include <vector>

namespace glintbake::bake::ndf {

namespace {
constexpr double kFlakesUpTo = 4.0;  // texels: the flakes answer at least this far
constexpr double kHalfOctave = 1.4142135623730951;
constexpr double kLobesUnbounded = 1e6;  // the record's largest footprint bound
}  // namespace

FlakesHandover capAtFlatFootprint(const FlakesHandover& handover, int map_width, int map_height, bool repeat) {
  FlakesHandover h = handover;
  if (!repeat || h.lobes_per_tile <= 0 || !(h.lobes_up_to < kLobesUnbounded)) return h;
  const double flat = kFlatAxisSigma * double(std::max(map_width, map_height));
  if (!(h.pyramid_from > flat)) return h;
  // Both stay within the record's bounds: lobes_from <= lobes_up_to <= pyramid_from.
  const double lobes_from = h.flakes_up_to * format::kLobesBand;
  h.pyramid_from = std::max(flat, lobes_from);
  h.lobes_up_to = std::max(lobes_from, std::min(h.lobes_up_to, h.pyramid_from / kHalfOctave));
  return h;
}

FlakesHandover fitHandoverToMap(const FlakesHandover& handover, int map_width, int map_height, bool repeat, int rate) {
  if (repeat) return capAtFlatFootprint(handover, map_width, map_height, true);
  if (map_width < 1 || map_height < 1 || rate < 1) return handover;
  const uint64_t flakes = uint64_t(map_width) * uint64_t(map_height) * uint64_t(rate) * uint64_t(rate);
  const double flat = kClampedFlatSigma * double(std::max(map_width, map_height));
  // The flakes path's window at F: 2 kFlakeWindowSigmas sqrt(F^2 + sigma_h^2) flakes across
  // (sigma_h < 1 texel), plus the two rounded ends.
  const double window = 2.0 * runtime::kFlakeWindowSigmas * std::sqrt(flat * flat + 1.0) * double(rate) + 2.0;
  if (flakes > kSmallClampedMapFlakes || !(window < double(runtime::kMaxFlakeWindow)) ||
      !(handover.flakes_up_to < flat))
    return handover;
  FlakesHandover h;
  h.flakes_up_to = flat;
  h.lobes_per_tile = 0;
  h.lobes_up_to = 0.0;
  h.pyramid_from = flat * kHalfOctave;
  return h;
}

FlakesHandover defaultHandover(double sigma0, int lobes_per_tile) {
  FlakesHandover h;
  if (lobes_per_tile <= 0) {
    h.flakes_up_to = std::max(kFlakesUpTo, sigma0);
    h.pyramid_from = h.flakes_up_to * kHalfOctave;
    return h;
  }
  h.flakes_up_to = kFlakesUpTo;
  h.lobes_per_tile = lobes_per_tile;
  h.lobes_up_to = std::max(kFlakesUpTo * format::kLobesBand, sigma0 * kHalfOctave);
  h.pyramid_from = std::max(2.0 * sigma0, h.lobes_up_to);
  return h;
}

FlakesHandover compressedHandover(const double* level_sigmas, const double* level_errors, int levels,
                                  double max_level_error, int lobes_per_tile, const bool* level_exact,
                                  const std::function<bool(int level)>& blend_loses) {
  if (lobes_per_tile <= 0 || levels <= 0) return defaultHandover(levels > 0 ? level_sigmas[0] : 0.0, lobes_per_tile);
  int first = levels;  // the first level from which every level is faithful
  while (first > 0 && level_errors[first - 1] <= max_level_error) --first;
  FlakesHandover h;
  h.flakes_up_to = kFlakesUpTo;
  h.lobes_per_tile = lobes_per_tile;
  const bool exact = first < levels && level_exact && level_exact[first];
  if (exact && !(blend_loses && blend_loses(first))) {
    // The pyramid's blend above an exact level is faithful from its own sigma up, or no farther
    // from the reference than the lobes (probeExactLevelHandover), so the lobes hand over at that
    // sigma.
    h.lobes_up_to = std::max(kFlakesUpTo * format::kLobesBand, level_sigmas[first]);
    h.pyramid_from = std::max(kHalfOctave * level_sigmas[first], h.lobes_up_to);
    return h;
  }
  if (exact) {
    // Where it is not, the lobes answer up to sqrt(2) times that level and the pyramid from twice
    // it, as above a compressed level, unless the blend above the next level loses too: then the
    // lobes go on above that level, and so on.
    int last = first;
    while (last + 1 < levels && blend_loses(last + 1)) ++last;
    h.lobes_up_to = std::max(kFlakesUpTo * format::kLobesBand, level_sigmas[last] * kHalfOctave);
    h.pyramid_from = std::max(2.0 * level_sigmas[last], h.lobes_up_to);
    return h;
  }
  if (first == 0) return defaultHandover(level_sigmas[0], lobes_per_tile);
  if (first == levels) {
    h.lobes_up_to = h.pyramid_from = kLobesUnbounded;
  } else {
    // As for an uncompressed pyramid: between the centres of its first level the pyramid blends
    // images, so the lobes answer up to sqrt(2) x its sigma and the pyramid alone from 2 x.
    h.lobes_up_to = std::max(kFlakesUpTo * format::kLobesBand, level_sigmas[first] * kHalfOctave);
    h.pyramid_from = std::max(2.0 * level_sigmas[first], h.lobes_up_to);
  }
  return h;
}

namespace {
// The record's hand-over, fitted to its map as fitHandoverToMap does.
void fitRecord(format::FlakesRecord* rec) {
  FlakesHandover h;
  h.flakes_up_to = rec->flakes_up_to;
  h.lobes_per_tile = int(rec->lobes_per_tile);
  h.lobes_up_to = rec->lobes_up_to;
  h.pyramid_from = rec->pyramid_from;
  h = fitHandoverToMap(h, int(rec->map_width), int(rec->map_height), rec->wrap == 0, int(rec->rate));
  rec->flakes_up_to = h.flakes_up_to;
  rec->lobes_per_tile = uint32_t(std::max(h.lobes_per_tile, 0));
  rec->lobes_up_to = h.lobes_per_tile > 0 ? h.lobes_up_to : 0.0;
  rec->pyramid_from = h.pyramid_from;
}
}  // namespace

namespace {
// The L1 distance between two NDFs f and g of one footprint, estimated from points drawn from the
// mixture m = sum_k n_k h_k / N of the densities the points were drawn from (points[k] from h_k):
// integral |f - g| = E_m[|f - g| / m]. fv, gv and mv hold f, g and m at every point.
double mixtureL1(const std::vector<double>& fv, const std::vector<double>& gv, const std::vector<double>& mv) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t k = 0; k < fv.size(); ++k) {
    if (mv[k] > 0.0) sum += std::fabs(fv[k] - gv[k]) / mv[k];
    ++n;
  }
  return n ? sum / double(n) : 0.0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

// kSamples points of source's NDF at fp, from a two-dimensional golden-ratio sequence of
// uniforms; points outside the s-square (density 0) are left out.
template <typename Source>
std::vector<runtime::SPoint> drawPoints(const Source& source, const runtime::Footprint& fp, int count) {
  std::vector<runtime::SPoint> out;
  for (int k = 0; k < count; ++k) {
    const double u1 = (k + 0.5) / count, u2 = std::fmod(0.5 + 0.6180339887498949 * (k + 1), 1.0);
    runtime::NdfSample smp;
    if (source.sample(fp, u1, u2, &smp) != runtime::RuntimeStatus::kOk) continue;
    if (std::fabs(smp.s.x) <= 1.0 && std::fabs(smp.s.y) <= 1.0) out.push_back(smp.s);
  }
  return out;
}

template <typename Source>
double densityAt(const Source& source, const runtime::Footprint& fp, const runtime::SPoint& s) {
  double v = 0.0;
  return source.eval(fp, s, &v) == runtime::RuntimeStatus::kOk ? v : 0.0;
}

// Footprint i (0-based) of a probe over a w x h map: a two-dimensional golden-ratio sequence.
runtime::Footprint probePosition(int i, int w, int h, double sigma) {
  const double fx = std::fmod(0.5 + 0.7548776662466927 * (i + 1), 1.0);
  const double fy = std::fmod(0.5 + 0.5698402909980532 * (i + 1), 1.0);
  return {fx * w, fy * h, sigma};
}

// The widest footprint (std, texels) whose exact flakes fit the runtime's window at this rate.
double flakeWindowMaxSigma(int rate) {
  return (double(runtime::kMaxFlakeWindow) - 4.0) / (2.0 * runtime::kFlakeWindowSigmas * rate);
}

// What the probe builds its flakes and lobes from: the whole map when it holds at most max_flakes
// flakes, else a window at its centre of at most sqrt(max_flakes) flakes per side, clamped (no
// texel beyond it stands in for the map's). The window's sides and origin are whole multiples of
// kLobeProbeCropAlign texels, so that its tiles (the probe's coarsest are 128 flakes) are the map's.
class ProbeWindow final : public runtime::TexelSource {
 public:
  ProbeWindow(const runtime::TexelSource& map, int rate, uint64_t max_flakes) : map_(map) {
    w_ = map.width();
    h_ = map.height();
    const uint64_t flakes = uint64_t(w_) * uint64_t(h_) * uint64_t(rate) * uint64_t(rate);
    if (flakes <= max_flakes) return;
    const int align = kLobeProbeCropAlign;
    const int side = std::max(align, int(std::sqrt(double(max_flakes)) / rate) / align * align);
    auto fit = [&](int n, int* origin, int* kept) {
      *kept = std::min(n, side);
      *origin = (n - *kept) / 2 / align * align;
    };
    fit(map.width(), &x0_, &w_);
    fit(map.height(), &y0_, &h_);
    cropped_ = w_ < map.width() || h_ < map.height();  // (a window of the whole map keeps its wrap)
  }
  int width() const override { return w_; }
  int height() const override { return h_; }
  bool repeats() const override { return cropped_ ? false : map_.repeats(); }
  void normal(int x, int y, float out[2]) const override { map_.normal(x0_ + x, y0_ + y, out); }

 private:
  const runtime::TexelSource& map_;
  int x0_ = 0, y0_ = 0, w_ = 0, h_ = 0;
  bool cropped_ = false;
};
}  // namespace

uint32_t chooseLobeTileRatio(const runtime::TexelSource& texels, int rate, double sigma_r, int lobes_per_tile,
                             double pyramid_from, uint64_t max_probe_flakes) {
  constexpr size_t kCandidates = std::size(kLobeTileRatioCandidates);
  const int width = texels.width(), height = texels.height();
  if (lobes_per_tile <= 0 || width < 1 || height < 1 || rate < 1) return format::kDefaultFlakesTileRatioMilli;
  const bool repeat = texels.repeats();
  // Footprints the lobes can answer on this map: below the pyramid's, below the flat footprint of
  // a repeating map (the pyramid answers from there, capAtFlatFootprint), within the exact flakes'
  // window (and the lobes', below). Nothing is built when no probe footprint is left.
  const double side = double(std::max(width, height));
  const double flat_max = repeat ? kFlatAxisSigma * side / kHalfOctave : kClampedFlatSigma * side;
  const double window_max = flakeWindowMaxSigma(rate);
  auto probed = [&](double sigma) { return sigma < pyramid_from && sigma <= flat_max && sigma <= window_max; };
  if (std::none_of(std::begin(kLobeProbeSigmas), std::end(kLobeProbeSigmas), probed))
    return format::kDefaultFlakesTileRatioMilli;
  // The targets are on NDF images of R x R bins, which average out detail finer than a bin: the
  // densities compared here are those of every lobe widened by a bin's variance (a box of side
  // 2 / R has variance (2 / R)^2 / 12), the images' blur as a Gaussian.
  const double bin = 2.0 / kLobeProbeResolution;
  const double probe_sigma_r = std::min(1.0, std::sqrt(sigma_r * sigma_r + bin * bin / 12.0));
  const ProbeWindow probe(texels, rate, max_probe_flakes);
  runtime::FlakeNdf exact;
  runtime::LobeNdf lobes;
  if (exact.build(probe, rate, probe_sigma_r, kLobeProbeResolution) != runtime::RuntimeStatus::kOk ||
      lobes.build(probe, rate, probe_sigma_r, lobes_per_tile, kLobeProbeResolution) != runtime::RuntimeStatus::kOk)
    return format::kDefaultFlakesTileRatioMilli;  // the section's own checks report what is wrong
  const double lobes_max = lobes.footprintRange().clustered_max_sigma;
  bool passes[kCandidates];
  std::fill(std::begin(passes), std::end(passes), true);
  constexpr int kPositions = kLobeProbePositions;
  for (double sigma : kLobeProbeSigmas) {
    if (!(probed(sigma) && sigma <= lobes_max)) continue;
    std::vector<runtime::Footprint> fps;
    std::vector<double> masses;
    for (int i = 0; i < kPositions; ++i) {
      fps.push_back(probePosition(i, probe.width(), probe.height(), sigma));
      double m = 0.0;
      exact.mass(fps.back(), &m);
      masses.push_back(m);
    }
    // Points of every position's exact NDF; at each, every position's exact density.
    std::vector<std::vector<runtime::SPoint>> drawn(kPositions);
    std::vector<runtime::SPoint> all;
    std::vector<size_t> first(kPositions);  // where each position's points start in `all`
    tbb::parallel_for(0, kPositions,
                      [&](int i) { drawn[size_t(i)] = drawPoints(exact, fps[size_t(i)], kLobeProbeSamples); });
    for (int i = 0; i < kPositions; ++i) {
      first[size_t(i)] = all.size();
      all.insert(all.end(), drawn[size_t(i)].begin(), drawn[size_t(i)].end());
    }
    if (all.empty()) continue;
    std::vector<std::vector<double>> p(kPositions, std::vector<double>(all.size()));
    tbb::parallel_for(size_t(0), size_t(kPositions) * all.size(), [&](size_t e) {
      const size_t j = e / all.size(), k = e % all.size();
      p[j][k] = masses[j] > 0.0 ? densityAt(exact, fps[j], all[k]) / masses[j] : 0.0;
    });
    std::vector<double> mean(all.size(), 0.0);
    for (int j = 0; j < kPositions; ++j)
      for (size_t k = 0; k < all.size(); ++k) mean[k] += p[size_t(j)][k] / kPositions;
    // The baseline of each position: its NDF against the mean of them all, from every point (the
    // mean's own).
    std::vector<double> spread(kPositions), errors(kPositions);
    for (int i = 0; i < kPositions; ++i) spread[size_t(i)] = mixtureL1(mean, p[size_t(i)], mean);
    const double baseline = median(spread);
    for (size_t c = 0; c < kCandidates; ++c) {
      if (!passes[c]) continue;
      lobes.setTileRatio(kLobeTileRatioCandidates[c] / 1000.0);
      tbb::parallel_for(0, kPositions, [&](int i) {
        const runtime::Footprint& fp = fps[size_t(i)];
        double lobes_mass = 0.0;
        lobes.mass(fp, &lobes_mass);
        // Points of the exact NDF and of the lobes' alike: their mixture's density at each.
        std::vector<runtime::SPoint> points = drawn[size_t(i)];
        const size_t from_exact = points.size();
        for (const runtime::SPoint& s : drawPoints(lobes, fp, kLobeProbeSamples)) points.push_back(s);
        std::vector<double> pv(points.size()), qv(points.size()), mv(points.size());
        for (size_t k = 0; k < points.size(); ++k) {
          // The exact density at its own points is p's; at the lobes' points it is evaluated here.
          if (k < from_exact)
            pv[k] = p[size_t(i)][first[size_t(i)] + k];
          else
            pv[k] = masses[size_t(i)] > 0.0 ? densityAt(exact, fp, points[k]) / masses[size_t(i)] : 0.0;
          qv[k] = lobes_mass > 0.0 ? densityAt(lobes, fp, points[k]) / lobes_mass : 0.0;
          mv[k] = (double(from_exact) * pv[k] + double(points.size() - from_exact) * qv[k]) / double(points.size());
        }
        errors[size_t(i)] = mixtureL1(qv, pv, mv);
      });
      const double error = median(errors);
      passes[c] = error <= kLobeProbeMaxError && error <= kLobeProbeMaxRatio * baseline;
    }
  }
  for (size_t c = 0; c < kCandidates; ++c)
    if (passes[c]) return kLobeTileRatioCandidates[c];
  return kLobeTileRatioCandidates[kCandidates - 1];
}

namespace {
// Relative L1 distance of an image from a reference image of the same size: sum |a - ref| / sum |ref|.
template <typename A>
double imageL1(const std::vector<A>& a, const std::vector<float>& ref) {
  double norm = 0.0, d = 0.0;
  for (size_t k = 0; k < ref.size(); ++k) {
    norm += std::fabs(double(ref[k]));
    d += std::fabs(double(a[k]) - double(ref[k]));
  }
  return norm > 0.0 ? d / norm : 0.0;
}
}  // namespace

HandoverProbe probeExactLevelHandover(const runtime::TexelSource& texels, int rate, double sigma_r, int lobes_per_tile,
                                      const PyramidLevelShape* levels, int count, double sigma,
                                      uint64_t max_probe_flakes) {
  HandoverProbe out;
  if (lobes_per_tile <= 0 || count < 1 || count > format::kMaxNdfLevels || rate < 1 || texels.width() < 1 ||
      texels.height() < 1 || !(levels[0].sigma > 0.0) || !(sigma > levels[0].sigma) || !std::isfinite(sigma))
    return out;
  out.sigma = sigma;
  const ProbeWindow probe(texels, rate, max_probe_flakes);
  const bool repeat = probe.repeats();
  const double side = double(std::max(probe.width(), probe.height()));
  if (out.sigma > flakeWindowMaxSigma(rate) || (repeat && !(out.sigma < kFlatAxisSigma * side))) return out;
  // The levels' records over the probed map: the map's strides, rounded to tile the window.
  std::vector<format::NdfLevelRecord> recs(static_cast<size_t>(count));
  for (int l = 0; l < count; ++l) {
    const PyramidLevelShape& shape = levels[l];
    if (shape.grid_width < 1 || shape.grid_height < 1 || !(shape.sigma > 0.0) ||
        (l > 0 && !(shape.sigma > levels[l - 1].sigma)))
      return out;
    auto grid = [](int probed, int map, int centres) {
      if (probed == map) return centres;
      return std::max(1, int(std::lround(double(probed) * double(centres) / double(map))));
    };
    format::NdfLevelRecord& r = recs[size_t(l)];
    r.level = uint32_t(l);
    r.ndf_res = uint32_t(kLobeProbeResolution);
    r.grid_width = uint32_t(grid(probe.width(), texels.width(), shape.grid_width));
    r.grid_height = uint32_t(grid(probe.height(), texels.height(), shape.grid_height));
    r.wrap = repeat ? 0u : 1u;
    r.map_width = uint32_t(probe.width());
    r.map_height = uint32_t(probe.height());
    r.rate = uint32_t(rate);
    r.stride_x = double(probe.width()) / double(r.grid_width);
    r.stride_y = double(probe.height()) / double(r.grid_height);
    r.origin_x = 0.5 * r.stride_x;
    r.origin_y = 0.5 * r.stride_y;
    r.sigma_texels = shape.sigma;
    r.sigma_r = sigma_r;
  }
  format::NdfPyramidBlend blend;
  blend.init(recs.data(), count);
  // The images an exact level stores are splats of the map's flakes (with the level's footprint
  // partition on repeating maps), and so is the reference here, as in scripts/fidelity.py.
  NormalMap map;
  map.width = probe.width();
  map.height = probe.height();
  map.wrap = repeat ? Wrap::kRepeat : Wrap::kClamp;
  try {
    map.normals.resize(size_t(map.width) * size_t(map.height) * 3);
  } catch (const std::bad_alloc&) {
    return out;
  }
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      float n[2];
      probe.normal(x, y, n);
      float* t = map.at(x, y);
      t[0] = n[0];
      t[1] = n[1];
      t[2] = float(std::sqrt(std::max(0.0, 1.0 - double(n[0]) * n[0] - double(n[1]) * n[1])));
    }
  }
  Result<FlakeSet> flakes = buildFlakes(map, rate);
  runtime::LobeNdf lobes;
  if (!flakes.ok() ||
      lobes.build(probe, rate, sigma_r, lobes_per_tile, kLobeProbeResolution) != runtime::RuntimeStatus::kOk ||
      out.sigma > lobes.footprintRange().clustered_max_sigma)
    return out;
  const FlakeSet& set = flakes.value();
  std::vector<FootprintPartition> partitions;
  for (const format::NdfLevelRecord& r : recs)
    partitions.push_back(
        footprintPartition(set, r.sigma_texels, int(r.grid_width), r.stride_x, int(r.grid_height), r.stride_y));
  SplatParams params;
  params.ndf_res = kLobeProbeResolution;
  params.sigma_r = sigma_r;
  constexpr int kPositions = kHandoverProbePositions;
  // Centres the blend weighs less are left out of its image: a splat costs as much whatever its
  // weight, and on a level of stride 2 sigma about half the centres weigh less than this.
  constexpr double kMinCentreWeight = 2e-3;
  const size_t bins = size_t(kLobeProbeResolution) * size_t(kLobeProbeResolution);
  std::vector<double> blend_errors(kPositions), lobes_errors(kPositions);
  std::vector<std::vector<float>> refs(kPositions);
  tbb::parallel_for(0, kPositions, [&](int i) {
    const runtime::Footprint fp = probePosition(i, probe.width(), probe.height(), out.sigma);
    Splatter splatter(set, params);
    std::vector<float> ref(bins, 0.0f), lobe(bins, 0.0f), centre(bins, 0.0f);
    std::vector<double> mixed(bins, 0.0);
    splatter.image(fp.x, fp.y, fp.sigma, ref.data());
    lobes.addImage(fp, 1.0, lobe.data(), bins);
    // The pyramid's answer: the level images of the centres it weighs, in the order it emits them.
    blend.blend(fp.x, fp.y, fp.sigma, [&](int l, size_t c, double w) {
      if (w < kMinCentreWeight) return;
      const format::NdfLevelRecord& r = recs[size_t(l)];
      const size_t gi = c % r.grid_width, gj = c / r.grid_width;
      const FootprintPartition& part = partitions[size_t(l)];
      splatter.image(r.origin_x + double(gi) * r.stride_x, r.origin_y + double(gj) * r.stride_y, r.sigma_texels,
                     centre.data(), part.empty() ? nullptr : &part);
      for (size_t k = 0; k < bins; ++k) mixed[k] += w * double(centre[k]);
    });
    blend_errors[size_t(i)] = imageL1(mixed, ref);
    lobes_errors[size_t(i)] = imageL1(lobe, ref);
    refs[size_t(i)] = std::move(ref);
  });
  // The smooth baseline: each position's image against the mean of them all.
  std::vector<double> mean(bins, 0.0), spread(kPositions);
  for (const std::vector<float>& r : refs)
    for (size_t k = 0; k < bins; ++k) mean[k] += double(r[k]) / kPositions;
  for (int i = 0; i < kPositions; ++i) spread[size_t(i)] = imageL1(mean, refs[size_t(i)]);
  out.baseline = median(spread);
  out.blend_error = median(blend_errors);
  out.lobes_error = median(lobes_errors);
  out.ran = true;
  return out;
}

namespace {
// Writes the trailer of a version-3 section whose record and normals are in place: the requested
// tile ratio, or (0) the one chooseLobeTileRatio picks for its flakes and hand-over.
void writeTrailer(std::vector<uint8_t>& section, const format::FlakesRecord& rec, uint32_t requested) {
  if (rec.version < 3 || section.size() < sizeof(rec) + sizeof(format::FlakesTrailer)) return;
  format::FlakesTrailer trailer;
  if (requested != 0) {
    trailer.tile_ratio_milli = requested;
  } else if (format::hasLobes(rec)) {
    const runtime::InterleavedTexels texels(int(rec.map_width), int(rec.map_height), rec.wrap == 0,
                                            reinterpret_cast<const float*>(section.data() + sizeof(rec)), 2);
    trailer.tile_ratio_milli =
        chooseLobeTileRatio(texels, int(rec.rate), rec.sigma_r, int(rec.lobes_per_tile), rec.pyramid_from);
  }
  std::memcpy(section.data() + (section.size() - sizeof(trailer)), &trailer, sizeof(trailer));
}
}  // namespace

Result<std::vector<uint8_t>> flakesSectionBytes(const NormalMap& map, int rate, double sigma_r,
                                                const FlakesHandover& handover) {
  format::FlakesRecord rec;
  rec.map_width = uint32_t(std::max(map.width, 0));
  rec.map_height = uint32_t(std::max(map.height, 0));
  rec.wrap = map.wrap == Wrap::kRepeat ? 0u : 1u;
  rec.rate = uint32_t(std::max(rate, 0));
  rec.sigma_r = sigma_r;
  rec.flakes_up_to = handover.flakes_up_to;
  rec.pyramid_from = handover.pyramid_from;
  rec.lobes_per_tile = uint32_t(std::max(handover.lobes_per_tile, 0));
  rec.lobes_up_to = handover.lobes_per_tile > 0 ? handover.lobes_up_to : 0.0;
  fitRecord(&rec);
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
  writeTrailer(section, rec, handover.tile_ratio_milli);
  return section;
}

BakeStatus setFlakesHandover(std::vector<uint8_t>& section, const FlakesHandover& handover) {
  format::FlakesRecord rec;
  if (section.size() < sizeof(rec)) return makeError(ErrorCode::kInvalidInput, "the flakes section is truncated");
  std::memcpy(&rec, section.data(), sizeof(rec));
  rec.version = std::max(rec.version, 2u);  // (the trailer of version 3 is rewritten below)
  rec.flakes_up_to = handover.flakes_up_to;
  rec.pyramid_from = handover.pyramid_from;
  rec.lobes_per_tile = uint32_t(std::max(handover.lobes_per_tile, 0));
  rec.lobes_up_to = handover.lobes_per_tile > 0 ? handover.lobes_up_to : 0.0;
  fitRecord(&rec);
  if (const char* why = format::checkFlakesRecord(rec, section.size())) return makeError(ErrorCode::kInvalidInput, why);
  std::memcpy(section.data(), &rec, sizeof(rec));
  writeTrailer(section, rec, handover.tile_ratio_milli);
  return okStatus();
}

BakeStatus writeFlakesSection(format::Writer& writer, const NormalMap& map, int rate, double sigma_r,
                              const FlakesHandover& handover, uint64_t* bytes) {
  Result<std::vector<uint8_t>> section = flakesSectionBytes(map, rate, sigma_r, handover);
  if (!section) return section.error();
  if (format::ContainerStatus s =
          writer.addSection(format::kSectionFlakes, 0, section.value().data(), section.value().size());
      s != format::ContainerStatus::kOk)
    return makeError(ErrorCode::kIo, std::string("cannot write the flakes section: ") + format::statusString(s));
  if (bytes) *bytes = section.value().size();
  return okStatus();
}

}  // namespace glintbake::bake::ndf
