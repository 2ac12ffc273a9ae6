#pragma once
// The default contact solver: the complementarity problem of Broms & Tornberg eq. 27,
//     0 <= lambda  _|_  d(lambda) - d_hat (1 + margin) >= 0,   d = d^P(Q(lambda)),
// solved by defect correction with a probed Delassus matrix: no pair below d_hat, and a force
// only on pairs held at the threshold. That is a feasible point of the barrier method's
// problem (Broms eq. 15, the smallest sum of lambda with every pair at d >= d_hat), and its
// minimum where pushing one pair never moves another apart (for the linearised problem: A a
// Z-matrix, off-diagonal entries <= 0, whose LCP solution is the least element of the feasible
// set; Cottle, Pang & Stone, The Linear Complementarity Problem, Sec. 3.11). Where a push on one
// pair does open another (pairs meeting at a sharp angle on a shared body, turning rods), the
// smallest sum can be lower: it pushes some pairs that then end apart, a force on a pair that is
// not touching, which complementarity forbids (barrier_working_set.hpp solves that problem).
//
// Why it is cheap. Of the Nc pairs flagged by d_try, only the few that the trial step brings
// below d_hat need a force (in the Broms Fig. 4 scenes ~4% of them), and those are spread through the
// suspension. We keep a working set W of those pairs (and of any pair a correction brings below
// the threshold) and approximate A = dt D^T M D on W by probing (delassus_probing.hpp):
// contacts far apart share one mobility application. Each iteration then solves the LCP of the
// linear model about the current iterate on W, a small dense problem (minimum-map Newton, no
// mobility applications),
//     0 <= lambda_W  _|_  d_W(lambda_k) + A~ (lambda_W - lambda_k,W) - d_hat (1 + margin) >= 0,
// and measures the true distances at the new lambda: one application for M D lambda. The true
// d(lambda_k) enters every model, so a fixed point solves Broms eq. 27 exactly whatever A~ is; the
// probing error (far-field coupling, a few per cent) sets the contraction rate per iteration.
// For spheres the linear model underestimates each centre distance (it is convex in the
// displacements), which keeps the iterates on the separated side.
//
// Refinements, each measured on the Broms Fig. 4 scenes or a hard case in the tests:
//  - pairs outside W that the model predicts the new lambda brings below the target join W
//    before the distances are measured (their rows come free with the probes);
//  - from the second correction on, each measured step (delta lambda, delta d) corrects A~ by
//    a multisecant update (secant_update.hpp); the memory is dropped when a correction makes
//    the worst shortfall grow (line contacts of near-parallel rods);
//  - A~ is lifted to positive definite where probing errors leave it indefinite; an exact model
//    of spheres (blocks, formed) is used as it is, and lifted only when its LCPs fail;
//  - where probes are shared and two corrections in a row fail to halve the shortfall (large
//    dense clusters, whose many far fields add up), the round is finished by the LCP sequence
//    with exact products, polished to complementarity (lcp_sequence.hpp).
//  - each correction's LCP is solved only as far as the corrections' convergence needs
//    (DefectCorrectionOptions::lcp_forcing), tighter as lambda settles.
//  - the guarantee's end check is made at the first corrected iterate too (blocks mode, from
//    1000 pushed pairs: DefectCorrectionOptions::early_end_check): a pair that the forces,
//    not the trial motion, bring below d_hat joins the step then, not in a second round.
//  - in blocks mode (M D exact and sparse) on convex shapes, the model from the second
//    correction on is the Jacobian of the distances at the iterate, dt D_k^T M D, D_k the
//    contact matrix at Q(lambda_k) (DefectCorrectionOptions::jacobian_at_iterate; Lu et al.
//    re-linearise each LCP at the current configuration the same way): Newton's method on
//    eq. 27, not a chord method. Dense Brownian rods (400, L/D = 5, eta 0.31-0.45): 14-59
//    corrections per step instead of 20-110, a 1.2-1.4x shorter median step, but its
//    sub-stepped steps cost 1.8x more (1424 steps at eta 0.40: 1.15x longer in all); jammed
//    spheres: 4 instead of 8-10, about the same time (docs/results.md, "The Jacobian at the
//    iterate").
//    Two corrections in a row that contract neither the shortfall nor the change of lambda
//    hand the round back to the model at Q* with secants.
//    Spheres in blocks mode keep the exact model at Q* instead, symmetric, and solve its LCPs
//    by BBPGD (DefectCorrectionOptions::bbpgd_on_exact_model): more corrections, each cheaper.
//
//  - the distance need not grow monotonically along the force (non-convex shapes: interlocked
//    boomerangs, whose closest points jump between arms as the bodies turn), so a converged
//    lambda* may be a far root of eq. 27 with a smaller separating force on the same ray, and
//    the corrections may stall in a dip of d between two roots. Along a ray s lambda, M D (s
//    lambda) = s M D lambda, so Q(s lambda) and its distances cost no mobility application:
//    at convergence the ray (0, lambda*] is sampled for its first crossing of the target and a
//    smaller crossing is refined by bisection and polished by one more round (never searched
//    again); a round whose corrections stall is sent along its best ray, doubled until it
//    separates, and then back to the first crossing the same way (ray_first_crossing). That
//    ray scales only the forces of the clusters (pairs linked through shared bodies) not yet
//    separated; the separated clusters keep theirs (stalled_cluster_ray).
//    Between bodies that only translate (convex shapes, free space) a pair's gap is convex
//    along the ray, and the samples are skipped where one pair's gap holds the ray below the
//    target past the last sample (ray_held_below_target).
//
// Stopping rule (Broms eq. 29 form): at an iterate whose flagged pairs all have d >= d_hat, stop when
// the next correction would change lambda by less than tol ||lambda||_inf; that iterate is
// returned, so separation is measured, never predicted. The margin puts roundoff and the
// remaining probing error on the separated side; it costs a relative force excess of about
// margin d_hat / (the overlap the force removes). A round whose corrections stop making progress
// at an iterate within the step's separation margin (no pair below it, no pushed pair above it)
// returns it, not converged (DefectCorrectionOptions::separated_stall_corrections): a rod's gap
// at an overlap end can have a maximum along its own force near d_hat (the force turns the
// rod), so the corrections creep up to it or cycle below it.
//
// Cost: the probes (one per colour of each batch of new working-set pairs) plus one
// application per iteration; 0 when no pair comes below d_hat. In formed mode every probe is
// one exact column of M D (cached by the step), A~ = A, and the iterations are free; in
// blocks mode (free draining) A~ = A is read from the sparse M D and nothing costs an application.
// Nothing is dense in the working set: A~ is sparse (delassus_probing.hpp), its LCP is solved
// with products only (GMRES inside minimum-map Newton, started from BBPGD on A~), the secant
// correction is a low-rank operator (secant_update.hpp), and the lift to positive definite is a
// diagonal shift beyond 200 pairs. Time and memory per correction are O(Nc + nnz A~) besides
// the application: one step of 1e6 free-draining spheres with 9e4 pushed pairs ran in 1.1 GB
// (docs/results.md).
// Iterations reported: corrections (LCPs solved).
#include <algorithm>
#include <cmath>
#include <concepts>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/contact/solvers/delassus_probing.hpp"
#include "stokescontact/core/sparse_columns.hpp"
#include "stokescontact/lcp/bbpgd.hpp"
#include "stokescontact/lcp/minimum_map_newton.hpp"
#include "stokescontact/lcp/model_started_newton.hpp"
#include "stokescontact/contact/solvers/secant_update.hpp"
#include "stokescontact/contact/solvers/lcp_sequence.hpp"

