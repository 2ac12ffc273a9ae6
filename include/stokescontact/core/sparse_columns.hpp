#pragma once
// The listed columns of a column-major sparse matrix, in the order listed (a column may be
// listed twice): column c of the result is column which[c] of A, its entries (explicit zeros
// included) and their order as stored. Written straight into compressed storage, so it costs
// the selected entries only (no selector matrix, no product, no insertion). The contact step
// reads the working set's columns of M D with it (contact/solvers/delassus_probing.hpp and the
// Jacobian at the iterate in defect_correction.hpp).
#include <span>
#include <string>

#include <Eigen/SparseCore>

#include "stokescontact/core/errors.hpp"

namespace stokescontact {

inline Eigen::SparseMatrix<double> select_columns(const Eigen::SparseMatrix<double>& A,
                                                  std::span<const Eigen::Index> which) {
  const auto count = static_cast<Eigen::Index>(which.size());
  Eigen::SparseMatrix<double> out(A.rows(), count);
  int* outer = out.outerIndexPtr();
  outer[0] = 0;
  for (Eigen::Index c = 0; c < count; ++c) {
    const Eigen::Index k = which[static_cast<std::size_t>(c)];
    if (!(0 <= k && k < A.cols()))
      fail_argument("which", "column " + std::to_string(k) + " is not in [0, " + std::to_string(A.cols()) + ")");
    outer[c + 1] = outer[c] + static_cast<int>(A.col(k).nonZeros());
  }
  out.resizeNonZeros(outer[count]);
  for (Eigen::Index c = 0; c < count; ++c) {
    int slot = outer[c];
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, which[static_cast<std::size_t>(c)]); it; ++it, ++slot) {
      out.innerIndexPtr()[slot] = static_cast<int>(it.row());
      out.valuePtr()[slot] = it.value();
    }
  }
  return out;
}

}  // namespace stokescontact
