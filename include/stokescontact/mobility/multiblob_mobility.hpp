#pragma once
// Rigid multiblob mobility of N bodies (Usabiaga et al., CAMCOS 11 (2016); Broms & Tornberg
// Sec. 1.1): each body a blob model (bodies of one model share it), blobs coupled by RPY with
// the overlap branch, blob motions rigid. The body mobility is N = (K^T M^-1 K)^-1, 6N x 6N,
// world frame, rows (u_i, omega_i), columns (f_i, tau_i) about each body's origin.
//
// Two paths, chosen by MultiblobOptions::solver (or both, adaptive):
//  - dense: the first apply after set_configuration assembles M for all blobs, factorises it
//    (Cholesky) and forms N; every apply is then one 6N x 6N product. For small systems. The
//    factorisation waits for an apply because a configuration may need none (a contact step
//    with no flagged pair sets the configuration and applies nothing).
//  - matrix_free: apply solves the saddle-point system of multiblob_saddle_point.hpp with
//    right-preconditioned GMRES (block-diagonal preconditioner), the RPY products summed
//    directly without forming M. Iterations of the last apply and in total are reported; an
//    apply that misses the tolerance throws std::runtime_error rather than return a wrong U.
//  automatic picks dense when the scene has at most dense_max_blobs blobs.
//  adaptive (up to adaptive_max_blobs blobs; matrix-free beyond): each configuration starts
//  matrix-free and is factorised once its GMRES has spent adaptive_products_per_blob x blobs
//  RPY products, about what the factorisation costs, so a configuration costs about twice the
//  cheaper path at most (the ski-rental rule) where that estimate holds; on the Fig. 8 rods
//  it took 2.7x the dense path. The switch counts products, not seconds, so the same inputs
//  take the same path on any machine.
//  Which path is cheaper depends on how many applications a configuration gets and how fast
//  GMRES converges, not on the blob count alone. Measured (docs/results.md): for the 30
//  multiblob rods of Fig. 8 (1380 blobs, gaps down to 0.005 against a blob radius of 0.19)
//  dense costs 2.3 s per contact step (the factorisation; 74 applications), matrix-free 6-15 s
//  (GMRES converges slowly for bodies this close) and adaptive 6.4 s (one thread, dense 2.4 s
//  in the same run); for loose 12-blob shells the dense set-up takes 6.8 s at 1992 blobs, a
//  matrix-free apply 29 ms at 1536 (15 GMRES iterations).
//
// Rules: all models must share one blob radius (RPY here is the equal-radius tensor); bodies
// may overlap, as the contact code's trial configurations can (RPY's overlap branch keeps M
// positive definite), but two blobs of different bodies closer than kMinBlobSeparation blob
// radii make M numerically singular and are refused with std::invalid_argument.
#include <algorithm>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "stokescontact/core/gmres.hpp"
#include "stokescontact/geometry/broad_phase.hpp"
#include "stokescontact/mobility/mobility_operator.hpp"
#include "stokescontact/mobility/multiblob_saddle_point.hpp"