namespace stokescontact {

struct DefectCorrectionOptions {
  double margin = 1e-4;               // target d_hat (1 + margin)
  double tol = 1e-4;                  // Broms eq. 29 rule on successive corrections
  double probe_radius_factor = 4.0;   // probe radius = factor x the largest bounding radius
  int max_iterations = 50;            // corrections per round
  int ray_samples = 16;               // samples of the ray (0, lambda] for its first crossing
  int stall_corrections = 3;          // corrections in a row that do not contract before the
                                      // ray search (single-contact probes; shared ones go to
                                      // the LCP sequence after two)
  double contraction = 0.5;           // a correction must shrink the shortfall by this factor ...
                                      // ... or, twice in a row, the LCP sequence takes over
  // A round that has made no progress for this many corrections in a row, at an iterate within
  // the step's separation margin m = ContactStepOptions::separation_margin of eq. 27 (every
  // flagged pair at d >= d_hat (1 - m), every pushed pair at d <= d_hat (1 + m)), ends there,
  // not converged: it returns that iterate instead of spending the rest of max_iterations (0:
  // never). A far root's iterates (pushed pairs many d_hat apart) go on as before. Progress: a
  // shortfall below 0.9 of the round's least so far, or a change of lambda below 0.9 of its
  // least (a sequence converging at any linear rate makes progress every correction). On
  // dense Brownian rods (400, L/D = 5, eta 0.40-0.45) rounds crept at 0.9996 d_hat with changes
  // of 1e-5 of ||lambda||_inf, or cycled between 0.91 and 0.96 d_hat, for 35 corrections and
  // more each (docs/results.md, "A round that stalls separated ends").
  int separated_stall_corrections = 6;
  LcpOptions lcp{1e-12};              // each small LCP's stopping rule, at its tightest
  // Inexact corrections (as in inexact Newton, Dembo, Eisenstat & Steihaug 1982): a correction's
  // LCP is solved only as far as the iteration needs, to the tolerance
  //     clamp(lcp_forcing x (the last correction's change of lambda / ||lambda||_inf),
  //           lcp.tolerance, lcp_tolerance_max),
  // lcp_tolerance_max for the first correction; the tolerance tightens as the corrections
  // converge. lcp_forcing = 0: every LCP to lcp.tolerance. On jammed packings (1575 pushed
  // pairs) the defaults cut the LCPs' time 2.5x with the same corrections; a ceiling of 1e-6 cut
  // it 3.5x but cost the Fig. 4 scenes applications (docs/results.md, "Inexact corrections").
  double lcp_forcing = 1e-3;
  double lcp_tolerance_max = 1e-8;
  // The guarantee's end check (contact_step.hpp) at the round's first corrected iterate: pairs
  // not flagged that the first correction's forces bring below d_hat join the step there, and
  // the round starts again from that iterate, instead of after the round has converged without
  // them (then a second round, warm-started, solves again with them: about a third of a step's
  // time on free-draining spheres). Only with DTryRule::relative, where such pairs are those
  // of the bodies the forces move (ContactStep::add_pairs_closing_at), and in blocks mode,
  // where the working-set model is exact and free. Formed, each pair that joins costs a column
  // (an application), and pairs close at the first iterate need not be at the last (Fig. 8
  // with overlap-ends: 6% more applications); matrix-free, the round started again probes anew
  // and its shared probes contract slowly (1e5 spheres: 8 corrections, then the LCP sequence,
  // 63 applications against 25).
  // The check costs a query over the moved bodies after an O(N) sort, about 8% of a step of 1e4
  // spheres; it is made where the first iterate pushes at least early_end_check_min_pushed
  // pairs. On spheres at packing 0.3 (|f| = 100, dt = d_hat = 0.01) a step missed a pair in 1
  // of 40 scenes of 1e3 spheres (about 84 pushed pairs), 2 of 20 at 3e3 (190), 3 of 12 at 1e4
  // (770) and every one from 3e4 (2400) on (docs/results.md, "The end check at the first
  // correction").
  bool early_end_check = true;
  std::size_t early_end_check_min_pushed = 1000;
  // Blocks mode (M D sparse and exact), convex shapes, contact directions from closest
  // points: the model of each correction from a nonzero iterate is the Jacobian of the
  // distances there, dt D_k^T M D on the working set (D_k the contact matrix at Q(lambda_k),
  // ContactStep::contact_matrix_at), as Lu et al. linearise each LCP of their sequence at the
  // current configuration: Newton's method on Broms eq. 27 instead of a chord method with
  // the Jacobian at Q*, which needs many corrections where bodies turn or slide far along
  // each other. false: the model at Q*, corrected by secants (the other modes always).
  bool jacobian_at_iterate = true;
  // Blocks mode, bodies that only translate (spheres): the model at Q*, dt D^T M D on W, is
  // exact, symmetric and positive semi-definite, so each correction's LCP is the convex QP of
  // Yan et al. eq. 42, which BBPGD (lcp/bbpgd.hpp, their Alg. 1) solves with sparse products
  // alone. With this on, such a round keeps that model (a chord method on Broms eq. 27: no
  // Jacobian at the iterate, no secants) and solves each LCP by BBPGD, Newton only where BBPGD
  // does not converge. Newton with the Jacobian at the iterate needs fewer corrections (4
  // against 8-9 on jammed packings), but its LCPs are not symmetric and need GMRES and sparse
  // factorisations, so each costs more than the extra corrections, which are free in blocks
  // mode (no mobility application). Jammed spheres (1000, phi 0.45-0.6), with the ceiling
  // below: 1.3-1.6x faster per step, complementary to 1.1-1.4e-4 where Newton left up to
  // 4.5e-3; the inward-driven ball 2.0x; 1e5 spheres at packing 0.3 1.05-1.07x
  // (docs/results.md, "BBPGD on the exact model of spheres").
  bool bbpgd_on_exact_model = true;
  // Such a round's ceiling on its LCPs' tolerance (lcp_tolerance_max for the others): the
  // chord's corrections are free, so a looser first LCP costs nothing but a correction, and
  // BBPGD's iterations on it were most of the step. 1e-6 against 1e-8: the ball 1.25x faster
  // with the same 850 corrections, jammed packings 1.2x at 0.55-0.6 (docs/results.md, same
  // section).
  double exact_model_lcp_tolerance_max = 1e-6;
  // A step this solver fails is solved again through solve_contact_step (contact_solver.hpp,
  // solve_failed_step_again), the first answer that does not fail kept: a far root (its
  // correction turns a body by more than ContactStepOptions::max_correction_turn) by eq. 15
  // on the working set (barrier-working-set, which looks for the smallest sum of lambda and so
  // for the near root; only where the library has NLopt), then any failure by the LCP
  // sequence (lcp-newton). Both false: the failure is returned as is. The barrier's SLSQP is
  // dense (its cost grows like the cube of the working set), so the far-root fallback runs only
  // on steps of at most far_root_fallback_max_pairs flagged pairs: on 400 aligned L/D = 5
  // rods at packing 0.31 (1300 flagged pairs, docs/results.md "Dense Brownian rods") one such
  // solve was still running 40 s into its step.
  bool far_root_fallback = true;
  bool lcp_sequence_fallback = true;
  std::size_t far_root_fallback_max_pairs = 256;

