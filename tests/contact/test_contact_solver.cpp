// Choosing a contact solver by value (contact/solvers/contact_solver.hpp): names round-trip,
// unknown names are refused with the list, solve_contact_step runs exactly the chosen solver,
// and the paths and names that moved in 0.2 still work.
#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/mobility/free_draining.hpp"

// The pre-0.2 paths: forwarding headers.
#include "stokescontact/contact/lcp.hpp"
#include "stokescontact/contact/lcp_apgd.hpp"
#include "stokescontact/contact/lcp_bbpgd.hpp"
#include "stokescontact/contact/lcp_minimum_map_newton.hpp"
#include "stokescontact/contact/delassus_probing.hpp"
#include "stokescontact/contact/secant_update.hpp"
#include "stokescontact/contact/solver_barrier_nlopt.hpp"
#include "stokescontact/contact/solver_default.hpp"
#include "stokescontact/contact/solver_lcp_sequence.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace contact_solver_tests {

namespace sc = stokescontact;

namespace {

using test_support::expect_rejects;

// Three unit spheres in a row, gaps 0.1, the outer ones driven inwards: two contacts.
struct Row {
  std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  std::vector<sc::Pose> poses{{sc::Vec3(0, 0, 0), sc::Quat::Identity()},
                              {sc::Vec3(2.1, 0, 0), sc::Quat::Identity()},
                              {sc::Vec3(4.2, 0.3, 0), sc::Quat::Identity()}};
  sc::VecX U = (sc::VecX(9) << 20, 0, 0, 0, 0, 0, -20, 0, 0).finished();

  sc::FreeDrainingMobility mobility() const { return {sc::sphere_mobility(shapes[0], 1.0), poses.size(), 3}; }
  sc::ContactStepProblem<sc::Sphere> problem() const {
    return {.shapes = shapes, .poses = poses, .U = U, .dt = 0.01, .d_hat = 0.01};
  }
};

TEST(ContactSolver, NamesRoundTripAndTheDefaultComesFirst) {
  const std::vector<std::string> names = sc::contact_solver_names();
  ASSERT_FALSE(names.empty());
  EXPECT_EQ(names.front(), "default");
  EXPECT_EQ(names.size(), 8u);  // this build has NLopt: four barrier variants
  for (const std::string& name : names) EXPECT_EQ(sc::contact_solver_name(sc::contact_solver_from_name(name)), name);
  EXPECT_TRUE(std::holds_alternative<sc::DefectCorrectionOptions>(sc::ContactSolver{}));
  EXPECT_EQ(std::get<sc::LcpSequenceOptions>(sc::contact_solver_from_name("lcp-apgd")).inner, sc::InnerLcpSolver::apgd);
  EXPECT_EQ(std::get<sc::BarrierNloptOptions>(sc::contact_solver_from_name("barrier-mma")).optimizer,
            sc::BarrierOptimizer::mma);
}

TEST(ContactSolver, UnknownNameIsRefusedWithTheKnownNames) {
  expect_rejects([] { (void)sc::contact_solver_from_name("lcp-gauss-seidel"); }, "solver");
  try {
    (void)sc::contact_solver_from_name("Default");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("default, lcp-bbpgd"), std::string::npos) << e.what();
  }
}

TEST(ContactSolver, StoppingToleranceIsTheSolversOwn) {
  sc::ContactSolver s = sc::contact_solver_from_name("default");
  EXPECT_EQ(sc::stopping_tolerance(s), sc::DefectCorrectionOptions{}.tol);
  sc::set_stopping_tolerance(s, 1e-6);
  EXPECT_EQ(std::get<sc::DefectCorrectionOptions>(s).tol, 1e-6);
  sc::ContactSolver lcp = sc::contact_solver_from_name("lcp-newton");
  EXPECT_FALSE(sc::stopping_tolerance(lcp).has_value());  // stops at its first separated iterate
  sc::set_stopping_tolerance(lcp, 1e-3);
  EXPECT_EQ(sc::stopping_tolerance(lcp), 1e-3);
  expect_rejects([&] { sc::set_stopping_tolerance(s, 0.0); }, "tol");
}

// solve_contact_step with a value runs that solver: the same result as calling it directly.
TEST(ContactSolver, SolveContactStepRunsTheChosenSolver) {
  const Row row;
  for (const std::string& name : sc::contact_solver_names()) {
    if (name == "barrier-cobyla") continue;  // derivative free: correct but slow, covered elsewhere
    SCOPED_TRACE(name);
    const sc::ContactSolver solver = sc::contact_solver_from_name(name);
    auto m1 = row.mobility();
    const sc::ContactStepResult chosen = sc::solve_contact_step(row.problem(), m1, {}, solver);
    auto m2 = row.mobility();
    const sc::ContactStepResult direct = std::visit(
        [&](const auto& o) {
          using O = std::decay_t<decltype(o)>;
          if constexpr (std::is_same_v<O, sc::DefectCorrectionOptions>)
            return sc::solve_contact_step_defect_correction(row.problem(), m2, {}, o);
          else if constexpr (std::is_same_v<O, sc::LcpSequenceOptions>)
            return sc::solve_contact_step_lcp_sequence(row.problem(), m2, {}, o);
          else
            return sc::solve_contact_step_barrier(row.problem(), m2, {}, o);
        },
        solver);
    EXPECT_EQ(chosen.status, direct.status);
    EXPECT_EQ(chosen.lambda, direct.lambda);
    EXPECT_EQ(chosen.mobility_applications, direct.mobility_applications);
    EXPECT_EQ(chosen.flagged_pairs, 2u);
    // NLopt's MMA ends this row unseparated after 1000 evaluations (min d / d_hat 0.84,
    // reported as failed_separation): the barrier optimiser's own open issue.
    if (name == "barrier-mma") continue;
    EXPECT_EQ(chosen.status, sc::ContactStepStatus::converged) << chosen.message;
    EXPECT_GE(chosen.min_distance_ratio, 1.0 - 1e-3);
  }
  // No solver given: the default (defect correction).
  auto m1 = row.mobility();
  auto m2 = row.mobility();
  EXPECT_EQ(sc::solve_contact_step(row.problem(), m1).lambda,
            sc::solve_contact_step_defect_correction(row.problem(), m2).lambda);
}