namespace stokescontact {

enum class MultiblobSolver { automatic, dense, matrix_free, adaptive };

inline const char* multiblob_solver_name(MultiblobSolver solver) {
  switch (solver) {
    case MultiblobSolver::automatic: return "automatic";
    case MultiblobSolver::dense: return "dense";
    case MultiblobSolver::matrix_free: return "matrix-free";
    case MultiblobSolver::adaptive: return "adaptive";
  }
  return "?";
}

// The solver named `name` ("automatic", "dense", "matrix-free", "adaptive"); anything else is
// refused naming `field`.
inline MultiblobSolver multiblob_solver_from_name(std::string_view name, std::string_view field) {
  for (MultiblobSolver s : {MultiblobSolver::automatic, MultiblobSolver::dense, MultiblobSolver::matrix_free,
                            MultiblobSolver::adaptive})
    if (name == multiblob_solver_name(s)) return s;
  fail_argument(field, "unknown multiblob solver '" + std::string(name) +
                           "' (known: automatic, dense, matrix-free, adaptive)");
}

struct MultiblobOptions {
  double viscosity = 1.0;
  MultiblobSolver solver = MultiblobSolver::automatic;
  // automatic: dense up to this many blobs in the scene (it factorises every configuration,
  // needed or not). The dense path holds about two (3 blobs)^2 matrices of doubles while it
  // factorises: 0.14 GB at 1000 blobs.
  Eigen::Index dense_max_blobs = 1000;
  // adaptive: may factorise up to this many blobs (a memory bound only, as adaptive pays the
  // factorisation only where GMRES would cost more): 1.3 GB at 3000 blobs.
  Eigen::Index adaptive_max_blobs = 3000;
  // adaptive: RPY products per blob after which a configuration is factorised. The dense
  // set-up cost about 1.2 x blobs products in both measurements above (6.8 s against 2.9 ms
  // a product at 1992 blobs, 2.3 s against 1.4 ms at 1380; the products from
  // bench_multiblob's 1536-blob apply, scaled by blobs^2).
  double adaptive_products_per_blob = 1.2;
  // Relative residual of the blob-unit saddle-point system; restart and iteration limits.
  GmresOptions gmres{1e-8, 1000, 100};

  void validate() const {
    require_positive(viscosity, "MultiblobOptions.viscosity");
    if (dense_max_blobs < 0) fail_argument("MultiblobOptions.dense_max_blobs", "must be >= 0");
    if (adaptive_max_blobs < 0) fail_argument("MultiblobOptions.adaptive_max_blobs", "must be >= 0");
    require_non_negative(adaptive_products_per_blob, "MultiblobOptions.adaptive_products_per_blob");
    gmres.validate();
  }
};

class MultiblobMobility {
 public:
  // models[k] is a blob model; body i uses models[body_models[i]].
  MultiblobMobility(std::vector<BlobModel> models, std::vector<std::size_t> body_models,
                    MultiblobOptions options = {})
      : models_(std::move(models)), body_models_(std::move(body_models)), options_(options) {
    options_.validate();
    if (models_.empty()) fail_argument("models", "needs at least one blob model");
    if (body_models_.empty()) fail_argument("body_models", "needs at least one body");
    a_ = models_.front().blob_radius;
    for (std::size_t k = 0; k < models_.size(); ++k) {
      const std::string field = "models[" + std::to_string(k) + "]";
      if (models_[k].blob_radius != a_)
        fail_argument(field + ".blob_radius", "must equal models[0].blob_radius = " + std::to_string(a_) +
                                                  " (RPY between equal blobs), got " +
                                                  std::to_string(models_[k].blob_radius));
      self_.push_back(blob_body_mobility(models_[k], field));
      body_frame_.push_back(physical_body_mobility(self_.back().n_blob_units, a_, options_.viscosity));
    }
    system_.first_blob.push_back(0);
    for (std::size_t i = 0; i < body_models_.size(); ++i) {
      if (body_models_[i] >= models_.size())
        fail_argument("body_models[" + std::to_string(i) + "]",
                      "is " + std::to_string(body_models_[i]) + ", only " + std::to_string(models_.size()) +
                          " models given");
      system_.first_blob.push_back(system_.first_blob.back() + models_[body_models_[i]].size());
      system_.bodies.push_back(&self_[body_models_[i]]);
    }
    const Eigen::Index blobs = system_.first_blob.back();
    dense_ = options_.solver == MultiblobSolver::dense ||
             (options_.solver == MultiblobSolver::automatic && blobs <= options_.dense_max_blobs);
    adaptive_ = options_.solver == MultiblobSolver::adaptive && blobs <= options_.adaptive_max_blobs;
  }

  // `bodies` bodies, all of one model.
  MultiblobMobility(const BlobModel& model, std::size_t bodies, MultiblobOptions options = {})
      : MultiblobMobility(std::vector<BlobModel>{model}, std::vector<std::size_t>(bodies, 0), options) {}