  void validate() const {
    require_non_negative(margin, "DefectCorrectionOptions.margin");
    require_positive(tol, "DefectCorrectionOptions.tol");
    require_positive(probe_radius_factor, "DefectCorrectionOptions.probe_radius_factor");
    require_non_negative(lcp_forcing, "DefectCorrectionOptions.lcp_forcing");
    for (const auto& [ceiling, field] : {std::pair{lcp_tolerance_max, "DefectCorrectionOptions.lcp_tolerance_max"},
                                         std::pair{exact_model_lcp_tolerance_max,
                                                   "DefectCorrectionOptions.exact_model_lcp_tolerance_max"}})
      if (!(ceiling >= lcp.tolerance && ceiling < 1.0))
        fail_argument(field, "must lie in [lcp.tolerance, 1), got " + std::to_string(ceiling));
    if (!(contraction > 0.0 && contraction <= 1.0))
      fail_argument("DefectCorrectionOptions.contraction", "must lie in (0, 1], got " + std::to_string(contraction));
    if (ray_samples < 2)
      fail_argument("DefectCorrectionOptions.ray_samples", "must be >= 2, got " + std::to_string(ray_samples));
    if (separated_stall_corrections < 0)
      fail_argument("DefectCorrectionOptions.separated_stall_corrections",
                    "must be >= 0, got " + std::to_string(separated_stall_corrections));
    if (stall_corrections < 1)
      fail_argument("DefectCorrectionOptions.stall_corrections",
                    "must be >= 1, got " + std::to_string(stall_corrections));
    if (max_iterations < 1)
      fail_argument("DefectCorrectionOptions.max_iterations", "must be >= 1, got " + std::to_string(max_iterations));
    lcp.validate();
  }
};

namespace detail {

template <Shape S>
double largest_bounding_radius(std::span<const S> shapes) {
  double r = 0.0;
  for (const S& s : shapes) r = std::max(r, bounding_radius(s));
  return r;
}

// The nearest matrix to the symmetric A~ whose eigenvalues are >= floor x its largest (A~
// itself when it is positive definite). The true A = dt D^T M D is positive semi-definite, and
// singular when the contacts outnumber the bodies' degrees of freedom (dense packings);
// probing errors can then make A~ indefinite, and its LCP unsolvable.
inline MatX positive_definite(const MatX& A, double floor = 1e-3) {
  if (A.size() == 0 || Eigen::LLT<MatX>(A).info() == Eigen::Success) return A;
  const Eigen::SelfAdjointEigenSolver<MatX> eigen(A);
  const VecX& values = eigen.eigenvalues();
  const double smallest = floor * values.maxCoeff();
  return eigen.eigenvectors() * values.cwiseMax(smallest).asDiagonal() * eigen.eigenvectors().transpose();
}

inline Eigen::SparseMatrix<double> lifted_positive_definite(const Eigen::SparseMatrix<double>& A,
                                                            double floor = 1e-3, Eigen::Index dense_limit = 200);

// The same lift for a sparse A~ (the probed model): up to `dense_limit` rows the nearest
// matrix above (dense); beyond, where an eigendecomposition costs O(n^3) (seconds at 1000), the shift
// A~ + tau I with tau = floor x (Gershgorin's bound on the largest eigenvalue), quadrupled
// until a sparse Cholesky factorisation succeeds. A~ itself when it is positive definite.
inline Eigen::SparseMatrix<double> positive_definite(const Eigen::SparseMatrix<double>& A, double floor = 1e-3,
                                                     Eigen::Index dense_limit = 200) {
  using Sparse = Eigen::SparseMatrix<double>;
  if (A.rows() == 0 || Eigen::SimplicialLLT<Sparse>(A).info() == Eigen::Success) return A;
  return lifted_positive_definite(A, floor, dense_limit);
}

// positive_definite's lift of a sparse A~ that is not positive definite (no check that it is).
inline Eigen::SparseMatrix<double> lifted_positive_definite(const Eigen::SparseMatrix<double>& A, double floor,
                                                            Eigen::Index dense_limit) {
  using Sparse = Eigen::SparseMatrix<double>;
  if (A.rows() <= dense_limit) return positive_definite(MatX(A), floor).sparseView();
  const VecX row_sums = A.cwiseAbs() * VecX::Ones(A.cols());
  Sparse identity(A.rows(), A.cols());
  identity.setIdentity();
  for (double tau = floor * row_sums.maxCoeff();; tau *= 4.0) {
    Sparse lifted = A + tau * identity;
    if (Eigen::SimplicialLLT<Sparse>(lifted).info() == Eigen::Success) return lifted;
  }
}

// The working-set model of DefectCorrectionOptions::jacobian_at_iterate: A = dt D_k^T M D on W,
// not symmetric; base() is the symmetric model at Q* (positive semi-definite), from which Newton
// starts (solve_working_set_lcp). Newton's GMRES is preconditioned by base() where A is close
// to it, and by the sparse LU of A's own active blocks where A departs from it by more than
// kLuDeparture (||A - base()||_F / ||base()||_F): rods that turn under their contact forces,
// whose GMRES preconditioned by base() took most of a correction's time. Measured on the
// working sets of the default solver's LCPs: 400 Brownian rods L/D = 5 at eta 0.45, 0.075-0.44
// (median 0.31); 1000 spheres driven into a ball or jammed, 4e-5-0.015 (median 1.5e-3), where
// LDLT of base() is the cheaper factorisation of an as good preconditioner (docs/results.md,
// "The working-set LCP's factorisations").
struct IterateJacobianModel {
  static constexpr double kLuDeparture = 0.03;
  const Eigen::SparseMatrix<double>& symmetric;
  Eigen::SparseMatrix<double> A;