// The names of 0.1 keep working for one release.
// A step refused before its solve (ContactStepOptions::max_flagged_pairs_per_body; here 2
// pairs of 3 bodies against a limit of 0.5 per body) is refused by every solver alike: the
// default solver returns it without trying its fallbacks.
TEST(ContactSolver, ARefusedStepIsNotSolvedAgain) {
  const Row row;
  auto mobility = row.mobility();
  sc::ContactStepOptions options;
  options.max_flagged_pairs_per_body = 0.5;
  const sc::ContactStepResult r = sc::solve_contact_step(row.problem(), mobility, options);
  EXPECT_EQ(r.status, sc::ContactStepStatus::failed_separation);
  EXPECT_TRUE(r.refused);
  EXPECT_TRUE(r.fallback.empty());
  EXPECT_EQ(r.message.find("tried on this step"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("2 flagged body pairs for 3 bodies"), std::string::npos) << r.message;
  options.max_flagged_pairs_per_body = 1.0;
  EXPECT_EQ(sc::solve_contact_step(row.problem(), mobility, options).status, sc::ContactStepStatus::converged);
}

TEST(ContactSolver, DeprecatedNamesStillWork) {
  const Row row;
  auto m1 = row.mobility();
  auto m2 = row.mobility();
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
  const sc::DefaultSolverOptions options;
  const sc::ContactStepResult old = sc::solve_contact_step_default(row.problem(), m1, {}, options);
#pragma GCC diagnostic pop
  EXPECT_EQ(old.lambda, sc::solve_contact_step(row.problem(), m2).lambda);
}

}  // namespace

// Broms eq. 15 on a working-set model (barrier_working_set.hpp) against its exact solution.
// A = [1 .6 0; .6 1 .6; 0 .6 1] (positive definite, not a Z-matrix: pushing the middle pair
// opens the outer ones), d = 0, target 1. Complementarity (the default solver's LCP) gives
// (1, 0, 1), sum 2, dissipation y^T A y = 2; the smallest sum with A y >= 1 is the vertex
// (0, 5/3, 0), sum 5/3, dissipation 25/9; the smallest dissipation is (1, 0, 1) again (KKT:
// 2 A y = A mu, mu = 2 y complementary to A y - 1 >= 0, y >= 0).
TEST(BarrierWorkingSet, ModelProblemIsTheSmallestSumOrDissipation) {
  const sc::MatX A = (sc::MatX(3, 3) << 1.0, 0.6, 0.0, 0.6, 1.0, 0.6, 0.0, 0.6, 1.0).finished();
  const std::vector<Eigen::Index> W{0, 1, 2};
  const sc::VecX zero = sc::VecX::Zero(3);
  const auto lcp = sc::detail::solve_working_set_lcp(A, W, zero, zero, 1.0, sc::LcpOptions{1e-12});
  ASSERT_TRUE(lcp.has_value());
  EXPECT_NEAR((*lcp - sc::Vec3(1.0, 0.0, 1.0)).norm(), 0.0, 1e-10);
  for (const nlopt::algorithm algorithm : {nlopt::LD_SLSQP, nlopt::LD_MMA}) {
    SCOPED_TRACE(algorithm == nlopt::LD_SLSQP ? "slsqp" : "mma");
    sc::detail::WorkingSetBarrier sum{algorithm, false};
    const auto y = sum(A, W, zero, zero, 1.0, {});
    ASSERT_TRUE(y.has_value());
    EXPECT_NEAR((*y - sc::Vec3(0.0, 5.0 / 3.0, 0.0)).norm(), 0.0, 1e-6) << y->transpose();
    const sc::VecX separation = A * *y;  // (a named product: GCC 12 misreads the temporary as used after free)
    EXPECT_GE(separation.minCoeff(), 1.0 - 1e-6);
    sc::detail::WorkingSetBarrier dissipation{algorithm, true};
    const auto z = dissipation(A, W, zero, zero, 1.0, {});
    ASSERT_TRUE(z.has_value());
    EXPECT_NEAR((*z - sc::Vec3(1.0, 0.0, 1.0)).norm(), 0.0, 1e-6) << z->transpose();
  }
  // The working-set form takes SLSQP only (MMA: minutes per step on dense packings).
  sc::BarrierNloptOptions mma;
  mma.constraint = sc::BarrierConstraint::working_set;
  mma.optimizer = sc::BarrierOptimizer::mma;
  expect_rejects([&] { mma.validate(); }, "BarrierNloptOptions.optimizer");
  // Nothing below the target: no force, no NLopt call.
  sc::detail::WorkingSetBarrier sum;
  const auto none = sum(A, W, zero, sc::VecX::Constant(3, 2.0), 1.0, {});
  ASSERT_TRUE(none.has_value());
  EXPECT_EQ(none->norm(), 0.0);
}

}  // namespace contact_solver_tests
