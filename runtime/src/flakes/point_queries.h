// SPDX-License-Identifier: Apache-2.0
// The point queries of the two flake evaluators (flake_ndf.cpp, lobe_ndf.cpp), written once over
// their Impl (internal to the runtime): the argument checks, the footprint's terms (Impl::terms,
// false for a footprint it cannot answer), then Impl::evalAt at s (0 outside [-1, 1]^2) and
// Impl::massOf.
#pragma once

#include <glintbake/runtime/ndf_source.h>

#include "../query_args.h"
#include "flake_model.h"

namespace glintbake::runtime::flakes {

template <typename Terms, typename Impl>
RuntimeStatus pointEval(const Impl* m, const Footprint& fp, const SPoint& s, double* value) {
  if (!m || !value || !validFootprint(fp) || !finitePoint(s)) return RuntimeStatus::kInvalidArgument;
  Terms t;
  if (!m->terms(fp, &t)) return RuntimeStatus::kInvalidArgument;
  *value = inSquare(s) ? m->evalAt(t, s.x, s.y) : 0.0;
  return RuntimeStatus::kOk;
}

template <typename Terms, typename Impl>
RuntimeStatus pointMass(const Impl* m, const Footprint& fp, double* value) {
  if (!m || !value || !validFootprint(fp)) return RuntimeStatus::kInvalidArgument;
  Terms t;
  if (!m->terms(fp, &t)) return RuntimeStatus::kInvalidArgument;
  *value = m->massOf(t);
  return RuntimeStatus::kOk;
}

// eval / mass (0 where the mass is not positive).
template <typename Terms, typename Impl>
RuntimeStatus pointPdf(const Impl* m, const Footprint& fp, const SPoint& s, double* value) {
  if (!m || !value || !validFootprint(fp) || !finitePoint(s)) return RuntimeStatus::kInvalidArgument;
  Terms t;
  if (!m->terms(fp, &t)) return RuntimeStatus::kInvalidArgument;
  const double mass = m->massOf(t);
  *value = (inSquare(s) && mass > 0.0) ? m->evalAt(t, s.x, s.y) / mass : 0.0;
  return RuntimeStatus::kOk;
}

}  // namespace glintbake::runtime::flakes
