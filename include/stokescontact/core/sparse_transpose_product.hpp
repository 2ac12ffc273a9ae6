#pragma once
// c S^T v for a column-major sparse S (the contact matrix D, or M D) and a scalar c: entry k is
// the sum of (c S_ik) v_i over column k's non-zeros in storage order. That is how Eigen
// evaluates `c * (S.transpose() * v)` (it moves c onto S, and sums a row of the row-major S^T
// in storage order), so the result is the same bit for bit; c = 1 gives `S.transpose() * v`.
//
// Why not Eigen's product: with OpenMP, Eigen runs a row-major sparse product above 20000
// non-zeros as a parallel region of its own. A contact step makes one or two such products per
// iteration of its LCPs (dt D^T M D x): thousands of regions of 10-100 us of work. On 2800 pairs
// of dense rods (docs/results.md, "Every solver on dense Brownian rods") they gained 1.1x on two
// free cores, and cost 3-7x when two processes of two threads shared the cores (a region waits
// for a thread that the other process holds). Here the columns are split over threads only
// from kSparseTransposeParallelColumns columns on, in chunks of kSparseTransposeChunk.
#include <algorithm>
#include <cstddef>

#include <Eigen/Sparse>

#include "stokescontact/core/parallel_for.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

inline constexpr Eigen::Index kSparseTransposeChunk = 8192;
inline constexpr Eigen::Index kSparseTransposeParallelColumns = 8 * kSparseTransposeChunk;

// out = c S^T v (out is resized; its storage is kept when it has the size already).
inline void sparse_transpose_times(const Eigen::SparseMatrix<double>& S, const VecX& v, VecX& out, double c = 1.0) {
  out.resize(S.cols());
  const auto columns = [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index k = begin; k < end; ++k) {
      double sum = 0.0;
      for (Eigen::SparseMatrix<double>::InnerIterator it(S, k); it; ++it) sum += (c * it.value()) * v(it.index());
      out(k) = sum;
    }
  };
  const Eigen::Index n = S.cols();
  if (n < kSparseTransposeParallelColumns) {
    columns(0, n);
    return;
  }
  const Eigen::Index chunks = (n + kSparseTransposeChunk - 1) / kSparseTransposeChunk;
  parallel_for(
      chunks,
      [&](std::ptrdiff_t chunk) {
        const Eigen::Index begin = chunk * kSparseTransposeChunk;
        columns(begin, std::min(n, begin + kSparseTransposeChunk));
      },
      2);
}

inline VecX sparse_transpose_times(const Eigen::SparseMatrix<double>& S, const VecX& v, double c = 1.0) {
  VecX out;
  sparse_transpose_times(S, v, out, c);
  return out;
}

}  // namespace stokescontact
