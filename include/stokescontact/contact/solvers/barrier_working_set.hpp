#pragma once
// Broms & Tornberg eq. 15 on the default solver's working set, with NLopt:
//     min_{lambda >= 0} ||lambda||   s.t.   E(lambda) = sum_k b(d_k(Q(lambda))) = 0,
// ||lambda|| the sum of lambda or the dissipation (eq. 14). Since b >= 0 and b(d) = 0 exactly
// for d >= d_hat (eq. 10), E = 0 holds exactly when every flagged pair has d_k >= d_hat: the
// same feasible set written pair by pair, which tells the optimiser which pairs are active
// (the scalar E hides it, and its gradient vanishes on the boundary, b'(d_hat) = 0; that is
// what makes the paper's form cost hundreds of evaluations, barrier_nlopt.hpp).
//
// The problem is solved by the default solver's defect correction (defect_correction.hpp):
// each correction poses eq. 15 on the linear model of the working set W about the current
// iterate lambda_k,
//     min_{y >= 0} ||y||   s.t.   d_W(lambda_k) + A~ (y - lambda_k,W) >= d_hat (1 + margin),
// (A~ the probed dt D^T M D on W, exact in formed and blocks modes), NLopt solves it with no
// mobility application, and the true distances at the new lambda (one application) correct
// the next model. At a fixed point the true distances satisfy every constraint, and the active
// pairs' are held exactly, so the returned lambda separates (measured, never predicted).
//
// Each model problem starts from its LCP solution (the default solver's correction), which is
// feasible and is the minimum of the sum where A~ is a Z-matrix (pushing one pair never moves
// another apart); NLopt then lowers the objective where it is not (a pair pushed that ends
// apart, because its push opens others). A result of NLopt that is not feasible in the model to 1e-6
// target (1% of the default margin 1e-4: the true distances decide separation, measured), or
// not below the start's objective, is replaced by the start.
//
// The smallest sum is a vertex of the model's feasible set, and it can jump between vertices
// as the corrections change the model (measured: a dense packing at 55%, formed mode, where 50
// corrections alternated between vertices 0.3 d_hat short; and with probed models, where the
// vertex follows the probing error, 2 of 200 Fig. 4 configurations at 24% whose corrections
// stopped contracting). Two safeguards, both reported in the round's message: from correction
// `smallest_sum_corrections` on, a round takes the LCP solution, which contracts like the
// default solver's; and a round that still does not converge is solved again from its warm
// start by the default solver's corrections (solve_contact_step_barrier). The result is then
// the complementarity solution: separated, with the default solver's force.
//
// Cost: the default solver's applications; NLopt's evaluations are dense products with A~ on
// W (O(|W|^2) each, O(|W|^3) per SLSQP iteration), none a mobility application. Only pairs of W
// carry force: the dissipation objective is minimised over them (a flagged pair that no
// correction brings below the target gets none).
#include <algorithm>
#include <cmath>
#include <exception>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <nlopt.hpp>

#include "stokescontact/contact/solvers/defect_correction.hpp"

namespace stokescontact::detail {

// One correction's eq. 15 on the working set (the subproblem of solve_defect_correction_round).
struct WorkingSetBarrier {
  nlopt::algorithm algorithm = nlopt::LD_SLSQP;
  bool dissipation = false;  // objective y^T A~ y (eq. 14 with M), else sum y
  int max_evaluations = 1000;
  LcpOptions lcp{1e-12};  // the start's LCP (its tolerance the correction's)
  std::string_view name = "barrier (working set)";

  int smallest_sum_corrections = 10;  // corrections that pose eq. 15; the LCP after them
  mutable int complementarity_corrections = 0;  // corrections of the round that took the LCP