  const Eigen::SparseMatrix<double>& base() const { return symmetric; }
  VecX operator()(const VecX& x) const { return A * x; }
  const Eigen::SparseMatrix<double>* lu_preconditioner() const {
    const double scale = symmetric.norm();
    return scale > 0.0 && (A - symmetric).norm() > kLuDeparture * scale ? &A : nullptr;
  }
};

// dt D_k^T (M D) on the working set W, D_k at the evaluated iterate e; M D sparse (blocks mode).
template <Shape S, MobilityOperator M>
Eigen::SparseMatrix<double> iterate_jacobian(const ContactStep<S, M>& step, const ContactEvaluation& e,
                                             std::span<const Eigen::Index> W) {
  using Sparse = Eigen::SparseMatrix<double>;
  const Sparse MD_W = select_columns(*step.sparse_MD(), W);
  return step.problem().dt * Sparse(step.contact_matrix_at(e, W).transpose() * MD_W);
}

// The working set's LCP of the linear model about the current iterate (A: the model on W, a
// matrix or an operator; distances: all flagged pairs at the iterate); the new lambda on all
// pairs, none if the LCP solver did not converge. `factorisations`, when given, receives the
// sparse factorisations Newton's preconditioner made (LcpResult::preconditioner_factorisations).
// `projected_gradient`: A is the exact symmetric model (DefectCorrectionOptions::
// bbpgd_on_exact_model), whose LCP BBPGD solves first.
template <LcpMatrixOperator Model>
std::optional<VecX> solve_working_set_lcp(const Model& A, std::span<const Eigen::Index> W, const VecX& lambda,
                                          const VecX& distances, double target, const LcpOptions& options,
                                          int* factorisations = nullptr, bool projected_gradient = false) {
  const auto n = static_cast<Eigen::Index>(W.size());
  VecX lambda_W(n), d_W(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    lambda_W(r) = lambda(W[static_cast<std::size_t>(r)]);
    d_W(r) = distances(W[static_cast<std::size_t>(r)]);
  }
  VecX A_lambda_W;
  if constexpr (is_eigen_matrix<Model>) A_lambda_W = A * lambda_W;
  else A_lambda_W = A(lambda_W);
  const VecX b = d_W - VecX::Constant(n, target) - A_lambda_W;
  const auto scatter = [&](const VecX& gamma_W) {  // onto all pairs, 0 outside W
    VecX next = VecX::Zero(lambda.size());
    for (Eigen::Index r = 0; r < n; ++r) next(W[static_cast<std::size_t>(r)]) = gamma_W(r);
    return next;
  };
  // Where there is a sparse model (or the sparse matrix a secant correction corrects), Newton
  // starts from BBPGD on it and is preconditioned by it (model_started_newton.hpp), or by the
  // model's own LU where it asks for that (IterateJacobianModel::lu_preconditioner). A
  // secant-corrected model is not symmetric, and BB steps on it can diverge: its sparse part
  // is used instead.
  const Eigen::SparseMatrix<double>* sparse_part = nullptr;
  if constexpr (std::is_same_v<Model, Eigen::SparseMatrix<double>>) sparse_part = &A;
  else if constexpr (requires { { A.base() } -> std::same_as<const Eigen::SparseMatrix<double>&>; })
    sparse_part = &A.base();
  const auto answer = [&](const LcpResult& lcp) {
    if (factorisations) *factorisations = lcp.preconditioner_factorisations;
    return lcp.converged ? std::optional<VecX>(scatter(lcp.gamma)) : std::nullopt;
  };
  if constexpr (std::is_same_v<Model, Eigen::SparseMatrix<double>>) {
    if (projected_gradient) {
      LcpResult lcp = solve_lcp_bbpgd([&A](const VecX& x) { return VecX(A * x); }, b, options, &lambda_W);
      if (lcp.converged) return answer(lcp);
    }
  }
  if (!sparse_part) return answer(solve_lcp_minimum_map_newton(A, b, options, &lambda_W));
  const VecX b_sparse = std::is_same_v<Model, Eigen::SparseMatrix<double>>
                            ? b
                            : VecX(d_W - VecX::Constant(n, target) - *sparse_part * lambda_W);
  const Eigen::SparseMatrix<double>* lu_preconditioner = nullptr;
  if constexpr (requires { { A.lu_preconditioner() } -> std::same_as<const Eigen::SparseMatrix<double>*>; })
    lu_preconditioner = A.lu_preconditioner();
  return answer(solve_lcp_newton_from_model(A, b, *sparse_part, b_sparse, options, lambda_W, lu_preconditioner));
}

// What the round tells the problem of one correction: its number in the round and how far to
// solve its LCP (DefectCorrectionOptions::lcp_forcing).
struct Correction {
  int number = 0;
  double lcp_tolerance = 1e-12;
  bool exact_symmetric_model = false;  // DefectCorrectionOptions::bbpgd_on_exact_model applies
};

// The round's inexact-correction tolerance (DefectCorrectionOptions::lcp_forcing); `change`:
// the last correction's change of lambda relative to ||lambda||_inf (1 before the first);
// `ceiling`: lcp_tolerance_max, or exact_model_lcp_tolerance_max in a BBPGD chord round.
inline double correction_lcp_tolerance(const DefectCorrectionOptions& options, double change, double ceiling) {
  if (options.lcp_forcing == 0.0) return options.lcp.tolerance;
  return std::clamp(options.lcp_forcing * change, options.lcp.tolerance, ceiling);
}

// The problem each correction solves on the working set's linear model, as the default solver
// poses it: the LCP above (Broms eq. 27, complementarity), to the correction's tolerance. The
// round takes any callable of this shape (barrier_working_set.hpp poses eq. 15 instead);
// `name` prefixes its messages.
// Once a correction's Newton has needed its sparse preconditioner (GMRES did not converge in
// LcpOptions::gmres_unpreconditioned_steps), the round's later corrections factorise at once:
// their working sets are the same clusters, and the unpreconditioned steps would be spent again
// on each (docs/results.md, "The working-set LCP's factorisations").
struct WorkingSetLcp {
  LcpOptions options;
  std::string_view name = "default solver";
  mutable bool factorise_at_once = false;  // learnt by the round's corrections, not an input

