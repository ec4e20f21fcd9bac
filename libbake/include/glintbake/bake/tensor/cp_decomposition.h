// SPDX-License-Identifier: Apache-2.0
// CP (CANDECOMP/PARAFAC) compression of groups of angular NDF blocks (Deng et al. 2022,
// "Constant-Cost Spatio-Angular Prefiltering of Glinty Appearance Using Tensor Decomposition",
// ACM TOG, sec. 4; algorithms after Kolda & Bader 2009, "Tensor Decompositions and Applications",
// sec. 3.4).
//
// A group tensor T is B x B x K: K angular blocks of B x B bins each (bin column i, row j, block k).
// A rank-R CP model approximates it by
//     T(i, j, k) ~ sum_r A(i, r) B(j, r) C(k, r),
// with the column scales (lambda) folded into C, so that A and B have unit-norm columns.
//
// Methods (CpMethod):
//   kCompressed (default, "compressed"): deterministic HOSVD start; the mode-3 fibres are compressed
//     onto a K x L orthonormal basis found by a seeded randomised range finder (Halko et al. 2011,
//     alg. 4.4 with one power iteration); ALS with extrapolation runs on the small B x B x L core;
//     the result is expanded and refined by at most `refine_sweeps` full extrapolated sweeps.
//     The core ALS runs from the HOSVD and from core_starts - 1 seeded random points and keeps the
//     best (core sweeps cost L/K of a full sweep; local minima are real).
//     Defaults: L = max(64, 2 R), 3 starts, up to 10 refinement sweeps (chosen by the survey in
//     bench/cp-survey.md).
//   kAls ("als"): deterministic HOSVD start and full-tensor sweeps with extrapolation.
//   kAlsPlain ("als-plain"): the published method: seeded uniform random start, plain ALS sweeps,
//     stop when the fit changes by less than `tol` or after `max_iters` sweeps.
// Every sweep uses a dimension tree: W = C^T X once, A and B from W,
// C from X (B kr A): the tensor is read twice per sweep. The R x R normal equations are solved by
// Cholesky with a ridge of `ridge` * trace / R; Gram matrices and the error are accumulated in
// double (error^2 = |X|^2 - 2 <M_C, C> + 1^T (A^T A .* B^T B .* C^T C) 1).
// Extrapolation is Nesterov-style momentum with restart (Mitchell et al. 2018, "Nesterov
// Acceleration of Alternating Least Squares for Canonical Tensor Decomposition"): a sweep starts
// from the extrapolated factors; if its error is not lower, the momentum is dropped and the sweep
// is redone from the last accepted factors.
//
// nonneg = true replaces the least-squares updates by HALS column updates (Cichocki & Phan 2009)
// projected onto A, B, C >= 0, from a non-negative start (|HOSVD| for kCompressed and kAls,
// uniform random for kAlsPlain). kCompressed runs its HALS sweeps against the mode-3 compressed
// tensor X~ = core x_3 Q (contractions through the B x B x L core and Q, the constraint on the
// full K x R matrix C), then up to refine_sweeps full HALS sweeps against X. Its defaults differ
// from the signed path's (sparse sign sketch with one power iteration, L = max(24, 3 R / 2), core
// sweeps to a fit change of 1e-4, 2 refinement sweeps), each chosen by measurement
// (bench/cp-survey.md). Every reconstructed value and every range sum is >= 0.
//
// Rank-deficient groups: when R exceeds the rank of an unfolding (e.g. a map whose normals vary
// along one axis only: its NDF images are thin lines, so one mode of the group spans a few bins),
// the surplus rank-1 terms die and their scales, carried by C, decay through the float subnormals.
// The HALS updates of A and B against such a column are of the order 1 / |c_r|; they are formed
// and normalised in double and the scale moved into C, so every factor stays finite (a dead term
// is zero or is revived as an ordinary one). The float arithmetic of every other column is
// unchanged.
//
// Determinism: results depend only on the tensor and the options (seeded generators, fixed
// summation order, no threading inside one decomposition): identical bytes on every run and for
// any thread count of decomposeCpBatch.
// Thread safety: all functions are reentrant; decomposeCpBatch uses TBB internally.
// Untrusted input: non-finite values and inconsistent sizes are rejected with kInvalidInput.
#pragma once