  // system_ points into self_: copies would dangle, moves keep the vector's storage.
  MultiblobMobility(const MultiblobMobility&) = delete;
  MultiblobMobility& operator=(const MultiblobMobility&) = delete;
  MultiblobMobility(MultiblobMobility&&) noexcept = default;
  MultiblobMobility& operator=(MultiblobMobility&&) noexcept = default;

  // New poses, same bodies. Validates everything before changing anything; on the dense path
  // the factorisation is left to the first apply (which throws std::invalid_argument naming
  // `poses` if M is not positive definite there).
  void set_configuration(std::span<const Pose> poses) {
    const std::size_t n = body_models_.size();
    validate(poses, n);
    MultiblobSaddlePoint next;
    next.first_blob = system_.first_blob;
    next.bodies = system_.bodies;
    next.blobs.resize(3, blob_count());
    next.offsets.resize(3, blob_count());
    next.rotations.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      next.rotations[i] = poses[i].rotation();
      const BlobModel& m = models_[body_models_[i]];
      const Eigen::Index begin = next.first_blob[i];
      next.offsets.middleCols(begin, m.size()) = (next.rotations[i] * m.positions) / a_;
      next.blobs.middleCols(begin, m.size()) = next.offsets.middleCols(begin, m.size()).colwise() + poses[i].x / a_;
    }
    require_separated_blobs(next.blobs);
    system_ = std::move(next);
    configured_ = true;
    factorised_ = false;
    configuration_products_ = 0;
  }

  // U = N F, one application.
  VecX apply(const VecX& F) {
    require_configured();
    require_finite(F, size(), "F");
    counter_.count();
    if (dense_ || (adaptive_ && (factorised_ || configuration_products_ >= adaptive_switch_products()))) {
      last_iterations_ = 0;
      return factorised_mobility() * F;
    }
    return solve_matrix_free(F);
  }

  // Dense and adaptive paths: N factorised (0 applications). Matrix-free: N assembled column
  // by column (size() applications) and symmetrised.
  MatX dense_matrix() {
    require_configured();
    if (dense_ || adaptive_) return factorised_mobility();
    MatX N(size(), size());
    for (Eigen::Index j = 0; j < size(); ++j) N.col(j) = apply(VecX::Unit(size(), j));
    return 0.5 * (N + N.transpose());
  }

  Eigen::Index size() const { return 6 * static_cast<Eigen::Index>(body_models_.size()); }
  int dofs_per_body() const { return 6; }
  std::size_t applications() const { return counter_.applications(); }
  void reset_applications() {
    counter_.reset_applications();
    total_iterations_ = 0;
  }

  bool uses_dense() const { return dense_; }
  // The path taken: dense, matrix_free or (up to adaptive_max_blobs blobs) adaptive; never automatic.
  MultiblobSolver solver() const {
    return dense_ ? MultiblobSolver::dense : adaptive_ ? MultiblobSolver::adaptive : MultiblobSolver::matrix_free;
  }
  // adaptive: whether the current configuration has been factorised.
  bool factorised() const { return factorised_; }
  Eigen::Index blob_count() const { return system_.first_blob.back(); }
  double blob_radius() const { return a_; }
  // GMRES diagnostics of the matrix-free path (0 on the dense path).
  int last_iterations() const { return last_iterations_; }
  std::size_t total_iterations() const { return total_iterations_; }
  double last_relative_residual() const { return last_residual_; }
  // Physical body-frame 6 x 6 mobility of one body of models[k] alone in the fluid.
  const Mat6& body_frame_mobility(std::size_t k) const { return body_frame_.at(k); }

 private:
  void require_configured() const {
    if (!configured_) throw std::logic_error("MultiblobMobility: call set_configuration before apply");
  }

  // Blobs of different bodies closer than kMinBlobSeparation * a (a cell list, O(n_blobs)).
  void require_separated_blobs(const Mat3X& x) const {
    const std::vector<BodyPair> close = candidate_pairs(x, 0.5 * kMinBlobSeparation, 0.0);
    for (const BodyPair& p : close) {
      const std::size_t bi = body_of(p.i), bj = body_of(p.j);
      if (bi != bj)
        fail_argument("poses", "bodies " + std::to_string(bi) + " and " + std::to_string(bj) +
                                   " have blobs closer than 1e-2 blob radii; the blob mobility is singular");
    }
  }