  template <LcpMatrixOperator Model>
  std::optional<VecX> operator()(const Model& A, std::span<const Eigen::Index> W, const VecX& lambda,
                                 const VecX& distances, double target, const Correction& correction) const {
    LcpOptions inexact = options;
    inexact.tolerance = correction.lcp_tolerance;
    if (factorise_at_once) inexact.gmres_unpreconditioned_steps = 0;
    int factorisations = 0;
    std::optional<VecX> next =
        solve_working_set_lcp(A, W, lambda, distances, target, inexact, &factorisations, correction.exact_symmetric_model);
    factorise_at_once = factorise_at_once || factorisations > 0;
    return next;
  }
};

// A ray of forces lambda(s) = base + s direction, s > 0, with M D of both (so every point
// of it is free, M D linear in lambda). The whole iterate is the ray with base 0; a stalled
// cluster's is its own forces scaled with the others' held (stalled_cluster_ray).
struct ForceRay {
  VecX base, direction;        // lambda
  VecX MD_base, MD_direction;  // M D lambda

  VecX lambda(double s) const { return base + s * direction; }
  VecX MD(double s) const { return MD_base + s * MD_direction; }
  // M D lambda(s) into `out`, whose storage is kept when it has the size already.
  const VecX& MD(double s, VecX& out) const {
    out.resize(MD_base.size());
    out.noalias() = MD_base + s * MD_direction;
    return out;
  }
  static ForceRay through(const VecX& lambda, const VecX& MD_lambda) {
    return {VecX::Zero(lambda.size()), lambda, VecX::Zero(MD_lambda.size()), MD_lambda};
  }
};

// Whether no sample of the ray s lambda, s in (0, s_max], can separate, known without
// evaluating one. Bodies that only translate, convex shapes, distances d^P, no periodic box
// (spheres in free space): along the ray each flagged pair's distance is a convex function of
// s (the signed distance of two convex bodies is a maximum of affine functions of their
// relative translation, and the ray translates them linearly in s), so a pair at d_0 < target
// at Q* (s = 0) and at d_1 at s = 1 (`distances`) stays below the target for
// s < (target - d_0) / (target - d_0 + max(0, d_1 - target)). When that bound reaches s_max
// for some pair, the search for a nearer crossing (a far root of eq. 27) has nothing to find.
// (In a periodic box a pair's nearest image may change along the ray; it is not used there.)
template <Shape S, MobilityOperator M>
bool ray_held_below_target(const ContactStep<S, M>& step, const VecX& distances, double target, double s_max) {
  if (step.dofs_per_body() != 3 || !S::convex || step.options().template surface_directions<S>() ||
      step.problem().box)
    return false;
  for (Eigen::Index k = 0; k < step.nc(); ++k) {
    if (step.carried(static_cast<std::size_t>(k))) continue;
    const double below = target - step.pairs()[static_cast<std::size_t>(k)].points.distance;
    if (below > 0.0 && below >= s_max * (below + std::max(0.0, distances(k) - target))) return true;
  }
  return false;
}

// The first crossing of the target by the flagged distances on the ray, s in (0, s_max]: the
// smallest of `samples` equal steps whose min d >= target, refined by bisection against the
// step before it to a relative width `tol`; the returned s separates. None when no sample
// separates. A separated window narrower than one step can be missed: the samples bound the cost.
template <Shape S, MobilityOperator M>
std::optional<double> ray_first_crossing(const ContactStep<S, M>& step, const ForceRay& ray, double s_max,
                                         double target, int samples, double tol) {
  VecX MD;  // one buffer for every sample: at 1e6 spheres a fresh one is 24 MB of new pages
  const auto separated = [&](double s) { return step.separated_at(ray.MD(s, MD), target); };
  double lo = 0.0, hi = -1.0;
  for (int j = 1; j <= samples; ++j) {
    const double s = s_max * j / samples;
    if (separated(s)) {
      hi = s;
      break;
    }
    lo = s;
  }
  if (hi < 0.0) return std::nullopt;
  while (hi - lo > tol * hi) {
    const double mid = 0.5 * (lo + hi);
    (separated(mid) ? hi : lo) = mid;
  }
  return hi;
}

// The pairs of the working set (pushed, or below `target`) in clusters, pairs linked through
// shared bodies transitively, that hold a pair below `target`: the clusters not yet
// separated. With a local mobility (free draining) no force outside a cluster moves its bodies.
template <Shape S, MobilityOperator M>
std::vector<char> unseparated_clusters(const ContactStep<S, M>& step, const VecX& lambda, const VecX& distances,
                                       double target) {
  const std::vector<ContactPair>& pairs = step.pairs();
  std::vector<Eigen::Index> parent(step.problem().poses.size());
  for (std::size_t b = 0; b < parent.size(); ++b) parent[b] = static_cast<Eigen::Index>(b);
  const auto root = [&](Eigen::Index b) {
    while (parent[static_cast<std::size_t>(b)] != b)
      b = parent[static_cast<std::size_t>(b)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(b)])];
    return b;
  };
  const auto pair = [&](Eigen::Index k) -> const ContactPair& { return pairs[static_cast<std::size_t>(k)]; };
  const auto in_working_set = [&](Eigen::Index k) { return lambda(k) > 0.0 || distances(k) < target; };
  for (Eigen::Index k = 0; k < step.nc(); ++k)
    if (in_working_set(k)) parent[static_cast<std::size_t>(root(pair(k).i))] = root(pair(k).j);
  std::vector<char> short_root(parent.size(), 0);
  for (Eigen::Index k = 0; k < step.nc(); ++k)
    if (distances(k) < target) short_root[static_cast<std::size_t>(root(pair(k).i))] = 1;
  std::vector<char> member(static_cast<std::size_t>(step.nc()), 0);
  for (Eigen::Index k = 0; k < step.nc(); ++k)
    member[static_cast<std::size_t>(k)] = in_working_set(k) && short_root[static_cast<std::size_t>(root(pair(k).i))];
  return member;
}

// The ray of a round whose corrections stall: the forces of the clusters not yet separated at
// the best iterate scaled, every separated cluster's held. Scaling the whole iterate instead
// pushes clusters that had converged as far as the stalled one needs, by up to 1024 (1000
// Brownian rods: a step whose default answer had lambda_max 6e5 and turned a rod by 1400 rad
// passed once the ray was limited so; docs/results.md). One application for M D of the scaled
// forces, where that is not free; none when they are all the forces.
template <Shape S, MobilityOperator M>
ForceRay stalled_cluster_ray(ContactStep<S, M>& step, const VecX& lambda, const VecX& MD_lambda,
                             const VecX& distances, double target) {
  const std::vector<char> member = unseparated_clusters(step, lambda, distances, target);
  VecX direction = lambda;
  for (Eigen::Index k = 0; k < lambda.size(); ++k)
    if (!member[static_cast<std::size_t>(k)]) direction(k) = 0.0;
  if (direction.sum() == 0.0 || direction == lambda) return ForceRay::through(lambda, MD_lambda);
  VecX MD_direction = step.MD_times(direction);
  return {lambda - direction, direction, MD_lambda - MD_direction, std::move(MD_direction)};
}