#include <glintbake/bake/result.h>

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace glintbake::bake::tensor {

constexpr int kMaxCpRank = 64;      // largest supported rank (the runtime's limit too)
constexpr int kMaxBlockBins = 256;  // largest block side B

// K blocks of B x B bins: bin (i, j) of block k is values[(k * B + j) * B + i] (row-major images,
// row j = 0 at the top, like NDF images). Values are NDF densities (any non-negative scale works;
// negative values are allowed but unusual).
struct GroupTensor {
  int bins = 32;              // B, [1, kMaxBlockBins]
  int blocks = 0;             // K, >= 1
  std::vector<float> values;  // blocks * bins * bins

  float at(int k, int i, int j) const { return values[(static_cast<size_t>(k) * bins + j) * bins + i]; }
};

enum class CpMethod { kCompressed, kAls, kAlsPlain };

// The first sketch of kCompressed's range finder: Gaussian (a dense B^2 x L GEMM) or a sparse sign
// sketch (each bin added to one of L columns with a random sign; Clarkson & Woodruff 2013), whose
// cost is one read of the tensor. kAuto: sparse when nonneg, Gaussian otherwise.
enum class RangeSketch { kAuto, kGaussian, kSparse };

// "compressed", "als", "als-plain".
const char* cpMethodName(CpMethod method);
std::optional<CpMethod> parseCpMethod(std::string_view name);

struct CpOptions {
  int rank = 16;  // R, [1, kMaxCpRank]
  CpMethod method = CpMethod::kCompressed;
  bool nonneg = false;                      // non-negative factors (HALS)
  int max_iters = 500;                      // sweeps of the main ALS loop, >= 1
  double tol = 1e-5;                        // stop when |fit_n - fit_{n-1}| < tol (fit = 1 - rel. error), >= 0
  double ridge = 1e-7;                      // relative Tikhonov term of the normal equations, [0, 1)
  int compressed_basis = 0;                 // L of kCompressed, [0, 4096]; 0 = max(64, 2 R), or max(24, 3 R / 2)
                                            // when nonneg (kCompressed runs kAls instead when K <= L,
                                            // or K <= 4 L when nonneg: core sweeps would then cost
                                            // over a quarter of a full sweep)
  int refine_sweeps = -1;                   // full sweeps after expanding the compressed solution, >= 0;
                                            // -1 = 10, or 2 when nonneg
  int range_power_iters = 1;                // kCompressed: power iterations of the range finder, [0, 8]
  RangeSketch sketch = RangeSketch::kAuto;  // kCompressed: the range finder's first sketch
  double core_tol = -1.0;                   // kCompressed: tol of the core sweeps, >= 0; -1 = tol, or 1e-4 when nonneg
  int core_starts = 3;                      // kCompressed: core ALS runs (HOSVD + seeded random), best kept, [1, 64]
  bool extrapolate = true;                  // momentum with restart (kCompressed and kAls)
  uint64_t seed = 0x243F6A8885A308D3ull;    // seeds the range finder and the random start
};

// Validates ranges (kBadArgument naming the option).
BakeStatus validateCpOptions(const CpOptions& options);

// A rank-R model of one group. Matrices are row-major: A(i, r) = a[i * rank + r] (bins x rank),
// B(j, r) = b[j * rank + r], C(k, r) = c[k * rank + r] (blocks x rank, lambda folded in).
struct CpFactors {
  int bins = 0;
  int blocks = 0;
  int rank = 0;
  std::vector<float> a, b, c;
  double relative_error = 0.0;  // |T - model|_F / |T|_F from the Gram identity (0 for T = 0)
  int sweeps = 0;               // full-tensor sweeps performed (core sweeps not counted)
  int core_sweeps = 0;          // sweeps on the compressed core (kCompressed)

  // Model value at bin (i, j) of block k (float products, double sum).
  float value(int k, int i, int j) const;
};

// Decomposes one group tensor at options.rank. Errors: kBadArgument (options), kInvalidInput
// (sizes or non-finite values). Cost: about 4 B^2 K R flops per full sweep.
Result<CpFactors> decomposeCp(const GroupTensor& tensor, const CpOptions& options);

// Error-target mode: the smallest rank in [1, options.rank] whose relative error is <= target
// (binary search over ranks; each candidate rank is decomposed with the same options, so the result
// equals decomposeCp at that rank). When no rank meets the target, the options.rank result.
// target_error in [0, 1].
Result<CpFactors> decomposeCpToError(const GroupTensor& tensor, const CpOptions& options, double target_error);

// Decomposes many tensors in parallel (one tensor per task, TBB, `threads` workers, 0 = all
// cores). target_error < 0: fixed rank; otherwise error-target mode. Output i belongs to input i
// and is identical whatever the thread count.
std::vector<Result<CpFactors>> decomposeCpBatch(const std::vector<GroupTensor>& tensors, const CpOptions& options,
                                                int threads, double target_error = -1.0);

// Explicit relative reconstruction error |T - model|_F / |T|_F, accumulated in double (a check of
// relative_error; costs B^2 K R).
double cpReconstructionError(const GroupTensor& tensor, const CpFactors& factors);

}  // namespace glintbake::bake::tensor
