// SPDX-License-Identifier: Apache-2.0
// CP decomposition drivers: the three methods, extrapolation with restart, error-target rank
// search and the parallel batch.
#include <glintbake/bake/tensor/cp_decomposition.h>

#include "cp_engine.h"
#include "cp_init.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>

namespace glintbake::bake::tensor {

const char* cpMethodName(CpMethod method) {
  switch (method) {
    case CpMethod::kCompressed:
      return "compressed";
    case CpMethod::kAls:
      return "als";
    case CpMethod::kAlsPlain:
      return "als-plain";
  }
  return "unknown";
}

std::optional<CpMethod> parseCpMethod(std::string_view name) {
  for (CpMethod m : {CpMethod::kCompressed, CpMethod::kAls, CpMethod::kAlsPlain}) {
    if (name == cpMethodName(m)) return m;
  }
  return std::nullopt;
}

BakeStatus validateCpOptions(const CpOptions& o) {
  auto bad = [](const std::string& what) { return makeError(ErrorCode::kBadArgument, what); };
  if (o.rank < 1 || o.rank > kMaxCpRank)
    return bad("rank " + std::to_string(o.rank) + " out of range [1, " + std::to_string(kMaxCpRank) + "]");
  if (o.max_iters < 1) return bad("max-iters must be >= 1");
  if (!(o.tol >= 0.0) || !std::isfinite(o.tol)) return bad("tol must be a finite number >= 0");
  if (!(o.ridge >= 0.0 && o.ridge < 1.0)) return bad("ridge must be in [0, 1)");
  if (o.compressed_basis < 0 || o.compressed_basis > 4096) return bad("compressed basis must be in [0, 4096]");
  if (o.refine_sweeps < -1) return bad("refine sweeps must be >= 0 (or -1 for the default)");
  if (!(o.core_tol >= 0.0 || o.core_tol == -1.0) || !std::isfinite(o.core_tol))
    return bad("core tol must be a finite number >= 0 (or -1 for the default)");
  if (o.core_starts < 1 || o.core_starts > 64) return bad("core starts must be in [1, 64]");
  if (o.range_power_iters < 0 || o.range_power_iters > 8) return bad("range power iterations must be in [0, 8]");
  return okStatus();
}

float CpFactors::value(int k, int i, int j) const {
  double sum = 0.0;
  for (int r = 0; r < rank; ++r) {
    sum += static_cast<double>(a[static_cast<size_t>(i) * rank + r] * b[static_cast<size_t>(j) * rank + r]) *
           c[static_cast<size_t>(k) * rank + r];
  }
  return static_cast<float>(sum);
}

namespace {

BakeStatus validateTensor(const GroupTensor& t) {
  if (t.bins < 1 || t.bins > kMaxBlockBins)
    return makeError(ErrorCode::kInvalidInput, "block size " + std::to_string(t.bins) + " out of range [1, " +
                                                   std::to_string(kMaxBlockBins) + "]");
  if (t.blocks < 1) return makeError(ErrorCode::kInvalidInput, "group tensor has no blocks");
  const size_t expected = static_cast<size_t>(t.bins) * t.bins * static_cast<size_t>(t.blocks);
  if (t.values.size() != expected)
    return makeError(ErrorCode::kInvalidInput, "group tensor holds " + std::to_string(t.values.size()) +
                                                   " values, expected " + std::to_string(expected));
  for (float v : t.values) {
    if (!std::isfinite(v)) return makeError(ErrorCode::kInvalidInput, "group tensor holds a non-finite value");
  }
  return okStatus();
}

struct SweepSettings {
  int max_sweeps = 0;
  double tol = 0.0;
  double ridge = 0.0;
  bool nonneg = false;
  bool extrapolate = false;
};

double sweep(CpEngine& engine, CpState& s, const SweepSettings& settings) {
  return settings.nonneg ? engine.halsSweep(s) : engine.alsSweep(s, settings.ridge);
}

// Runs sweeps from `s` (whose squared error is err_sq, +inf when unknown) until the fit changes by
// less than tol or max_sweeps sweeps were spent. Nesterov-type momentum with restart (Mitchell et
// al. 2018): the sweep input is s + beta_k (s - s_prev), beta_k = (k - 1) / (k + 2) with k the
// accepted sweeps since the last restart; a sweep that does not lower the error is discarded and
// redone from s without momentum. Returns the squared error of the final s; adds to *sweeps.
double runSweeps(CpEngine& engine, CpState& s, double err_sq, const SweepSettings& settings, int* sweeps) {
  const double norm = std::sqrt(engine.normSquared());
  auto fitOf = [norm](double e) { return std::isfinite(e) ? 1.0 - std::sqrt(e) / norm : -1e300; };
  CpState prev;
  bool have_prev = false;
  int since_restart = 0;
  int spent = 0;
  while (spent < settings.max_sweeps) {
    const double old_fit = fitOf(err_sq);
    CpState next;
    double next_err = std::numeric_limits<double>::infinity();
    bool accepted = false;
    if (settings.extrapolate && have_prev && since_restart >= 2) {
      const float beta = static_cast<float>(since_restart - 1) / static_cast<float>(since_restart + 2);
      next.a = s.a + beta * (s.a - prev.a);
      next.b = s.b + beta * (s.b - prev.b);
      next.c = s.c + beta * (s.c - prev.c);
      next_err = sweep(engine, next, settings);
      ++spent;
      if (next_err < err_sq) {
        accepted = true;
      } else {
        since_restart = 0;
      }
    }
    if (!accepted) {
      if (spent >= settings.max_sweeps) break;
      next = s;
      next_err = sweep(engine, next, settings);
      ++spent;
    }
    prev = std::move(s);
    have_prev = true;
    s = std::move(next);
    const bool improved = next_err < err_sq;
    err_sq = next_err;
    ++since_restart;
    if (!improved) since_restart = 0;
    if (std::abs(fitOf(err_sq) - old_fit) < settings.tol) break;
  }
  *sweeps += spent;
  return err_sq;
}

CpFactors packFactors(const CpState& s, int bins, int blocks, int rank) {
  CpFactors f;
  f.bins = bins;
  f.blocks = blocks;
  f.rank = rank;
  auto rowMajor = [rank](const MatF& m) {
    std::vector<float> out(static_cast<size_t>(m.rows()) * rank);
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      for (int r = 0; r < rank; ++r) out[static_cast<size_t>(i) * rank + r] = m(i, r);
    }
    return out;
  };
  f.a = rowMajor(s.a);
  f.b = rowMajor(s.b);
  f.c = rowMajor(s.c);
  return f;
}

}  // namespace

