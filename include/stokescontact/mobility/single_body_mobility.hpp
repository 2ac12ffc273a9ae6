#pragma once
// One body of a blob model alone in the fluid: its 6 x 6 mobility
// N = (K^T M^-1 K)^-1 (Usabiaga et al. 2016) in the body frame, about the body
// origin. Computed once per model and kept: the multiblob solver's block-diagonal
// preconditioner reuses the factor of M, and a free-draining model of an arbitrary shape
// can use the 6 x 6 mobility as its self-mobility.
//
// Internally in blob units (positions / a, mobilities / mu0, mu0 = 1 / (6 pi eta a)); the
// physical mobility is N = mu0 S N~ S with S = diag(I, I / a) (torques over a, angular
// velocities times a are the blob-unit forces and velocities).
#include <string>

#include <Eigen/Cholesky>

#include "stokescontact/mobility/blob_model.hpp"
#include "stokescontact/mobility/blob_rpy.hpp"
#include "stokescontact/mobility/rigidity_matrix.hpp"

namespace stokescontact {

// Blob-unit scale factors: S = diag(I, I / a) turns (f, tau) into blob-unit forces.
inline Vec6 blob_unit_scale(double blob_radius) {
  Vec6 s;
  s << Vec3::Ones(), Vec3::Constant(1.0 / blob_radius);
  return s;
}

// The blob-unit pieces of one model's self-mobility, body frame.
struct BlobBodyMobility {
  Mat3X x;                    // blob positions / a
  Eigen::LLT<MatX> m_factor;  // Cholesky factor of M / mu0 (3n x 3n)
  Mat6 n_blob_units;          // N~ = (K~^T (M / mu0)^-1 K~)^-1

  // The solve of the body's own saddle-point block [M -K; -K^T 0][lambda; U] = [r_l; r_u]
  // (Usabiaga et al. 2016, their preconditioner): U = -N (r_u + K^T M^-1 r_l), lambda = M^-1 (r_l + K U).
  void solve_block(const Eigen::Ref<const VecX>& r_lambda, const Vec6& r_u, Eigen::Ref<VecX> lambda,
                   Vec6& u) const {
    const VecX m_inv_r = m_factor.solve(r_lambda);
    u = -n_blob_units * (r_u + apply_rigidity_transpose(x, m_inv_r));
    VecX rhs = r_lambda;
    apply_rigidity(x, u, lambda);  // lambda <- K U, then M^-1 (r_l + K U)
    rhs += lambda;
    lambda = m_factor.solve(rhs);
  }
};

// Throws std::invalid_argument naming `field` when the model is unusable.
inline BlobBodyMobility blob_body_mobility(const BlobModel& model, const std::string& field = "model") {
  validate(model, field);
  BlobBodyMobility out;
  out.x = model.positions / model.blob_radius;
  out.m_factor.compute(rpy_blob_matrix(out.x));
  if (out.m_factor.info() != Eigen::Success)
    fail_argument(field + ".positions", "blob mobility is not positive definite");
  const MatX K = rigidity_matrix(out.x);
  const MatX Y = out.m_factor.matrixL().solve(K);  // L^-1 K, so K^T M^-1 K = Y^T Y
  const Mat6 resistance = Y.transpose() * Y;
  const Eigen::LLT<Mat6> r_factor(resistance);
  if (r_factor.info() != Eigen::Success)
    fail_argument(field + ".positions", "body resistance K^T M^-1 K is singular");
  out.n_blob_units = r_factor.solve(Mat6::Identity());
  out.n_blob_units = 0.5 * (out.n_blob_units + out.n_blob_units.transpose()).eval();
  return out;
}

// Physical 6 x 6 body-frame mobility from the blob-unit one: N = mu0 S N~ S.
inline Mat6 physical_body_mobility(const Mat6& n_blob_units, double blob_radius, double viscosity) {
  const Vec6 s = blob_unit_scale(blob_radius);
  return stokes_mobility(blob_radius, viscosity) * (s.asDiagonal() * n_blob_units * s.asDiagonal());
}

// The body-frame 6 x 6 mobility of one body of `model` in a fluid of viscosity `viscosity`:
// rows/columns (u, omega) / (f, tau), about the model's origin.
inline Mat6 single_body_mobility(const BlobModel& model, double viscosity) {
  require_positive(viscosity, "viscosity");
  return physical_body_mobility(blob_body_mobility(model).n_blob_units, model.blob_radius, viscosity);
}

}  // namespace stokescontact
