// CP decomposition: recovery, error identities, rank behaviour, determinism, the fast default
// against 500 plain sweeps, non-negativity and the error-target rank search.
#include <glintbake/bake/tensor/cp_decomposition.h>

#include "ndf_like_tensors.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstring>

namespace glintbake::bake::tensor {
namespace {

using testing::makeLowRankTensor;
using testing::makeNdfLikeTensor;

CpFactors decompose(const GroupTensor& t, const CpOptions& o) {
  Result<CpFactors> r = decomposeCp(t, o);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? std::move(r).value() : CpFactors{};
}

bool sameBytes(const CpFactors& x, const CpFactors& y) {
  auto eq = [](const std::vector<float>& p, const std::vector<float>& q) {
    return p.size() == q.size() && std::memcmp(p.data(), q.data(), p.size() * sizeof(float)) == 0;
  };
  return x.rank == y.rank && eq(x.a, y.a) && eq(x.b, y.b) && eq(x.c, y.c) && x.relative_error == y.relative_error;
}

TEST(CpDecomposition, RecoversExactLowRankTensorWithEveryMethod) {
  const GroupTensor t = makeLowRankTensor(16, 200, 5, 11);
  for (CpMethod method : {CpMethod::kCompressed, CpMethod::kAls, CpMethod::kAlsPlain}) {
    CpOptions o;
    o.rank = 5;
    o.method = method;
    o.tol = 1e-10;
    o.compressed_basis = 32;
    const CpFactors f = decompose(t, o);
    EXPECT_LT(cpReconstructionError(t, f), 1e-4) << cpMethodName(method);
    EXPECT_NEAR(f.relative_error, cpReconstructionError(t, f), 1e-5) << cpMethodName(method);
  }
}

TEST(CpDecomposition, GramErrorEqualsExplicitError) {
  const GroupTensor t = makeNdfLikeTensor(32, 96, 3);
  for (bool nonneg : {false, true}) {
    CpOptions o;
    o.rank = 12;
    o.nonneg = nonneg;
    o.max_iters = 60;
    const CpFactors f = decompose(t, o);
    EXPECT_NEAR(f.relative_error, cpReconstructionError(t, f), 1e-5) << "nonneg " << nonneg;
    EXPECT_GT(f.relative_error, 0.0);
  }
}

TEST(CpDecomposition, ErrorFallsWithRank) {
  const GroupTensor t = makeNdfLikeTensor(32, 256, 5);
  double previous = 1.0;
  for (int rank : {8, 16, 32}) {
    CpOptions o;
    o.rank = rank;
    const CpFactors f = decompose(t, o);
    std::printf("rank %2d: relative error %.4f (%d full sweeps, %d core sweeps)\n", rank, f.relative_error,
                f.sweeps, f.core_sweeps);
    EXPECT_LT(f.relative_error, previous) << "rank " << rank;
    previous = f.relative_error;
  }
}

TEST(CpDecomposition, DeterministicAcrossRunsAndThreadCounts) {
  std::vector<GroupTensor> tensors;
  for (uint64_t seed = 20; seed < 24; ++seed) tensors.push_back(makeNdfLikeTensor(16, 128, seed));
  for (CpMethod method : {CpMethod::kCompressed, CpMethod::kAlsPlain}) {
    CpOptions o;
    o.rank = 8;
    o.method = method;
    o.max_iters = 40;
    o.compressed_basis = 32;
    const CpFactors once = decompose(tensors[0], o);
    const CpFactors twice = decompose(tensors[0], o);
    EXPECT_TRUE(sameBytes(once, twice));
    const auto serial = decomposeCpBatch(tensors, o, 1);
    const auto parallel = decomposeCpBatch(tensors, o, 2);
    ASSERT_EQ(serial.size(), tensors.size());
    ASSERT_EQ(parallel.size(), tensors.size());
    for (size_t n = 0; n < tensors.size(); ++n) {
      ASSERT_TRUE(serial[n].ok() && parallel[n].ok());
      EXPECT_TRUE(sameBytes(serial[n].value(), parallel[n].value())) << "tensor " << n;
    }
    EXPECT_TRUE(sameBytes(serial[0].value(), once));
  }
}

// The default method must stay within 1% of the error of 500 plain sweeps (algorithms.md sec. 2).
TEST(CpDecomposition, DefaultWithinOnePercentOfFiveHundredPlainSweeps) {
  for (uint64_t seed : {31u, 32u}) {
    const GroupTensor t = makeNdfLikeTensor(32, 512, seed);
    CpOptions plain;
    plain.method = CpMethod::kAlsPlain;
    plain.tol = 0.0;
    plain.max_iters = 500;
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    const CpFactors reference = decompose(t, plain);
    const auto t1 = Clock::now();
    const CpFactors fast = decompose(t, CpOptions{});
    const auto t2 = Clock::now();
    std::printf("seed %d: plain-500 error %.5f (%.0f ms), default error %.5f (%.0f ms, %d+%d sweeps)\n",
                static_cast<int>(seed), reference.relative_error,
                std::chrono::duration<double, std::milli>(t1 - t0).count(), fast.relative_error,
                std::chrono::duration<double, std::milli>(t2 - t1).count(), fast.core_sweeps, fast.sweeps);
    EXPECT_LE(fast.relative_error, 1.01 * reference.relative_error);
  }
}

TEST(CpDecomposition, NonnegativeFactorsAndErrorCost) {
  const GroupTensor t = makeNdfLikeTensor(32, 256, 41);
  CpOptions o;
  o.nonneg = true;
  const CpFactors nn = decompose(t, o);
  for (const auto* v : {&nn.a, &nn.b, &nn.c}) {
    for (float x : *v) ASSERT_GE(x, 0.0f);
  }
  const CpFactors plain = decompose(t, CpOptions{});
  std::printf("rank 16: unconstrained error %.4f, non-negative error %.4f (%+.1f%%)\n", plain.relative_error,
              nn.relative_error, 100.0 * (nn.relative_error / plain.relative_error - 1.0));
  EXPECT_GE(nn.relative_error, plain.relative_error * 0.99);
  EXPECT_LT(nn.relative_error, 1.0);
}

TEST(CpDecomposition, ErrorTargetPicksSmallestSufficientRank) {
  const GroupTensor t = makeNdfLikeTensor(16, 96, 51);
  CpOptions o;
  o.rank = 16;
  o.compressed_basis = 32;
  CpOptions at6 = o;
  at6.rank = 6;
  const double target = decompose(t, at6).relative_error * 1.0001;
  Result<CpFactors> r = decomposeCpToError(t, o, target);
  ASSERT_TRUE(r.ok());
  const CpFactors& f = r.value();
  EXPECT_LE(f.relative_error, target);
  EXPECT_LE(f.rank, 6);
  if (f.rank > 1) {
    CpOptions below = o;
    below.rank = f.rank - 1;
    EXPECT_GT(decompose(t, below).relative_error, target) << "rank " << f.rank - 1 << " already meets the target";
  }
  // An unreachable target returns the maximum rank.
  Result<CpFactors> unreachable = decomposeCpToError(t, o, 0.0);
  ASSERT_TRUE(unreachable.ok());
  EXPECT_EQ(unreachable.value().rank, 16);
}

TEST(CpDecomposition, RejectsBadOptionsAndInputs) {
  const GroupTensor t = makeLowRankTensor(8, 4, 2, 1);
  for (int rank : {0, kMaxCpRank + 1}) {
    CpOptions o;
    o.rank = rank;
    Result<CpFactors> r = decomposeCp(t, o);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kBadArgument);
  }
  GroupTensor bad = t;
  bad.values[5] = std::nanf("");
  EXPECT_EQ(decomposeCp(bad, CpOptions{}).error().code, ErrorCode::kInvalidInput);
  bad = t;
  bad.values.pop_back();
  EXPECT_EQ(decomposeCp(bad, CpOptions{}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(decomposeCpToError(t, CpOptions{}, 1.5).error().code, ErrorCode::kBadArgument);
  EXPECT_EQ(parseCpMethod("als-plain"), CpMethod::kAlsPlain);
  EXPECT_FALSE(parseCpMethod("tucker").has_value());
}

TEST(CpDecomposition, ZeroTensorGivesZeroModel) {
  GroupTensor t;
  t.bins = 8;
  t.blocks = 3;
  t.values.assign(8 * 8 * 3, 0.0f);
  const CpFactors f = decompose(t, CpOptions{});
  EXPECT_EQ(f.relative_error, 0.0);
  for (float v : f.c) EXPECT_EQ(v, 0.0f);
}

}  // namespace
}  // namespace glintbake::bake::tensor