  template <LcpMatrixOperator Model>
  std::optional<VecX> operator()(const Model& A, std::span<const Eigen::Index> W, const VecX& lambda,
                                 const VecX& distances, double target, const Correction& correction) const {
    LcpOptions inexact = lcp;
    inexact.tolerance = correction.lcp_tolerance;
    std::optional<VecX> start = solve_working_set_lcp(A, W, lambda, distances, target, inexact);
    if (!start) return std::nullopt;
    if (correction.number >= smallest_sum_corrections) {
      ++complementarity_corrections;
      return start;
    }
    const auto n = static_cast<Eigen::Index>(W.size());
    VecX y0(n), lambda_W(n), d_W(n);
    for (Eigen::Index r = 0; r < n; ++r) {
      const Eigen::Index k = W[static_cast<std::size_t>(r)];
      y0(r) = (*start)(k);
      lambda_W(r) = lambda(k);
      d_W(r) = distances(k);
    }
    const double scale = y0.size() == 0 ? 0.0 : y0.maxCoeff();
    if (!(scale > 0.0)) return start;  // no force needed: the sum's and the dissipation's minimum
    MatX AW(n, n);  // the model on W, dense: n products, no mobility application
    if constexpr (is_eigen_matrix<Model>) {
      AW = MatX(A);
    } else {
      for (Eigen::Index j = 0; j < n; ++j) AW.col(j) = A(VecX(VecX::Unit(n, j)));
    }
    // Constraints in x = y / scale, each <= 0: target - d_W - A~ (scale x - lambda_W), in units of target.
    Problem p{AW, (VecX::Constant(n, target) - d_W + AW * lambda_W) / target, scale / target, dissipation,
              dissipation ? 1.0 / std::max(y0.dot(AW * y0) / (scale * scale), 1e-300) : 1.0};
    nlopt::opt opt(algorithm, static_cast<unsigned>(n));
    opt.set_min_objective(&Problem::objective, &p);
    opt.add_inequality_mconstraint(&Problem::constraints, &p, std::vector<double>(static_cast<std::size_t>(n), 1e-12));
    opt.set_lower_bounds(0.0);
    opt.set_maxeval(max_evaluations);
    opt.set_xtol_rel(1e-12);
    opt.set_ftol_rel(1e-14);
    std::vector<double> x(static_cast<std::size_t>(n));
    for (Eigen::Index r = 0; r < n; ++r) x[static_cast<std::size_t>(r)] = y0(r) / scale;
    double f = 0.0;
    try {
      opt.optimize(x, f);
    } catch (const std::exception&) {  // roundoff_limited, forced stops: x holds NLopt's last point
    }
    const VecX y = scale * Eigen::Map<const VecX>(x.data(), n).cwiseMax(0.0);
    const double shortfall = (VecX::Constant(n, target) - d_W - AW * (y - lambda_W)).maxCoeff();
    if (!(shortfall <= 1e-6 * target) || !(p.value(y / scale) < p.value(y0 / scale))) return start;
    VecX next = VecX::Zero(lambda.size());
    for (Eigen::Index r = 0; r < n; ++r) next(W[static_cast<std::size_t>(r)]) = y(r);
    return next;
  }

 private:
  // The scaled model problem NLopt sees: min f(x) s.t. r - c A~ x <= 0, x >= 0.
  struct Problem {
    const MatX& A;
    VecX r;        // (target - d_W + A~ lambda_W) / target
    double c;      // scale / target
    bool dissipation;
    double unit;   // makes the dissipation O(1) at the start

    double value(const VecX& x) const {
      if (!dissipation) return x.sum();
      VecX Ax(x.size());
      Ax.noalias() = A * x;
      return unit * x.dot(Ax);
    }

    static double objective(unsigned n, const double* x, double* grad, void* data) {
      const auto& p = *static_cast<const Problem*>(data);
      const VecX xs = Eigen::Map<const VecX>(x, n);
      if (grad && !p.dissipation) std::fill(grad, grad + n, 1.0);
      if (grad && p.dissipation) {  // unit (A + A^T) x, written out (GCC 12 misreads the temporaries as used after free)
        VecX g(xs.size());
        g.noalias() = p.A * xs;
        g.noalias() += p.A.transpose() * xs;
        for (unsigned j = 0; j < n; ++j) grad[j] = p.unit * g(j);
      }
      return p.value(xs);
    }

    static void constraints(unsigned m, double* result, unsigned n, const double* x, double* grad, void* data) {
      const auto& p = *static_cast<const Problem*>(data);
      const VecX Ax = p.A * Eigen::Map<const VecX>(x, n);
      for (unsigned i = 0; i < m; ++i) result[i] = p.r(i) - p.c * Ax(i);
      if (grad)  // row-major m x n: d result_i / d x_j = -c A_ij
        for (unsigned i = 0; i < m; ++i)
          for (unsigned j = 0; j < n; ++j) grad[i * n + j] = -p.c * p.A(i, j);
    }
  };
};

}  // namespace stokescontact::detail
