// SPDX-License-Identifier: Apache-2.0
// Deterministic starts (HOSVD, seeded random) and the randomised mode-3 range finder.
#include "cp_init.h"

#include "random.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <vector>

namespace glintbake::bake::tensor {

namespace {

// Columns of the `rank` leading eigenvectors of a symmetric B x B matrix, largest first, with the
// largest-magnitude entry of each made positive; extra columns are seeded Gaussian.
MatF leadingVectors(const MatD& gram_matrix, int rank, SplitMix64& rng, bool nonneg) {
  const Eigen::Index n = gram_matrix.rows();
  Eigen::SelfAdjointEigenSolver<MatD> solver(gram_matrix);
  MatF out(n, rank);
  for (int r = 0; r < rank; ++r) {
    Eigen::VectorXd v(n);
    if (r < n && solver.info() == Eigen::Success) {
      v = solver.eigenvectors().col(n - 1 - r);
      Eigen::Index arg = 0;
      v.cwiseAbs().maxCoeff(&arg);
      if (v[arg] < 0.0) v = -v;
    } else {
      for (Eigen::Index i = 0; i < n; ++i) v[i] = rng.normal();
      v.normalize();
    }
    if (nonneg) v = v.cwiseAbs();
    out.col(r) = v.cast<float>();
  }
  return out;
}

}  // namespace

void hosvdStart(const float* x, int bins, int blocks, int rank, uint64_t seed, bool nonneg, CpState& state) {
  SplitMix64 rng(seed ^ 0x5851F42D4C957F2Dull);
  const Eigen::Index n = bins;
  // Mode 1: bins i are the rows of the B x (B K) column-major view of the data.
  Eigen::Map<const MatF> unfold1(x, n, n * blocks);
  MatF g1(n, n);
  g1.noalias() = unfold1 * unfold1.transpose();
  // Mode 2: sum over blocks of M_k^T M_k, M_k(i, j) the block as a B x B column-major matrix.
  MatF g2 = MatF::Zero(n, n);
  for (int k = 0; k < blocks; ++k) {
    Eigen::Map<const MatF> mk(x + static_cast<size_t>(k) * n * n, n, n);
    g2.noalias() += mk.transpose() * mk;
  }
  state.a = leadingVectors(g1.cast<double>(), rank, rng, nonneg);
  state.b = leadingVectors(g2.cast<double>(), rank, rng, nonneg);
  state.c = MatF::Zero(blocks, rank);
}

void randomStart(int bins, int blocks, int rank, uint64_t seed, CpState& state) {
  SplitMix64 rng(seed);
  auto fill = [&rng](MatF& m, Eigen::Index rows, int cols) {
    m.resize(rows, cols);
    for (int c = 0; c < cols; ++c) {
      for (Eigen::Index r = 0; r < rows; ++r) m(r, c) = static_cast<float>(rng.uniform());
    }
  };
  fill(state.a, bins, rank);
  fill(state.b, bins, rank);
  fill(state.c, blocks, rank);
}

MatF modeThreeRangeBasis(const float* x, int bins, int blocks, int basis, uint64_t seed, int power_iters, bool sparse) {
  const Eigen::Index n = static_cast<Eigen::Index>(bins) * bins;
  Eigen::Map<const MatF> xt(x, n, blocks);  // X^T, (B*B) x K
  SplitMix64 rng(seed ^ 0x2545F4914F6CDD1Dull);
  auto orthonormalise = [blocks, basis](MatF& y) {
    // The power iteration squares the data's scale: NDF bins of 1e6 give sketch entries beyond
    // 1e20, whose squared column norms overflow the float QR. Q is invariant under scaling y by a
    // power of two (every Householder quantity scales exactly), so large sketches are brought to
    // [1, 2) first; below 2^40 nothing is touched.
    const float peak = y.cwiseAbs().maxCoeff();
    if (std::isfinite(peak) && peak > 0x1.0p40f) y *= std::ldexp(1.0f, -std::ilogb(peak));
    Eigen::HouseholderQR<MatF> qr(y);
    MatF q = qr.householderQ() * MatF::Identity(blocks, basis);
    return q;
  };
  MatF y(blocks, basis);
  if (sparse) {
    // Sparse sign sketch (Clarkson & Woodruff 2013): bin b adds +-X(b, :) to one column h(b) of Y.
    std::vector<int> column(static_cast<size_t>(n));
    std::vector<float> sign(static_cast<size_t>(n));
    for (Eigen::Index b = 0; b < n; ++b) {
      const uint64_t r = rng.next();
      column[static_cast<size_t>(b)] = static_cast<int>((r >> 1) % static_cast<uint64_t>(basis));
      sign[static_cast<size_t>(b)] = (r & 1u) ? 1.0f : -1.0f;
    }
    // Four partial rows (bin b into partial b % 4): consecutive bins that hash to one column no
    // longer wait on each other's additions.
    const size_t width = static_cast<size_t>(basis);
    std::vector<float> rows(4 * width);
    for (int k = 0; k < blocks; ++k) {
      std::fill(rows.begin(), rows.end(), 0.0f);
      const float* xk = x + static_cast<size_t>(k) * static_cast<size_t>(n);
      size_t b = 0;
      for (; b + 4 <= static_cast<size_t>(n); b += 4) {
        for (size_t p = 0; p < 4; ++p) rows[p * width + static_cast<size_t>(column[b + p])] += sign[b + p] * xk[b + p];
      }
      for (; b < static_cast<size_t>(n); ++b) rows[static_cast<size_t>(column[b])] += sign[b] * xk[b];
      for (size_t c = 0; c < width; ++c)
        y(k, static_cast<Eigen::Index>(c)) = (rows[c] + rows[width + c]) + (rows[2 * width + c] + rows[3 * width + c]);
    }
  } else {
    MatF omega(n, basis);
    for (int c = 0; c < basis; ++c) {
      for (Eigen::Index r = 0; r < n; ++r) omega(r, c) = static_cast<float>(rng.normal());
    }
    y.noalias() = xt.transpose() * omega;
  }
  MatF q = orthonormalise(y);
  MatF z(n, basis);
  for (int it = 0; it < power_iters; ++it) {
    z.noalias() = xt * q;
    y.noalias() = xt.transpose() * z;
    q = orthonormalise(y);
  }
  return q;
}

}  // namespace glintbake::bake::tensor
