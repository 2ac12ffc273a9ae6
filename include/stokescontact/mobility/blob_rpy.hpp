#pragma once
// The blob-blob mobility M of the rigid multiblob method (Usabiaga et al. 2016):
// RPY between equal blobs, overlap branch included (rpy_kernel.hpp), in blob units:
// positions in blob radii a and M in units of mu0 = 1 / (6 pi eta a). Working in these
// units makes the multiblob solves independent of the viscosity and of the scene's scale.
//
// Two forms: the dense 3n x 3n matrix for small systems, and the product M lambda by direct
// summation over all blob pairs, O(n^2) work, O(n) memory, OpenMP-parallel over targets;
// the two agree to rounding.
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

// Below this many blobs the O(n^2) sum is too short to pay for waking OpenMP threads.
inline constexpr Eigen::Index kRpyParallelMinBlobs = 256;

// (M / mu0) lambda for blobs at x / a, lambda stacked per blob (3n).
inline VecX rpy_blob_product(const Mat3X& x, const VecX& lambda) {
  const Eigen::Index n = x.cols();
  VecX out(3 * n);
  const double* p = x.data();
  const double* l = lambda.data();
#ifdef _OPENMP
#pragma omp parallel for schedule(static) if (n >= kRpyParallelMinBlobs)
#endif
  for (Eigen::Index i = 0; i < n; ++i) {
    const double xi = p[3 * i], yi = p[3 * i + 1], zi = p[3 * i + 2];
    double vx = 0.0, vy = 0.0, vz = 0.0;
    for (Eigen::Index j = 0; j < n; ++j) {
      const double dx = xi - p[3 * j], dy = yi - p[3 * j + 1], dz = zi - p[3 * j + 2];
      const double r2 = dx * dx + dy * dy + dz * dz;
      // M = f I + h d d^T: rpy_translation_coefficients with h = g / r^2, written with one
      // square root and one division per pair (the sum's cost).
      double f = 1.0, h = 0.0;  // r = 0: the self term
      if (r2 > 4.0) {
        const double s = 1.0 / std::sqrt(r2), s2 = s * s;
        f = 0.75 * s * (1.0 + 2.0 / 3.0 * s2);
        h = 0.75 * s * s2 * (1.0 - 2.0 * s2);
      } else if (r2 > 0.0) {
        const double r = std::sqrt(r2);
        f = 1.0 - 9.0 / 32.0 * r;
        h = 3.0 / 32.0 / r;
      }
      const double lx = l[3 * j], ly = l[3 * j + 1], lz = l[3 * j + 2];
      const double proj = h * (dx * lx + dy * ly + dz * lz);
      vx += f * lx + proj * dx;
      vy += f * ly + proj * dy;
      vz += f * lz + proj * dz;
    }
    out(3 * i) = vx;
    out(3 * i + 1) = vy;
    out(3 * i + 2) = vz;
  }
  return out;
}

}  // namespace stokescontact
