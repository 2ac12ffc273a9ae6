#pragma once
// The rigid multiblob mobility problem as one saddle-point system (Usabiaga et al. 2016),
// in blob units (positions / a, M / mu0, torques / a, angular velocities * a):
//
//   [ M    -K ] [ lambda ]   [  0 ]      M: blob-blob RPY mobility (3 n_blobs square)
//   [ -K^T  0 ] [   U    ] = [ -F ]      K: rigidity matrix, body by body
//
// lambda are the blobs' constraint forces (blob velocities K U = M lambda, force balance
// K^T lambda = F). The block-diagonal preconditioner of Usabiaga et al. solves each body's
// own block exactly with the body's self-mobility, factorised once per model in the body
// frame and rotated: M_ii = R M_body R^T, K_i = R K_body Q^T, N_i = Q N_body Q^T with R the
// blockwise rotation of the blobs and Q = diag(R, R) that of (u, omega).
#include <cstddef>
#include <vector>

#include "stokescontact/mobility/blob_rpy.hpp"
#include "stokescontact/mobility/rigidity_matrix.hpp"
#include "stokescontact/mobility/single_body_mobility.hpp"

namespace stokescontact {

// Below this many blobs the per-body preconditioner solves are too short to share out.
inline constexpr Eigen::Index kPreconditionerParallelMinBlobs = 1024;

struct MultiblobSaddlePoint {
  Mat3X blobs;                                  // world blob centres / a
  Mat3X offsets;                                // world blob centre - body centre, / a
  std::vector<Eigen::Index> first_blob;         // body i owns blobs [first_blob[i], first_blob[i + 1])
  std::vector<Mat3> rotations;                  // body frame -> world, per body
  std::vector<const BlobBodyMobility*> bodies;  // per body: its model's self-mobility

  Eigen::Index body_count() const { return static_cast<Eigen::Index>(rotations.size()); }
  Eigen::Index blob_count() const { return blobs.cols(); }
  Eigen::Index size() const { return 3 * blob_count() + 6 * body_count(); }

  // [M lambda - K U; -K^T lambda]; O(n_blobs^2) for the RPY sum, O(n_blobs) for the rest.
  VecX operator()(const VecX& x) const {
    const Eigen::Index nl = 3 * blob_count();
    VecX y(size());
    y.head(nl) = rpy_blob_product(blobs, x.head(nl));
    for (Eigen::Index i = 0; i < body_count(); ++i) {
      const auto [begin, n] = range(i);
      const Vec6 u = x.segment<6>(nl + 6 * i);
      VecX ku(3 * n);
      apply_rigidity(offsets.middleCols(begin, n), u, ku);
      y.segment(3 * begin, 3 * n) -= ku;
      y.segment<6>(nl + 6 * i) = -apply_rigidity_transpose(offsets.middleCols(begin, n), x.segment(3 * begin, 3 * n));
    }
    return y;
  }

  // The block-diagonal preconditioner: each body's block solved exactly in its body frame.
  VecX precondition(const VecX& r) const {
    const Eigen::Index nl = 3 * blob_count();
    VecX z(size());
    const auto bodies_n = body_count();
#ifdef _OPENMP
#pragma omp parallel for schedule(static) if (blob_count() >= kPreconditionerParallelMinBlobs)
#endif
    for (Eigen::Index i = 0; i < bodies_n; ++i) {
      const auto [begin, n] = range(i);
      const Mat3& R = rotations[static_cast<std::size_t>(i)];
      VecX r_lambda(3 * n);  // rotated into the body frame
      for (Eigen::Index k = 0; k < n; ++k) r_lambda.segment<3>(3 * k) = R.transpose() * r.segment<3>(3 * (begin + k));
      Vec6 r_u;
      r_u << R.transpose() * r.segment<3>(nl + 6 * i), R.transpose() * r.segment<3>(nl + 6 * i + 3);
      VecX lambda(3 * n);
      Vec6 u;
      bodies[static_cast<std::size_t>(i)]->solve_block(r_lambda, r_u, lambda, u);
      for (Eigen::Index k = 0; k < n; ++k) z.segment<3>(3 * (begin + k)) = R * lambda.segment<3>(3 * k);
      z.segment<3>(nl + 6 * i) = R * u.head<3>();
      z.segment<3>(nl + 6 * i + 3) = R * u.tail<3>();
    }
    return z;
  }

  // Dense K (3 n_blobs x 6 n_bodies), block by block.
  MatX rigidity() const {
    MatX K = MatX::Zero(3 * blob_count(), 6 * body_count());
    for (Eigen::Index i = 0; i < body_count(); ++i) {
      const auto [begin, n] = range(i);
      K.block(3 * begin, 6 * i, 3 * n, 6) = rigidity_matrix(offsets.middleCols(begin, n));
    }
    return K;
  }

 private:
  struct Range {
    Eigen::Index begin, count;
  };
  Range range(Eigen::Index i) const {
    const auto k = static_cast<std::size_t>(i);
    return {first_blob[k], first_blob[k + 1] - first_blob[k]};
  }
};

}  // namespace stokescontact
