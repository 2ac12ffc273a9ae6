#pragma once
// The rigidity matrix K of one body (Usabiaga et al. 2016): blob velocities of a
// rigid motion, v_k = u + omega x r_k, with r_k the blob centre minus the body centre;
// its transpose sums blob forces into the body's force and torque,
// K^T lambda = (sum_k lambda_k, sum_k r_k x lambda_k).
// Blob vectors are stacked (x, y, z) per blob; body vectors as (u, omega) or (f, tau).
#include "stokescontact/core/types.hpp"

namespace stokescontact {

// v = K U for the blobs at offsets r (3 x n); v has 3n entries.
inline void apply_rigidity(const Eigen::Ref<const Mat3X>& r, const Vec6& U, Eigen::Ref<VecX> v) {
  const Vec3 u = U.head<3>(), omega = U.tail<3>();
  for (Eigen::Index k = 0; k < r.cols(); ++k) v.segment<3>(3 * k) = u + omega.cross(r.col(k));
}

// K^T lambda for the blobs at offsets r; lambda has 3n entries.
inline Vec6 apply_rigidity_transpose(const Eigen::Ref<const Mat3X>& r, const Eigen::Ref<const VecX>& lambda) {
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero();
  for (Eigen::Index k = 0; k < r.cols(); ++k) {
    const Vec3 l = lambda.segment<3>(3 * k);
    force += l;
    torque += r.col(k).cross(l);
  }
  Vec6 out;
  out << force, torque;
  return out;
}

// K as a dense 3n x 6 matrix: rows 3k..3k+2 are [I, -[r_k]_x].
inline MatX rigidity_matrix(const Eigen::Ref<const Mat3X>& r) {
  MatX K = MatX::Zero(3 * r.cols(), 6);
  for (Eigen::Index k = 0; k < r.cols(); ++k) {
    const Vec3 p = r.col(k);
    K.block<3, 3>(3 * k, 0).setIdentity();
    K.block<3, 3>(3 * k, 3) << 0.0, p.z(), -p.y(), -p.z(), 0.0, p.x(), p.y(), -p.x(), 0.0;
  }
  return K;
}

}  // namespace stokescontact
