#pragma once
// The blob-blob mobility M of the rigid multiblob method (Usabiaga et al. 2016):
// RPY between equal blobs, overlap branch included (rpy_kernel.hpp), in blob units:
// positions in blob radii a and M in units of mu0 = 1 / (6 pi eta a). Working in these
// units makes the multiblob solves independent of the viscosity and of the scene's scale.
//
// Two forms: the dense 3n x 3n matrix from the reference pair blocks, for small systems, and
// the product M lambda, the RPY direct sum of rpy_direct_sum.hpp (O(n^2) work, O(n) memory,
// OpenMP-parallel, vectorised for the CPU it runs on); the two agree to rounding.
#include "stokescontact/mobility/rpy_direct_sum.hpp"
#include "stokescontact/mobility/rpy_kernel.hpp"

namespace stokescontact {

// M / mu0 for blobs at x / a (3 x n).
inline MatX rpy_blob_matrix(const Mat3X& x) {
  const Eigen::Index n = x.cols();
  MatX m(3 * n, 3 * n);
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = j; i < n; ++i) {
      const Mat3 block = rpy_translation(x.col(i) - x.col(j), 1.0, 1.0) / stokes_mobility(1.0, 1.0);
      m.block<3, 3>(3 * i, 3 * j) = block;
      m.block<3, 3>(3 * j, 3 * i) = block.transpose();
    }
  }
  return m;
}

// (M / mu0) lambda for blobs at x / a, lambda stacked per blob (3n).
inline VecX rpy_blob_product(const Mat3X& x, const VecX& lambda) { return rpy_direct_sum(x, lambda, 3); }

}  // namespace stokescontact