  std::size_t body_of(Eigen::Index blob) const {
    const auto it = std::upper_bound(system_.first_blob.begin(), system_.first_blob.end(), blob);
    return static_cast<std::size_t>(it - system_.first_blob.begin()) - 1;
  }

  // Dense path: N of the current configuration, formed on the first call after it was set.
  const MatX& factorised_mobility() {
    if (!factorised_) {
      dense_mobility_ = dense_body_mobility(system_);
      factorised_ = true;
    }
    return dense_mobility_;
  }

  // N = mu0 S (K^T M^-1 K)^-1 S in world frame, by one Cholesky of the blob-unit M.
  MatX dense_body_mobility(const MultiblobSaddlePoint& s) const {
    const Eigen::LLT<MatX> m_factor(rpy_blob_matrix(s.blobs));
    if (m_factor.info() != Eigen::Success)
      fail_argument("poses", "the blob mobility is not positive definite in this configuration");
    const MatX Y = m_factor.matrixL().solve(s.rigidity());  // L^-1 K: K^T M^-1 K = Y^T Y
    const Eigen::LLT<MatX> r_factor(Y.transpose() * Y);
    if (r_factor.info() != Eigen::Success)
      fail_argument("poses", "the body resistance K^T M^-1 K is singular in this configuration");
    MatX N = r_factor.solve(MatX::Identity(size(), size()));
    const VecX scale = body_unit_scale();
    N = stokes_mobility(a_, options_.viscosity) * (scale.asDiagonal() * N * scale.asDiagonal());
    return 0.5 * (N + N.transpose());
  }

  std::size_t adaptive_switch_products() const {
    return static_cast<std::size_t>(options_.adaptive_products_per_blob * static_cast<double>(blob_count()));
  }

  VecX body_unit_scale() const {
    return blob_unit_scale(a_).replicate(static_cast<Eigen::Index>(body_models_.size()), 1);
  }

  VecX solve_matrix_free(const VecX& F) {
    const VecX scale = body_unit_scale();
    VecX rhs = VecX::Zero(system_.size());
    rhs.tail(size()) = -(scale.asDiagonal() * F);
    const GmresResult result = gmres([this](const VecX& v) { return system_(v); }, rhs,
                                     [this](const VecX& v) { return system_.precondition(v); }, options_.gmres);
    last_iterations_ = result.iterations;
    last_residual_ = result.relative_residual;
    configuration_products_ += static_cast<std::size_t>(result.operator_applications);
    total_iterations_ += static_cast<std::size_t>(result.iterations);
    if (!result.converged)
      throw std::runtime_error("MultiblobMobility: GMRES stopped at relative residual " +
                               std::to_string(result.relative_residual) + " after " +
                               std::to_string(result.iterations) + " iterations (tolerance " +
                               std::to_string(options_.gmres.tolerance) + ")");
    return stokes_mobility(a_, options_.viscosity) * (scale.asDiagonal() * result.x.tail(size()));
  }

  std::vector<BlobModel> models_;
  std::vector<std::size_t> body_models_;
  MultiblobOptions options_;
  double a_ = 0.0;
  std::vector<BlobBodyMobility> self_;  // per model, blob units
  std::vector<Mat6> body_frame_;        // per model, physical
  MultiblobSaddlePoint system_;
  bool dense_ = false;
  bool configured_ = false;
  bool adaptive_ = false;
  bool factorised_ = false;  // dense_mobility_ belongs to the current configuration
  std::size_t configuration_products_ = 0;  // RPY products of GMRES in the current configuration
  MatX dense_mobility_;
  ApplicationCounter counter_;
  int last_iterations_ = 0;
  std::size_t total_iterations_ = 0;
  double last_residual_ = 0.0;
};

}  // namespace stokescontact
