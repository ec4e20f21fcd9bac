// SPDX-License-Identifier: Apache-2.0
// What the clustered lobes (lobe_ndf.cpp) use of the exact flakes (internal to the runtime).
#pragma once

#include <glintbake/runtime/flake_ndf.h>

#include "flake_model.h"
#include "gaussian_rect.h"

namespace glintbake::runtime {

struct FlakeNdfAccess {
  // Widest window (flakes per side) whose weights along an axis are summed on the stack.
  static constexpr int kPrefixFlakes = 1024;
  // FlakeNdf::eval with the flakes' footprint weights truncated at window_sigmas standard
  // deviations (a disk: spatial exponent below window_sigmas^2 / 2) instead of 6; the same
  // exponent cutoff and kernels. With a cut, only the flakes of the tiles inside it count
  // (windowedEval, windowedMass and windowedPick alike); the caller keeps those tiles inside the
  // disk, and the window within kPrefixFlakes flakes per side, or mass and pick fail.
  static RuntimeStatus windowedEval(const FlakeNdf& f, const Footprint& fp, const SPoint& s, double window_sigmas,
                                    double* value, const flakes::TileCut* cut = nullptr);
  // windowedEval with outer_window_sigmas (<= 6, the exact path's window; value) and with
  // inner_window_sigmas (<= outer; inner) from one traversal: the inner window's flakes are a
  // subset of the outer one's with the same lane values, so both equal windowedEval up to the
  // order of the summation.
  static RuntimeStatus evalWithInnerWindow(const FlakeNdf& f, const Footprint& fp, const SPoint& s,
                                           double inner_window_sigmas, double outer_window_sigmas, double* value,
                                           double* inner);
  // FlakeNdf::average and FlakeNdf::addImage with the footprint weights truncated at
  // window_sigmas (<= 6), as windowedEval (FlakeNdf's own are these at 6).
  static RuntimeStatus windowedAverage(const FlakeNdf& f, const Footprint& fp, const SRect& rect, double window_sigmas,
                                       double* value);
  static RuntimeStatus windowedAddImage(const FlakeNdf& f, const Footprint& fp, double window_sigmas, double weight,
                                        float* out, size_t out_count);
  // FlakeNdf::sample; without with_pdf the density is not evaluated (out->pdf = 0), for callers
  // that evaluate their own.
  static RuntimeStatus sample(const FlakeNdf& f, const Footprint& fp, double u1, double u2, NdfSample* out,
                              bool with_pdf);
  // The sum of the footprint weights of the flakes in that disk (the integral of windowedEval).
  static RuntimeStatus windowedMass(const FlakeNdf& f, const Footprint& fp, double window_sigmas, double* value,
                                    const flakes::TileCut* cut = nullptr);
  // A flake of that disk in proportion to its weight (u1 picks its row, or with a cut its tile and
  // then its row in the tile, u2 the flake in the row; mass from windowedMass) and its lobe; v1, v2
  // are u1, u2 rescaled within the picked intervals.
  static RuntimeStatus windowedPick(const FlakeNdf& f, const Footprint& fp, double window_sigmas, double u1, double u2,
                                    double mass, flakes::Lobe* lobe, double* v1, double* v2,
                                    const flakes::TileCut* cut = nullptr);
};

class LobeNdf;
struct LobeNdfAccess {
  // Whether the lobes answer a footprint of this sigma from the exact flakes (their finest level
  // keeps every flake as a lobe): then LobeNdf::eval is norm times FlakeNdfAccess::windowedEval
  // with *window_sigmas, on flakes equal to the FlakeNdf built from the same source.
  static bool exactWindow(const LobeNdf& lobes, double sigma, double* window_sigmas, double* norm);
  // LobeNdf::sample, with or without the density (as FlakeNdfAccess::sample). known_mass, when not
  // null, is LobeNdf::mass of the footprint (the same bits), which saves weighing the window twice.
  static RuntimeStatus sample(const LobeNdf& lobes, const Footprint& fp, double u1, double u2, NdfSample* out,
                              bool with_pdf, const double* known_mass = nullptr);
  // LobeNdf::build, with the exact flakes of its finest level taken from `shared` (may be null:
  // the lobes build their own), a built FlakeNdf of the same source, rate and sigma_r that
  // outlives the lobes; kInvalidArgument when it is not built.
  static RuntimeStatus build(LobeNdf& lobes, const TexelSource& source, int rate, double sigma_r, int lobes_per_tile,
                             int resolution, const FlakeNdf* shared);
};

}  // namespace glintbake::runtime
