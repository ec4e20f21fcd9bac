// SPDX-License-Identifier: Apache-2.0
// Fitting a whole LTC table: the published fit order and warm starts, parallel over roughness.
#include <glintbake/bake/ltc/table.h>

#include "ltc/cell_fit.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace glintbake::bake::ltc {

double cellAlpha(int a, int size) {
  const double roughness = double(a) / double(size - 1);
  return std::max(roughness * roughness, kMinAlpha);
}

Vec3 cellView(int t, int size) {
  const double x = double(t) / double(size - 1);
  const double cos_theta = 1.0 - x * x;
  const double theta = std::min(kMaxThetaV, std::acos(cos_theta));
  return {std::sin(theta), 0.0, std::cos(theta)};
}

const char* fitMethodString(FitMethod method) {
  switch (method) {
    case FitMethod::kPublished:
      return "published";
    case FitMethod::kRefined:
      return "refined";
  }
  return "unknown";
}

bool fitMethodFromString(const std::string& name, FitMethod* method) {
  if (name == "published") {
    *method = FitMethod::kPublished;
  } else if (name == "refined") {
    *method = FitMethod::kRefined;
  } else {
    return false;
  }
  return true;
}

namespace {

// Fits cell (a, t) starting from *ltc's parameters; t = 0 cells are isotropic and aligned with the
// normal, the others are expressed in the frame of the BRDF's average direction.
FittedCell fitOneCell(const TableFitOptions& options, int a, int t, Ltc* ltc) {
  const int n = options.size;
  const double alpha = cellAlpha(a, n);
  const Vec3 v = cellView(t, n);
  const CellMoments moments = computeMoments(options.brdf, v, alpha, options.samples);
  ltc->magnitude = moments.norm;
  ltc->fresnel = moments.fresnel;
  const bool isotropic = t == 0;
  if (isotropic) {
    ltc->x_axis = {1, 0, 0};
    ltc->y_axis = {0, 1, 0};
    ltc->z_axis = {0, 0, 1};
    ltc->m13 = 0.0;
  } else {
    const Vec3 l = moments.average_dir;
    ltc->x_axis = {l.z, 0, -l.x};
    ltc->y_axis = {0, 1, 0};
    ltc->z_axis = l;
  }
  ltc->update();
  const CellObjective objective(options.brdf, v, alpha, options.samples);
  FittedCell cell;
  cell.objective = fitCell(objective, options.method, isotropic, ltc);
  cell.m = ltc->m;
  // Terms that vanish for an isotropic BRDF with V in the x-z plane.
  cell.m.m[0][1] = cell.m.m[1][0] = cell.m.m[2][1] = cell.m.m[1][2] = 0.0;
  cell.norm = moments.norm;
  cell.fresnel = moments.fresnel;
  cell.fitted = true;
  return cell;
}

}  // namespace

Result<FittedTable> fitTable(const TableFitOptions& options, const FitProgress& progress,
                             const std::atomic<bool>* cancel) {
  if (options.size < 2 || options.size > 256)
    return makeError(ErrorCode::kBadArgument, "table size must be in [2, 256]");
  if (options.samples < 4 || options.samples > 256)
    return makeError(ErrorCode::kBadArgument, "samples must be in [4, 256]");
  if (options.max_roughness_columns < 0)
    return makeError(ErrorCode::kBadArgument, "max_roughness_columns must be >= 0");
  const int n = options.size;
  const int columns = options.max_roughness_columns == 0 ? n : std::min(n, options.max_roughness_columns);
  const int first_a = n - columns;

  FittedTable table;
  table.size = n;
  table.brdf = options.brdf;
  table.cells.resize(size_t(n) * size_t(n));
  std::atomic<int> done{0};
  auto report = [&](int count) {
    const int now = done.fetch_add(count) + count;
    if (progress) progress(now);
  };
  auto cancelled = [&] { return cancel && cancel->load(std::memory_order_relaxed); };

  // Row t = 0 chains through roughness: each cell starts from the previous (rougher) one.
  std::vector<Ltc> row0(static_cast<size_t>(n));
  Ltc chain;
  for (int a = n - 1; a >= first_a; --a) {
    if (cancelled()) return makeError(ErrorCode::kRuntime, "cancelled");
    if (a == n - 1) chain.m11 = chain.m22 = 1.0;
    chain.m13 = 0.0;
    table.cells[size_t(a)] = fitOneCell(options, a, 0, &chain);
    row0[size_t(a)] = chain;
    report(1);
  }

  // Each column's sweep over t is independent; results land in fixed slots, so the output does not
  // depend on scheduling.
  tbb::parallel_for(first_a, n, [&](int a) {
    Ltc ltc = row0[size_t(a)];
    for (int t = 1; t < n; ++t) {
      if (cancelled()) return;
      table.cells[size_t(a) + size_t(n) * size_t(t)] = fitOneCell(options, a, t, &ltc);
    }
    report(n - 1);
  });
  if (cancelled()) return makeError(ErrorCode::kRuntime, "cancelled");
  return table;
}

}  // namespace glintbake::bake::ltc
