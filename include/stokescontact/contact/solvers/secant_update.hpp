#pragma once
// A multisecant (Broyden type-I) correction of an approximate Jacobian. Given steps s_l and
// the changes y_l they caused (columns of S and Y), the matrix
//     A = A0 + (Y - A0 S) S^+        (S^+ the pseudo-inverse)
// maps every s_l to y_l exactly and equals A0 on the complement of span(S): the smallest change
// of A0 (in the Frobenius norm) that honours all the secant conditions. For a linear map the
// error left is confined to directions no step has explored yet, so a defect-correction
// iteration converges faster than with A0 alone (Fang & Saad's multisecant family).
//
// Steps are kept in the full contact space (Nc) and restricted to a working set when used,
// since the working set may grow between steps.
#include <span>
#include <vector>

#include <Eigen/QR>

#include "stokescontact/core/types.hpp"

namespace stokescontact {

class SecantCorrection {
 public:
  void add(VecX s, VecX y) {
    if (s.lpNorm<Eigen::Infinity>() == 0.0) return;  // no information
    steps_.push_back(std::move(s));
    changes_.push_back(std::move(y));
  }

  std::size_t size() const { return steps_.size(); }
  void clear() {
    steps_.clear();
    changes_.clear();
  }

  // A0 (on the working set `rows`, indices into the full space) corrected by every step.
  MatX corrected(const MatX& A0, std::span<const Eigen::Index> rows) const {
    if (steps_.empty()) return A0;
    const auto n = static_cast<Eigen::Index>(rows.size());
    const auto m = static_cast<Eigen::Index>(steps_.size());
    MatX S(n, m), Y(n, m);
    for (Eigen::Index l = 0; l < m; ++l)
      for (Eigen::Index r = 0; r < n; ++r) {
        S(r, l) = steps_[static_cast<std::size_t>(l)](rows[static_cast<std::size_t>(r)]);
        Y(r, l) = changes_[static_cast<std::size_t>(l)](rows[static_cast<std::size_t>(r)]);
      }
    return A0 + (Y - A0 * S) * Eigen::CompleteOrthogonalDecomposition<MatX>(S).pseudoInverse();
  }

 private:
  std::vector<VecX> steps_, changes_;
};

}  // namespace stokescontact