// The probed model on W (|W| x |W|) as a matrix on all nc flagged pairs: W's entries where
// they belong, and for a pair outside W (not probed: apart and unpushed at the iterate) the
// mean of W's diagonal, alone on its row. Positive definite when the model is.
inline Eigen::SparseMatrix<double> model_on_flagged_pairs(const Eigen::SparseMatrix<double>& model,
                                                          std::span<const Eigen::Index> W, Eigen::Index nc) {
  if (model.rows() != static_cast<Eigen::Index>(W.size()))
    fail_argument("model", "has " + std::to_string(model.rows()) + " rows for a working set of " + std::to_string(W.size()));
  const double diagonal = model.rows() > 0 ? model.diagonal().mean() : 1.0;
  std::vector<char> in_W(static_cast<std::size_t>(nc), 0);
  for (const Eigen::Index k : W) in_W[static_cast<std::size_t>(k)] = 1;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(model.nonZeros() + nc));
  for (Eigen::Index c = 0; c < model.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(model, c); it; ++it)
      entries.emplace_back(W[static_cast<std::size_t>(it.row())], W[static_cast<std::size_t>(c)], it.value());
  for (Eigen::Index k = 0; k < nc; ++k)
    if (!in_W[static_cast<std::size_t>(k)]) entries.emplace_back(k, k, diagonal);
  Eigen::SparseMatrix<double> out(nc, nc);
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

// The fallback of a round whose corrections do not contract: the LCP sequence with exact
// products, its Newton started from and preconditioned by the round's probed model (`probed`
// on the working set W).
template <Shape S, MobilityOperator M>
ContactSolveOutcome finish_by_lcp_sequence(ContactStep<S, M>& step, const VecX& lambda, int corrections,
                                           const Eigen::SparseMatrix<double>& probed, std::span<const Eigen::Index> W,
                                           const DefectCorrectionOptions& options, std::string_view name) {
  LcpSequenceOptions sequence;
  sequence.tol = options.tol;  // on to complementarity, as the corrections would have
  sequence.margin = options.margin;
  // Each of its GMRES steps is a mobility application: the model's factorisation is cheaper.
  // (Jammed 1000 spheres at phi 0.6, matrix-free: 1320 applications with the default 50
  // unpreconditioned steps first, 788 with none; docs/results.md.)
  sequence.lcp.gmres_unpreconditioned_steps = 0;
  const Eigen::SparseMatrix<double> model = model_on_flagged_pairs(probed, W, step.nc());
  ContactSolveOutcome out = solve_lcp_sequence_round(step, lambda, sequence, &model);
  out.message = std::string(name) + ": probing did not contract after " + std::to_string(corrections) +
                " corrections, finished by the LCP sequence (" + std::to_string(out.iterations) + " LCPs)" +
                (out.message.empty() ? "" : ": " + out.message);
  out.iterations += corrections;
  return out;
}

// Whether an iterate lies within the step's separation margin m of Broms eq. 27's distances:
// every flagged pair at d >= d_hat (1 - m) (separated, as the step counts it) and every pushed
// pair at d <= d_hat (1 + m) (held, not flung apart: a far root's pairs end many d_hat apart).
template <Shape S, MobilityOperator M>
bool within_separation_margin(const ContactStep<S, M>& step, const VecX& lambda, const VecX& distances) {
  const double m = step.options().separation_margin, d_hat = step.problem().d_hat;
  for (Eigen::Index k = 0; k < lambda.size(); ++k)
    if (!step.separated(distances(k)) || (lambda(k) > 0.0 && distances(k) > d_hat * (1.0 + m))) return false;
  return true;
}

// What a round may do besides its corrections: search rays for a nearer root, and check the
// end early (DefectCorrectionOptions::early_end_check). A round started again does neither twice.
struct RoundChoices {
  bool search_rays = true;
  bool early_end_check = true;
};

template <Shape S, MobilityOperator M, class Subproblem>
ContactSolveOutcome solve_defect_correction_round(ContactStep<S, M>& step, VecX lambda,
                                                  const DefectCorrectionOptions& options, const Subproblem& subproblem,
                                                  RoundChoices choices = {});

// The round again from lambda(s) of the ray, its first crossing found by ray_first_crossing
// (no further ray search): its result when it separates with no more total force, else
// lambda(s) itself, which separates. `before`: the corrections spent so far.
template <Shape S, MobilityOperator M, class Subproblem>
ContactSolveOutcome restart_from_crossing(ContactStep<S, M>& step, const ForceRay& ray, double s, int before,
                                          const DefectCorrectionOptions& options, const Subproblem& subproblem,
                                          const std::string& why) {
  const VecX start = ray.lambda(s);
  ContactSolveOutcome out = solve_defect_correction_round(step, start, options, subproblem, {false, false});
  const bool kept = out.converged && step.evaluate(out.lambda).min_distance() >= step.problem().d_hat &&
                    out.lambda.sum() <= start.sum();
  if (!kept) {
    out.lambda = start;
    out.converged = true;  // separated (the crossing), no force beyond the ray's smallest
  }
  out.iterations += before;
  const bool whole = ray.base.isZero(0.0);
  out.message = std::string(subproblem.name) + ": " + why + ", first crossing of d_hat at " + std::to_string(s) + " x " +
                (whole ? "lambda" : "the unseparated clusters' lambda") + (kept ? ", polished" : "");
  return out;
}

