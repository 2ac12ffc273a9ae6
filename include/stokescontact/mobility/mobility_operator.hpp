#pragma once
// The mobility operator: the only view of hydrodynamics the contact code has.
// Given the poses of N rigid bodies and stacked forces (and torques) F, a model returns
// the stacked velocities (and angular velocities) U = M F (Broms Sec. 1.1, Yan Sec. III.A).
//
// Layout: body i owns entries [i * d, (i + 1) * d) with d = dofs_per_body(): d = 6 stacks
// (force, torque) -> (velocity, angular velocity), world frame; d = 3 is a translation-only
// model for scenes that never need torques (spheres pushed through their centres).
// Every model shipped is symmetric positive definite by construction.
#include <concepts>
#include <cstddef>
#include <span>

#include <Eigen/SparseCore>

#include "stokescontact/core/pose.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

// What contact code needs from any model, including one a user writes.
template <typename M>
concept MobilityOperator = requires(M& m, const M& cm, std::span<const Pose> poses, const VecX& F) {
  { m.set_configuration(poses) };                              // new poses, same bodies
  { m.apply(F) } -> std::convertible_to<VecX>;                  // U = M F, counts one application
  { cm.size() } -> std::convertible_to<Eigen::Index>;           // rows of M = N * dofs_per_body()
  { cm.dofs_per_body() } -> std::convertible_to<int>;           // 3 or 6
  { cm.applications() } -> std::convertible_to<std::size_t>;    // applications since the last reset
  { m.reset_applications() };
};

// A model that can give its dense matrix cheaply (one call counts as size() applications
// when the matrix is assembled column by column, as 0 when it is formed directly).
template <typename M>
concept DenseMobilityOperator = MobilityOperator<M> && requires(M& m) {
  { m.dense_matrix() } -> std::convertible_to<MatX>;
};

// A model whose M is block diagonal (bodies do not interact through the fluid: free
// draining) and gives it as a sparse matrix, formed directly from its per-body blocks at the
// current configuration (0 applications). The contact step then forms M D exactly and
// sparsely, in O(bodies + contacts) (MobilityCost::blocks, contact/contact_step.hpp).
template <typename M>
concept BlockDiagonalMobility = MobilityOperator<M> && requires(const M& cm) {
  { cm.block_diagonal() } -> std::convertible_to<Eigen::SparseMatrix<double>>;
};

// Brownian dynamics (Yan et al. eq. 29 with U_known the Brownian velocity, Sec. IV; Delong,
// Balboa Usabiaga & Donev, J. Chem. Phys. 143, 144107 (2015)) needs two more things from a
// model: M^(1/2) W and the thermal drift kT div_q M. Every MobilityOperator gets both from
// mobility/brownian_velocity.hpp (Lanczos) and mobility/thermal_drift.hpp (random finite
// differences); a model that can do better says so with the refinements below.

// A model with an exact, cheap square root (libMobility's sqrtMdotW): apply_sqrt(W) = B W for
// a fixed linear B with B B^T = M at the current configuration. B need not be the symmetric
// root (a Cholesky factor will do): only the covariance B B^T = M matters for a Brownian
// increment. Counts one application, like apply.
template <typename M>
concept SquareRootMobility = MobilityOperator<M> && requires(M& m, const VecX& W) {
  { m.apply_sqrt(W) } -> std::convertible_to<VecX>;
};

// A model that knows the divergence of its mobility exactly at the current configuration:
// divergence()_a = sum_b d M_ab / d q_b, where q_b moves body b's centre (translation entries)
// or rotates it by the exponential map (rotation entries, world frame), the coordinates in
// which random finite differences measure it (Delong et al. 2015). Costs no application and no
// random numbers: a model whose M does not depend on the configuration returns zeros, and so
// skips the two extra applications a random finite difference would take.
template <typename M>
concept ExactDivergenceMobility = MobilityOperator<M> && requires(const M& cm) {
  { cm.divergence() } -> std::convertible_to<VecX>;
};

// Counts applications for a model: the cost unit the papers compare.
class ApplicationCounter {
 public:
  void count(std::size_t n = 1) { applications_ += n; }
  std::size_t applications() const { return applications_; }
  void reset_applications() { applications_ = 0; }

 private:
  std::size_t applications_ = 0;
};

}  // namespace stokescontact
