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
#include <utility>
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

  // A0 (on the working set `rows`, indices into the full space; dense or sparse) corrected by
  // every step, as the operator x -> A0 x + (Y - A0 S) (S^+ x): O(nnz(A0) + n m) per product,
  // never a dense n x n matrix. A0 must outlive it.
  template <typename Matrix>
  class Model {
   public:
    explicit Model(const Matrix& A0) : A0_(A0) {}
    Model(const Matrix& A0, MatX left, const MatX& S) : A0_(A0), left_(std::move(left)), steps_(S) {}
    const Matrix& base() const { return A0_; }  // A0, the matrix corrected
    VecX operator()(const VecX& x) const {
      VecX out = A0_ * x;
      if (left_.cols() > 0) out += left_ * VecX(steps_.solve(x));  // S^+ x: the minimum-norm least squares
      return out;
    }

   private:
    const Matrix& A0_;
    MatX left_;                                       // Y - A0 S
    Eigen::CompleteOrthogonalDecomposition<MatX> steps_;  // of S (n x m): S^+ x in O(n m)
  };

  template <typename Matrix>
  Model<Matrix> corrected(const Matrix& A0, std::span<const Eigen::Index> rows) const {
    if (steps_.empty()) return Model<Matrix>(A0);
    const auto n = static_cast<Eigen::Index>(rows.size());
    const auto m = static_cast<Eigen::Index>(steps_.size());
    MatX S(n, m), Y(n, m);
    for (Eigen::Index l = 0; l < m; ++l)
      for (Eigen::Index r = 0; r < n; ++r) {
        S(r, l) = steps_[static_cast<std::size_t>(l)](rows[static_cast<std::size_t>(r)]);
        Y(r, l) = changes_[static_cast<std::size_t>(l)](rows[static_cast<std::size_t>(r)]);
      }
    MatX left = Y - A0 * S;
    return Model<Matrix>(A0, std::move(left), S);
  }

 private:
  std::vector<VecX> steps_, changes_;
};

}  // namespace stokescontact
