// SPDX-License-Identifier: Apache-2.0
// LTC tables: fitting one linearly transformed cosine per (roughness, view angle) cell, the
// published texture layout real-time renderers use, and a fit-error measure for any table in that
// layout (Heitz et al. 2016).
//
// Parametrisation (shared by fitter, layout, evaluator and runtime): a table of size N has columns
// a = 0..N-1 with roughness = a / (N-1), alpha = max(roughness^2, 1e-5), and rows t = 0..N-1 with
// x = t / (N-1), cos(theta_V) = 1 - x^2, theta_V clamped to 1.57 rad, V = (sin, 0, cos). Flat cell
// index a + N t (row t = 0 first).
#pragma once

#include <glintbake/bake/ltc/ltc.h>
#include <glintbake/bake/result.h>
#include <glintbake/format/container.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace glintbake::bake::ltc {

constexpr double kMinAlpha = 1e-5;
constexpr double kMaxThetaV = 1.57;

// View vector and alpha of cell (a, t) of a size-N table.
double cellAlpha(int a, int size);
Vec3 cellView(int t, int size);

enum class FitMethod : uint32_t {
  // The published fitter's settings: Nelder-Mead, simplex offset 0.05, tolerance 1e-5,
  // 100 iterations per cell.
  kPublished = 0,
  // The published run, then a Nelder-Mead restart from its best point (simplex offset 0.01,
  // tolerance 1e-7, 100 iterations) and a Ceres Levenberg-Marquardt polish on the square-rooted
  // objective terms; keeps the best parameters seen, so each cell's objective is never above the
  // published run's from the same start. Default.
  kRefined = 1,
};
const char* fitMethodString(FitMethod method);  // "published", "refined"
bool fitMethodFromString(const std::string& name, FitMethod* method);

struct TableFitOptions {
  BrdfKind brdf = BrdfKind::kGgx;
  int size = 64;     // N, 2..256
  int samples = 32;  // stratified samples per axis for the moments and the objective, 4..256
  FitMethod method = FitMethod::kRefined;
  // Fit only the first `max_roughness_columns` columns counted from a = N-1 downwards (0 = all);
  // the remaining cells keep identity matrices. Tests use it to keep run times short.
  int max_roughness_columns = 0;
};

// One fitted cell: the LTC matrix M (before normalisation), moments and the final objective.
struct FittedCell {
  Mat3 m;
  double norm = 0.0;     // integral of BRDF * cos over the hemisphere
  double fresnel = 0.0;  // same, weighted by (1 - V.H)^5
  double objective = 0.0;
  bool fitted = false;
};

struct FittedTable {
  int size = 0;
  BrdfKind brdf = BrdfKind::kGgx;
  std::vector<FittedCell> cells;  // size * size, flat index a + size * t
};

// Called with the number of cells finished so far (from worker threads; must be thread-safe).
using FitProgress = std::function<void(int cells_done)>;

// Fits a table. The t = 0 cells are fitted serially (warm-started through roughness from a = N-1
// down), then each column's sweep over t runs as an independent task on the TBB arena of the
// caller; the result is bit-identical for every thread count. Returns kBadArgument for options out
// of range, kRuntime if `cancel` becomes true.
Result<FittedTable> fitTable(const TableFitOptions& options, const FitProgress& progress = {},
                             const std::atomic<bool>* cancel = nullptr);

// The published texture layout: two size x size RGBA float images, row t first.
// ltc_1 = (m00, m20, m02, m22) of M^-1 divided by its middle element (row, col);
// ltc_2 = (norm, fresnel, 0, sphere).
struct PublishedTable {
  int size = 0;
  std::vector<float> ltc1;  // size * size * 4
  std::vector<float> ltc2;  // size * size * 4
};
PublishedTable packPublished(const FittedTable& table);

// Adds the two sections of an ltc-table asset (formats/SPEC.md 10.2: type 48, keys 0 and 1,
// size x size x 4 image sections) to an open writer of that kind. kIo on a writer failure.
BakeStatus writeLtcTableSections(const PublishedTable& table, format::Writer& writer);

// The horizon-clipped, cosine-weighted solid angle of a spherical cap divided by that of the
// unclipped cap (Snyder 1996 / Heitz et al. 2017 "sphere" table): rows j (len = j/(N-1), the length
// of the average direction, sin^2 of the cap half-angle), columns i (z = 2i/(N-1) - 1, cosine of the
// cap axis elevation). Returns N * N values, flat index i + N j.
std::vector<float> sphereTable(int size);

// The LTC of cell (a, t) read back from the published layout (magnitude = tabulated norm).
Ltc ltcFromPublished(const PublishedTable& table, int a, int t);

// Fit error of one cell, estimated with samples^2 stratified LTC samples and as many BRDF
// samples, combined with the balance heuristic:
//  - objective: sum of |f_brdf - f_ltc|^3 / (pdf_ltc + pdf_brdf) divided by samples^2 (the
//    published fit objective; scales with the BRDF's peak value cubed, huge at low roughness);
//  - relative_l1: integral of |f_brdf - f_ltc| over the sphere divided by the BRDF's integral
//    (norm): 0 for a perfect fit, at most 2; comparable across cells.
struct CellError {
  double objective = 0.0;
  double relative_l1 = 0.0;
};
CellError cellError(BrdfKind brdf, const Ltc& ltc, Vec3 v, double alpha, int samples);

struct TableError {
  int size = 0;
  int samples = 0;
  std::vector<CellError> cells;  // per cell, flat index a + size t
  double mean_relative_l1 = 0.0;
  double max_relative_l1 = 0.0;
  int max_relative_l1_cell = 0;
  double mean_objective = 0.0;
  // Mean of log10(objective) over cells with a positive objective: the objective spans many
  // decades across roughness, so its plain mean only reflects the sharpest cells.
  double mean_log10_objective = 0.0;
};

// The fit error of a table in the published layout against the true BRDF, per cell, with
// `samples`^2 stratified samples per strategy (use many more than the fit did). Cells are
// evaluated in parallel; the result does not depend on the thread count.
Result<TableError> evaluateTable(const PublishedTable& table, BrdfKind brdf, int samples);

// C header text with the two arrays (static const float ltc_1[N*N*4], ltc_2[N*N*4]) in the
// published layout, printed with 9 significant digits (%.8e) so the floats round-trip exactly.
std::string publishedCHeader(const PublishedTable& table, const std::string& guard_comment);

// Writes the two published-layout images as N x N RGBA float EXR files <prefix>_1.exr and
// <prefix>_2.exr (row t = 0 at the top), each atomically.
BakeStatus writePublishedExr(const PublishedTable& table, const std::string& prefix);

// Reads a table in the published layout from two square RGBA images of equal size (any float or
// integer format OpenImageIO reads; EXR in practice). Safe on untrusted files: sizes are checked
// (2..1024) and non-finite values refused (kInvalidInput); unreadable files give kIo.
Result<PublishedTable> readPublishedImages(const std::string& path1, const std::string& path2);

}  // namespace glintbake::bake::ltc
