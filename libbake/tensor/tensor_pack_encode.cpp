// SPDX-License-Identifier: Apache-2.0
// Compression and encoding of one tensor-ndf group: CP decomposition, column rebalancing, storage
// rounding, prefix sums of the stored values and the error of the stored model.
#include "tensor/tensor_pack_internal.h"

#include <glintbake/bake/tensor/prefix_sums.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

namespace glintbake::bake::tensor {

namespace detail {
namespace {

// Scales the columns of the three factors so that column r of A, B and C have the same norm
// (their product, the rank-1 term, is unchanged). A zero column makes the whole term zero.
void balanceColumns(CpFactors& f) {
  const int rank = f.rank;
  auto columnNorm = [rank](const std::vector<float>& m, int rows, int r) {
    double s = 0.0;
    for (int i = 0; i < rows; ++i) s += double(m[size_t(i) * rank + r]) * double(m[size_t(i) * rank + r]);
    return std::sqrt(s);
  };
  auto scaleColumn = [rank](std::vector<float>& m, int rows, int r, double scale) {
    for (int i = 0; i < rows; ++i) m[size_t(i) * rank + r] = float(double(m[size_t(i) * rank + r]) * scale);
  };
  for (int r = 0; r < rank; ++r) {
    const double na = columnNorm(f.a, f.bins, r), nb = columnNorm(f.b, f.bins, r), nc = columnNorm(f.c, f.blocks, r);
    if (!(na > 0.0 && nb > 0.0 && nc > 0.0)) {
      scaleColumn(f.a, f.bins, r, 0.0);
      scaleColumn(f.b, f.bins, r, 0.0);
      scaleColumn(f.c, f.blocks, r, 0.0);
      continue;
    }
    const double g = std::cbrt(na * nb * nc);
    scaleColumn(f.a, f.bins, r, g / na);
    scaleColumn(f.b, f.bins, r, g / nb);
    scaleColumn(f.c, f.blocks, r, g / nc);
  }
}

// Rounds a factor to the storage precision in place; appends its stored bytes to `out`. Returns
// false if a stored value is not finite.
bool storeFactor(std::vector<float>& values, int precision, std::vector<uint8_t>& out) {
  const size_t at = out.size();
  if (precision == 1) {
    out.resize(at + values.size() * 2);
    for (size_t n = 0; n < values.size(); ++n) {
      const uint16_t h = floatToHalf(values[n]);
      values[n] = halfToFloat(h);
      std::memcpy(out.data() + at + 2 * n, &h, 2);
      if (!std::isfinite(values[n])) return false;
    }
  } else {
    out.resize(at + values.size() * 4);
    std::memcpy(out.data() + at, values.data(), values.size() * 4);
    for (float v : values) {
      if (!std::isfinite(v)) return false;
    }
  }
  return true;
}

void appendFloats(const std::vector<float>& values, std::vector<uint8_t>& out) {
  const size_t at = out.size();
  out.resize(at + values.size() * 4);
  std::memcpy(out.data() + at, values.data(), values.size() * 4);
}

// A column whose rank-1 term vanishes (product of the column norms below 1e-6 of the largest)
// is wasted rank: the deterministic HOSVD start of kCompressed/kAls leaves such columns when the
// mode unfoldings of the group have lower rank than R (e.g. groups of a few repeated spike
// patterns: a flat map's NDF lobes narrower than a bin), and ALS cannot leave that stationary point.
bool hasDeadColumns(const CpFactors& f) {
  std::vector<double> products(size_t(f.rank), 1.0);
  auto accumulate = [&](const std::vector<float>& m, int rows) {
    for (int r = 0; r < f.rank; ++r) {
      double s = 0.0;
      for (int i = 0; i < rows; ++i) s += double(m[size_t(i) * f.rank + r]) * double(m[size_t(i) * f.rank + r]);
      products[size_t(r)] *= std::sqrt(s);
    }
  };
  accumulate(f.a, f.bins);
  accumulate(f.b, f.bins);
  accumulate(f.c, f.blocks);
  double largest = 0.0;
  for (double p : products) largest = std::max(largest, p);
  for (double p : products) {
    if (p <= 1e-6 * largest) return true;
  }
  return false;
}

bool isFinite(const CpFactors& f) {
  for (const auto* m : {&f.a, &f.b, &f.c}) {
    for (float v : *m) {
      if (!std::isfinite(v)) return false;
    }
  }
  return std::isfinite(f.relative_error);
}

// Retries a decomposition stuck with dead columns (or, as a last resort, one whose factors are not
// finite) from the seeded random start of kAlsPlain (same rank, same options otherwise) and keeps
// whichever fits better. Costs nothing on groups without dead columns; deterministic either way.
void retryDeadColumns(const GroupTensor& tensor, const CpOptions& options, CpFactors& f) {
  if (options.method == CpMethod::kAlsPlain) return;
  const bool finite = isFinite(f);
  if (finite && (!(f.relative_error > 1e-6) || !hasDeadColumns(f))) return;
  CpOptions plain = options;
  plain.method = CpMethod::kAlsPlain;
  plain.rank = f.rank;
  Result<CpFactors> retry = decomposeCp(tensor, plain);
  if (retry && (!finite || retry.value().relative_error < f.relative_error)) f = std::move(retry).value();
}

}  // namespace

size_t groupSectionBytes(int bins, int rank, int blocks, int precision) {
  return size_t(format::tensorGroupSectionBytes(uint64_t(bins), uint64_t(rank), uint64_t(blocks), uint32_t(precision)));
}

namespace {

// The section of a group with these factors (rounded to the storage precision in place) and the
// error of the stored model against the tensor.
Result<EncodedGroup> encodeGroup(const GroupTensor& tensor, CpFactors& f, int level, int region,
                                 const TensorPackOptions& options, std::chrono::steady_clock::time_point t0) {
  const int bins = f.bins, rank = f.rank, blocks = f.blocks;
  EncodedGroup g;
  g.rank = rank;
  g.section.reserve(groupSectionBytes(bins, rank, blocks, options.precision));
  format::TensorGroupHeader header;
  header.bins = uint32_t(bins);
  header.rank = uint32_t(rank);
  header.blocks = uint32_t(blocks);
  header.level = uint32_t(level);
  header.region = uint32_t(region);
  header.precision = uint32_t(options.precision);
  g.section.resize(sizeof(header));
  std::memcpy(g.section.data(), &header, sizeof(header));
  if (!storeFactor(f.a, options.precision, g.section) || !storeFactor(f.b, options.precision, g.section) ||
      !storeFactor(f.c, options.precision, g.section)) {
    return makeError(ErrorCode::kRuntime, "a CP factor of group " + std::to_string(region) + " of level " +
                                              std::to_string(level) + " is not finite at the storage precision");
  }
  appendFloats(buildPrefixSums(f.a, bins, rank), g.section);
  appendFloats(buildPrefixSums(f.b, bins, rank), g.section);
  GLINTBAKE_CHECK(g.section.size() == groupSectionBytes(bins, rank, blocks, options.precision));

  // Error of the stored model, bin by bin (float products summed in double, as the runtime's
  // range sums are exact to float rounding).
  std::vector<double> bc(static_cast<size_t>(rank));
  for (int k = 0; k < blocks; ++k) {
    for (int j = 0; j < bins; ++j) {
      for (int r = 0; r < rank; ++r)
        bc[size_t(r)] = double(f.b[size_t(j) * rank + r]) * double(f.c[size_t(k) * rank + r]);
      for (int i = 0; i < bins; ++i) {
        const float* a_row = f.a.data() + size_t(i) * rank;
        double model = 0.0;
        for (int r = 0; r < rank; ++r) model += double(a_row[r]) * bc[size_t(r)];
        const double data = tensor.at(k, i, j);
        g.error_squared += (data - model) * (data - model);
        g.norm_squared += data * data;
        g.error_l1 += std::abs(data - model);
        g.data_l1 += std::abs(data);
        g.absolute_mass += std::abs(model);
        if (model < 0.0) g.negative_mass -= model;
      }
    }
  }
  g.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return g;
}

}  // namespace

Result<EncodedGroup> compressGroup(const GroupTensor& tensor, int level, int region, const TensorPackOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  Result<CpFactors> decomposed = options.error_target < 0.0
                                     ? decomposeCp(tensor, options.cp)
                                     : decomposeCpToError(tensor, options.cp, options.error_target);
  if (!decomposed) return decomposed.error();
  CpFactors& f = decomposed.value();
  retryDeadColumns(tensor, options.cp, f);
  balanceColumns(f);
  return encodeGroup(tensor, f, level, region, options, t0);
}

Result<EncodedGroup> exactGroup(const GroupTensor& tensor, int level, int region, const TensorPackOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  GLINTBAKE_CHECK(tensor.blocks == 1 && tensor.bins <= int(format::kTensorMaxRank));
  // Rank B with A the identity: bin (i, j) = sum_r [i == r] B(j, r) C(0, r) = B(j, i).
  CpFactors f;
  f.bins = tensor.bins;
  f.blocks = 1;
  f.rank = tensor.bins;
  const size_t b = size_t(f.bins);
  f.a.assign(b * b, 0.0f);
  f.b.assign(b * b, 0.0f);
  f.c.assign(b, 1.0f);
  for (size_t i = 0; i < b; ++i) f.a[i * b + i] = 1.0f;
  for (int j = 0; j < f.bins; ++j)
    for (int i = 0; i < f.bins; ++i) f.b[size_t(j) * b + size_t(i)] = tensor.at(0, i, j);
  return encodeGroup(tensor, f, level, region, options, t0);
}

}  // namespace detail
}  // namespace glintbake::bake::tensor