Result<CpFactors> decomposeCp(const GroupTensor& tensor, const CpOptions& options) {
  if (BakeStatus st = validateCpOptions(options); !st) return st.error();
  if (BakeStatus st = validateTensor(tensor); !st) return st.error();
  const int bins = tensor.bins, blocks = tensor.blocks, rank = options.rank;
  const float* x = tensor.values.data();

  CpEngine engine(x, bins, blocks, rank);
  CpState s;
  if (engine.normSquared() == 0.0) {
    s.a = MatF::Zero(bins, rank);
    s.b = MatF::Zero(bins, rank);
    s.c = MatF::Zero(blocks, rank);
    return packFactors(s, bins, blocks, rank);
  }

  SweepSettings settings;
  settings.max_sweeps = options.max_iters;
  settings.tol = options.tol;
  settings.ridge = options.ridge;
  settings.nonneg = options.nonneg;
  settings.extrapolate = options.extrapolate && options.method != CpMethod::kAlsPlain;

  int sweeps = 0, core_sweeps = 0;
  double err_sq = std::numeric_limits<double>::infinity();
  const int basis = options.compressed_basis > 0
                        ? options.compressed_basis
                        : (options.nonneg ? std::max(24, 3 * rank / 2) : std::max(64, 2 * rank));
  const bool sparse_sketch =
      options.sketch == RangeSketch::kSparse || (options.sketch == RangeSketch::kAuto && options.nonneg);
  SweepSettings core_settings = settings;  // sweeps on the compressed core
  core_settings.tol = options.core_tol >= 0.0 ? options.core_tol : (options.nonneg ? 1e-4 : options.tol);
  SweepSettings refine = settings;  // full sweeps after the core
  refine.max_sweeps = options.refine_sweeps >= 0 ? options.refine_sweeps : (options.nonneg ? 2 : 10);
  // Mode-3 compression T ~ core x_3 Q, Q (K x L) orthonormal; core_t column l is core block l.
  auto compress = [&](MatF* q, MatF* core_t) {
    *q = modeThreeRangeBasis(x, bins, blocks, basis, options.seed, options.range_power_iters, sparse_sketch);
    Eigen::Map<const MatF> xt(x, static_cast<Eigen::Index>(bins) * bins, blocks);
    core_t->resize(xt.rows(), basis);
    core_t->noalias() = xt * *q;
  };
  // Up to refine.max_sweeps full sweeps from s; the squared error of the result.
  auto refineFull = [&]() {
    const double start = refine.max_sweeps > 0 ? std::numeric_limits<double>::infinity() : engine.evaluate(s);
    return runSweeps(engine, s, start, refine, &sweeps);
  };
  if (options.method == CpMethod::kAlsPlain) {
    randomStart(bins, blocks, rank, options.seed, s);
    err_sq = runSweeps(engine, s, err_sq, settings, &sweeps);
  } else if (options.nonneg && options.method == CpMethod::kCompressed && blocks > 4 * basis) {
    // Non-negative model on compressed data: HALS sweeps against X~ = core x_3 Q (contractions
    // through the L-column core and Q; the constraint stays on the full C), then up to
    // refine_sweeps full HALS sweeps against X. Below K = 4 L a core sweep costs over a quarter of
    // a full one and the full-tensor HALS below is used instead.
    MatF q, core_t;
    compress(&q, &core_t);
    CpEngine compressed(core_t.data(), bins, basis, rank, &q);
    hosvdStart(core_t.data(), bins, basis, rank, options.seed, true, s);
    s.c = MatF::Constant(blocks, rank, 1.0f);
    const double core_err = compressed.solveC(s, options.ridge, true);
    runSweeps(compressed, s, core_err, core_settings, &core_sweeps);
    err_sq = refineFull();
  } else if (options.nonneg || options.method == CpMethod::kAls || blocks <= basis) {
    hosvdStart(x, bins, blocks, rank, options.seed, options.nonneg, s);
    if (options.nonneg) s.c = MatF::Constant(blocks, rank, 1.0f);  // HALS refines C from a positive start
    err_sq = engine.solveC(s, options.ridge, options.nonneg);
    err_sq = runSweeps(engine, s, err_sq, settings, &sweeps);
  } else {
    // Mode-3 compression: T ~ core x_3 Q with Q (K x L) orthonormal; ALS on the B x B x L core,
    // then C = Q C_core and a few full sweeps.
    MatF q, core_t;
    compress(&q, &core_t);
    CpEngine core(core_t.data(), bins, basis, rank);
    // Local minima are real (random starts change the error by a few percent) and core sweeps
    // are cheap: start from the HOSVD and from `core_starts - 1` seeded random points, keep the
    // best core fit.
    double best_err = std::numeric_limits<double>::infinity();
    for (int start = 0; start < std::max(1, options.core_starts); ++start) {
      CpState candidate;
      double err = std::numeric_limits<double>::infinity();
      if (start == 0) {
        hosvdStart(core_t.data(), bins, basis, rank, options.seed, false, candidate);
        err = core.solveC(candidate, options.ridge, false);
      } else {
        randomStart(bins, basis, rank, options.seed + 0x9E3779B97F4A7C15ull * static_cast<uint64_t>(start), candidate);
      }
      err = runSweeps(core, candidate, err, core_settings, &core_sweeps);
      if (err < best_err) {
        best_err = err;
        s = std::move(candidate);
      }
    }
    s.c = q * s.c;
    err_sq = refineFull();
  }

  CpFactors f = packFactors(s, bins, blocks, rank);
  f.relative_error = std::sqrt(err_sq / engine.normSquared());
  f.sweeps = sweeps;
  f.core_sweeps = core_sweeps;
  return f;
}