// One round from the warm start (the previous round's lambda, zero-padded); `subproblem`
// solves each correction's problem on the working set (WorkingSetLcp for the default solver).
template <Shape S, MobilityOperator M, class Subproblem>
ContactSolveOutcome solve_defect_correction_round(ContactStep<S, M>& step, VecX lambda,
                                                  const DefectCorrectionOptions& options, const Subproblem& subproblem,
                                                  RoundChoices choices) {
  if (lambda.size() != step.nc())
    fail_argument("lambda", "has " + std::to_string(lambda.size()) + " entries for " + std::to_string(step.nc()) +
                                " flagged pairs (a warm start from before pairs were added? pad it: detail::padded)");
  const bool search_rays = choices.search_rays;
  ContactSolveOutcome out;
  const double ray_tol = 1e-9;  // relative width of a crossing's bracket: the samples are cheap
  int stalled = 0;
  const double d_hat = step.problem().d_hat, target = d_hat * (1.0 + options.margin);
  const double radius = step.cost() != MobilityCost::matrix_free  // formed and blocks: exact
                            ? std::numeric_limits<double>::infinity()
                            : options.probe_radius_factor * largest_bounding_radius(step.problem().shapes);
  DelassusProbing probing(step, radius);
  // (Convex shapes only: between non-convex ones the closest points jump from arm to arm, and
  // the derivative at one iterate says little about the next; interlocked boomerangs stalled.)
  const bool exact_model = !std::isfinite(radius) && step.dofs_per_body() == 3;
  const bool chord_bbpgd = options.bbpgd_on_exact_model && exact_model && step.cost() == MobilityCost::blocks;
  bool at_iterate = !chord_bbpgd && options.jacobian_at_iterate && step.cost() == MobilityCost::blocks && S::convex &&
                    !step.options().template surface_directions<S>();
  int slow_newton = 0;  // corrections in a row that did not contract with the Jacobian at the iterate
  double least_change = std::numeric_limits<double>::infinity();  // of lambda, relative, over the round
  double least_shortfall = std::numeric_limits<double>::infinity();
  SecantCorrection secant;
  std::vector<char> member(static_cast<std::size_t>(step.nc()), 0);
  const auto join = [&](std::vector<Eigen::Index>& joining, Eigen::Index k) {
    if (member[static_cast<std::size_t>(k)]) return;
    member[static_cast<std::size_t>(k)] = 1;
    joining.push_back(k);
  };
  VecX previous_lambda, previous_distances;
  // The model on W, recomputed when W grows: positive_definite(probing.matrix()). An exact
  // model of bodies that only translate (spheres in blocks and formed modes: dt D_W^T M D_W
  // from exact columns) is positive semi-definite by construction and is used as it is; it is
  // lifted (lifted_positive_definite) only when the LCPs on it fail, which a singular one (more
  // contacts than degrees of freedom) may make them. The sparse Cholesky factorisation that
  // checks a model for the lift was 15-30% of the step on jammed packings of 1000 spheres
  // (docs/results.md, "The exact model is not checked"). Bodies that turn keep the check: the
  // exact models of dense rods are mostly not positive definite (534 lifts in 40 steps of 400
  // rods at eta 0.45), and used as they are, the first of those steps failed at step 3 with
  // a pair at 0.985 d_hat after 50 corrections, where the lifted models ran all 40.
  Eigen::SparseMatrix<double> probed;
  bool probed_lifted = false;  // probed is positive_definite's answer
  double previous_shortfall = std::numeric_limits<double>::infinity();
  double best_shortfall = std::numeric_limits<double>::infinity();
  VecX best_lambda = lambda, best_MD, best_distances;  // best_MD: M D best_lambda
  int slow_corrections = 0;
  // separated_stall_corrections: the least shortfall and relative change of lambda so far, and
  // the corrections since either last fell below 0.9 of its least
  double progress_shortfall = std::numeric_limits<double>::infinity();
  double progress_change = std::numeric_limits<double>::infinity();
  int without_progress = 0;
  double last_change = 1.0;  // of lambda, relative to ||lambda||_inf: sets the next LCP's tolerance
  for (;;) {
    const ContactEvaluation& e = step.evaluate(lambda);
    if (options.early_end_check && choices.early_end_check && out.iterations == 1 &&
        step.cost() == MobilityCost::blocks &&
        static_cast<std::size_t>((lambda.array() > 0.0).count()) >= options.early_end_check_min_pushed &&
        step.add_pairs_closing_at(e) > 0) {
      ContactSolveOutcome again = solve_defect_correction_round(step, padded(lambda, step.nc()), options, subproblem,
                                                                {search_rays, false});
      again.iterations += out.iterations;
      return again;
    }
    // The working set: every pair below the target or pushed...
    std::vector<Eigen::Index> joining;
    for (Eigen::Index k = 0; k < step.nc(); ++k)
      if (e.distances(k) < target || lambda(k) > 0.0) join(joining, k);
    // Secant pairs from the second correction on (the first is far from linear); a correction
    // that made the worst shortfall grow shows the model is not to be trusted (line contacts
    // whose closest points jump, e.g. parallel rods): the memory is dropped.
    const double shortfall = std::max(0.0, target - e.min_distance());
    if (shortfall > previous_shortfall) {
      secant.clear();
    } else if (out.iterations > 1) {
      secant.add(lambda - previous_lambda, e.distances - previous_distances);
    }
    // Probes shared by contacts whose coupling is not small (large dense clusters, where the
    // far fields of many contacts add up) give a model too poor to contract: after two
    // corrections that did not halve the shortfall, the round is finished by the LCP sequence
    // with exact (matrix-free) products, from the best iterate.
    if (shortfall < best_shortfall) {
      best_shortfall = shortfall;
      best_lambda = lambda;
      best_MD = e.MD_lambda;
      best_distances = e.distances;
    }
    // (With every probe a single contact the model is exact, and slowness is the geometry's.)
    const bool shared_probes = std::isfinite(radius) && probing.probes() < static_cast<int>(probing.members().size());
    slow_corrections = shared_probes && shortfall > options.contraction * previous_shortfall ? slow_corrections + 1 : 0;
    if (slow_corrections == 2) return finish_by_lcp_sequence(step, best_lambda, out.iterations, probed, probing.members(), options,
                                                         subproblem.name);
    // Corrections that stall with exact single-contact probes: the linear model points the
    // wrong way (d falls along the force before it rises, non-convex contacts). The best
    // iterate's ray through the clusters not yet separated (stalled_cluster_ray) is doubled until it
    // separates (free, see above), then searched back for its first crossing.
    stalled = !shared_probes && out.iterations > 0 && shortfall > options.contraction * previous_shortfall
                  ? stalled + 1 : 0;
    if (search_rays && stalled == options.stall_corrections && best_lambda.sum() > 0.0) {
      // (evaluating best_lambda again would overwrite e: its M D and distances were kept)
      const ForceRay ray = stalled_cluster_ray(step, best_lambda, best_MD, best_distances, target);
      for (double s_max = 2.0; s_max <= 1024.0; s_max *= 2.0)
        if (step.separated_at(ray.MD(s_max), target)) {
          if (const std::optional<double> s =
                  ray_first_crossing(step, ray, s_max, target, 2 * options.ray_samples, ray_tol))
            return restart_from_crossing(step, ray, *s, out.iterations, options, subproblem,
                                         "corrections stalled " + std::to_string(stalled) + " times");
          break;
        }
    }
    // No progress, but within the step's separation margin: that iterate is the round's answer
    // (not converged), and the guarantee loop checks it like any other.
    const bool progress = shortfall < 0.9 * progress_shortfall ||
                          (out.iterations > 0 && last_change < 0.9 * progress_change);
    progress_shortfall = std::min(progress_shortfall, shortfall);
    if (out.iterations > 0) progress_change = std::min(progress_change, last_change);
    without_progress = progress ? 0 : without_progress + 1;
    if (options.separated_stall_corrections > 0 && without_progress >= options.separated_stall_corrections &&
        within_separation_margin(step, lambda, e.distances)) {
      out.message = std::string(subproblem.name) + ": no progress in " + std::to_string(without_progress) +
                    " corrections inside the separation margin, min flagged d / d_hat = " +
                    std::to_string(e.min_distance() / d_hat) + " (returned as it is)";
      break;
    }
    previous_shortfall = shortfall;
    VecX next;
    const Correction correction{out.iterations,
                                correction_lcp_tolerance(options, last_change,
                                                         chord_bbpgd ? options.exact_model_lcp_tolerance_max
                                                                     : options.lcp_tolerance_max)};
    for (;;) {
      probing.add(step, joining);
      const std::vector<Eigen::Index>& W = probing.members();
      // The secant-corrected model is not symmetric; should its LCP fail, the probed one (made
      // positive definite, at once or, an exact model, below) is a strictly convex QP.
      if (probed.rows() != static_cast<Eigen::Index>(W.size())) {
        probed = exact_model ? probing.matrix() : positive_definite(probing.matrix());
        probed_lifted = !exact_model;
      }
      // The Jacobian at the iterate need not be a P-matrix (its LCP may have no solution):
      // then the secant-corrected model, then the probed one; an exact model that was not
      // positive definite is then lifted, and the three tried again.
      std::optional<VecX> solved;
      const auto solve_on_models = [&] {
        if (chord_bbpgd) {
          Correction exact = correction;
          exact.exact_symmetric_model = true;
          solved = subproblem(probed, W, lambda, e.distances, target, exact);
          if (solved) return;
        }
        if (at_iterate && lambda.sum() > 0.0)
          solved = subproblem(IterateJacobianModel{probed, iterate_jacobian(step, e, W)}, W, lambda, e.distances,
                              target, correction);
        if (!solved) solved = subproblem(secant.corrected(probed, W), W, lambda, e.distances, target, correction);
        if (!solved) solved = subproblem(probed, W, lambda, e.distances, target, correction);
      };
      solve_on_models();
      if (!solved && !probed_lifted) {
        probed_lifted = true;
        if (Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>(probed).info() != Eigen::Success) {
          probed = lifted_positive_definite(probed);
          solve_on_models();
        }
      }
      if (!solved) {
        out.message = std::string(subproblem.name) + ": the working-set problem (" + std::to_string(W.size()) +
                      " pairs) was not solved";
        out.lambda = std::move(lambda);
        return out;
      }
      next = std::move(*solved);
      // ... and every pair the model predicts the new lambda brings below it (free: the probes
      // already hold those rows).
      joining.clear();
      VecX change_W(static_cast<Eigen::Index>(W.size()));
      for (std::size_t r = 0; r < W.size(); ++r) change_W(static_cast<Eigen::Index>(r)) = next(W[r]) - lambda(W[r]);
      const VecX predicted = e.distances + probing.rows_times(change_W);
      for (Eigen::Index k = 0; k < step.nc(); ++k)
        if (!member[static_cast<std::size_t>(k)] && predicted(k) < target) join(joining, k);
      if (joining.empty()) break;
    }
    const double change = (next - lambda).lpNorm<Eigen::Infinity>();
    const double scale = std::max(next.lpNorm<Eigen::Infinity>(), lambda.lpNorm<Eigen::Infinity>());
    // Newton's method without a globalisation: where two corrections in a row bring neither
    // the shortfall nor the change of lambda below half its least value so far in the round
    // (iterates cycling about a far root of turning rods), the round goes on with the model at
    // Q* and its secants.
    const double relative_change = scale > 0.0 ? change / scale : 1.0;
    if (at_iterate && out.iterations > 1) {
      const bool contracted = shortfall < options.contraction * least_shortfall ||
                              relative_change <= options.contraction * least_change;
      slow_newton = contracted ? 0 : slow_newton + 1;
      if (slow_newton == 2) {
        at_iterate = false;
        secant.clear();  // steps of another model's iteration
      }
    }
    if (out.iterations > 0) least_change = std::min(least_change, relative_change);
    least_shortfall = std::min(least_shortfall, shortfall);
    last_change = relative_change;
    if (e.min_distance() >= d_hat && change <= options.tol * scale) {  // Broms eq. 29 at a separated iterate
      // A smaller separating force on the same ray (a far root of a non-monotone d): the
      // samples before s = 1 only (s = j / ray_samples, j < ray_samples), so a monotone d
      // costs them and nothing else (no bisection towards s = 1, whose crossing is lambda's).
      const int below_one = options.ray_samples - 1;
      if (search_rays && lambda.sum() > 0.0 &&
          !ray_held_below_target(step, e.distances, target, double(below_one) / options.ray_samples)) {
        const ForceRay ray = ForceRay::through(lambda, e.MD_lambda);
        const std::optional<double> s =
            ray_first_crossing(step, ray, double(below_one) / options.ray_samples, target, below_one, ray_tol);
        if (s && *s < 1.0 - 1.0 / options.ray_samples)
          return restart_from_crossing(step, ray, *s, out.iterations, options, subproblem, "converged to a far root");
      }
      out.converged = true;
      break;
    }
    if (out.iterations == options.max_iterations) {
      // Shared probes whose corrections contract, but too slowly to finish (a large cluster
      // whose shortfall halves every other correction): the exact products finish the round.
      if (shared_probes) return finish_by_lcp_sequence(step, best_lambda, out.iterations, probed, probing.members(), options,
                                                         subproblem.name);
      out.message = std::string(subproblem.name) + ": " + std::to_string(out.iterations) + " corrections, min flagged d / d_hat = " +
                    std::to_string(e.min_distance() / d_hat) + ", last change " + std::to_string(change / scale) +
                    " of ||lambda||_inf";
      break;
    }
    ++out.iterations;
    previous_lambda = lambda;
    previous_distances = e.distances;
    lambda = std::move(next);
  }
  out.lambda = std::move(lambda);
  return out;
}

}  // namespace detail

template <Shape S, MobilityOperator M>
ContactStepResult solve_contact_step_defect_correction(const ContactStepProblem<S>& problem, M& mobility,
                                             const ContactStepOptions& options = {},
                                             const DefectCorrectionOptions& solver = {}) {
  solver.validate();
  return run_contact_step(problem, mobility, options, [&solver](ContactStep<S, M>& step, const VecX& warm) {
    return detail::solve_defect_correction_round(step, warm, solver, detail::WorkingSetLcp{solver.lcp});
  });
}

}  // namespace stokescontact