Result<CpFactors> decomposeCpToError(const GroupTensor& tensor, const CpOptions& options, double target_error) {
  if (!(target_error >= 0.0 && target_error <= 1.0))
    return makeError(ErrorCode::kBadArgument, "error target must be in [0, 1]");
  if (BakeStatus st = validateCpOptions(options); !st) return st.error();
  std::map<int, CpFactors> tried;
  auto attempt = [&](int rank) -> BakeStatus {
    CpOptions o = options;
    o.rank = rank;
    Result<CpFactors> r = decomposeCp(tensor, o);
    if (!r) return r.error();
    tried.emplace(rank, std::move(r).value());
    return okStatus();
  };
  // Invariant: rank lo misses the target (rank 0 by definition), rank hi meets it.
  int lo = 0, hi = options.rank;
  if (BakeStatus st = attempt(hi); !st) return st.error();
  if (tried.at(hi).relative_error > target_error) return std::move(tried.at(hi));
  while (hi - lo > 1) {
    const int mid = lo + (hi - lo) / 2;
    if (BakeStatus st = attempt(mid); !st) return st.error();
    if (tried.at(mid).relative_error <= target_error) {
      hi = mid;
    } else {
      lo = mid;
    }
  }
  return std::move(tried.at(hi));
}

std::vector<Result<CpFactors>> decomposeCpBatch(const std::vector<GroupTensor>& tensors, const CpOptions& options,
                                                int threads, double target_error) {
  std::vector<std::optional<Result<CpFactors>>> slots(tensors.size());
  auto work = [&](size_t n) {
    slots[n].emplace(target_error < 0.0 ? decomposeCp(tensors[n], options)
                                        : decomposeCpToError(tensors[n], options, target_error));
  };
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tensors.size(), 1), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t n = range.begin(); n != range.end(); ++n) work(n);
    });
  });
  std::vector<Result<CpFactors>> out;
  out.reserve(tensors.size());
  for (auto& slot : slots) out.push_back(std::move(*slot));
  return out;
}

double cpReconstructionError(const GroupTensor& tensor, const CpFactors& f) {
  double diff = 0.0, total = 0.0;
  for (int k = 0; k < tensor.blocks; ++k) {
    for (int j = 0; j < tensor.bins; ++j) {
      for (int i = 0; i < tensor.bins; ++i) {
        double model = 0.0;
        for (int r = 0; r < f.rank; ++r) {
          model += static_cast<double>(f.a[static_cast<size_t>(i) * f.rank + r]) *
                   f.b[static_cast<size_t>(j) * f.rank + r] * f.c[static_cast<size_t>(k) * f.rank + r];
        }
        const double v = tensor.at(k, i, j);
        diff += (v - model) * (v - model);
        total += v * v;
      }
    }
  }
  return total > 0.0 ? std::sqrt(diff / total) : 0.0;
}

}  // namespace glintbake::bake::tensor
