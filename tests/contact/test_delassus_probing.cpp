// The probed Delassus matrix (delassus_probing.hpp) against the exact dt D^T M D, and the
// multisecant correction (secant_update.hpp) against its defining conditions.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/solvers/delassus_probing.hpp"
#include "stokescontact/contact/solvers/secant_update.hpp"
#include "stokescontact/contact/solvers/defect_correction.hpp"
#include "stokescontact/contact/solvers/lcp_sequence.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/rpy_mobility.hpp"

namespace sc = stokescontact;

namespace {

// Two clusters of three spheres in a row, 30 apart, every neighbour pair a contact at the
// trial step (gap 0.01, at rest): 4 contacts, two per cluster.
struct TwoClusters {
  std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  std::vector<sc::Pose> poses;
  sc::VecX U;
  TwoClusters() {
    for (double x0 : {0.0, 30.0})
      for (int k = 0; k < 3; ++k) poses.push_back({sc::Vec3(x0 + 2.01 * k, 0.3 * k, 0.0), sc::Quat::Identity()});
    U = sc::VecX::Zero(3 * static_cast<Eigen::Index>(poses.size()));
  }
  sc::ContactStepProblem<sc::Sphere> problem() const { return {shapes, poses, U, 0.01, 0.005, 0.05, 1.0, {}}; }
};

// dt D^T M D on the given contacts, one exact column per application.
template <sc::MobilityOperator M>
sc::MatX exact_delassus(sc::ContactStep<sc::Sphere, M>& step, const std::vector<Eigen::Index>& contacts) {
  const auto n = static_cast<Eigen::Index>(contacts.size());
  sc::MatX A(n, n);
  for (Eigen::Index c = 0; c < n; ++c) {
    sc::VecX e = sc::VecX::Zero(step.nc());
    e(contacts[static_cast<std::size_t>(c)]) = 1.0;
    const sc::VecX column = step.problem().dt * (step.D().transpose() * step.MD_times(e));
    for (Eigen::Index r = 0; r < n; ++r) A(r, c) = column(contacts[static_cast<std::size_t>(r)]);
  }
  return A;
}

template <sc::MobilityOperator M>
void check_probing(M& mobility, double radius, int expected_probes, double tolerance) {
  const TwoClusters scene;
  sc::ContactStepOptions options;
  options.cost = sc::MobilityCost::matrix_free;
  sc::ContactStep<sc::Sphere, M> step(scene.problem(), mobility, options);
  ASSERT_EQ(step.nc(), 4);
  const std::vector<Eigen::Index> all = {0, 1, 2, 3};
  const sc::MatX exact = exact_delassus(step, all);
  const std::size_t before = mobility.applications();
  sc::DelassusProbing probing(step, radius);
  probing.add(step, std::vector<Eigen::Index>{0, 1, 2, 3});
  EXPECT_EQ(probing.probes(), expected_probes);
  EXPECT_EQ(mobility.applications() - before, static_cast<std::size_t>(expected_probes));
  EXPECT_EQ(probing.matrix(), probing.matrix().transpose());
  const double error = (probing.matrix() - exact).cwiseAbs().maxCoeff() / exact.cwiseAbs().maxCoeff();
  std::printf("[probing] radius %g: %d probes, max error %.3e of max |A|\n", radius, probing.probes(), error);
  EXPECT_LE(error, tolerance);
  // row(k) reads the probes as they are (before symmetrising): the same up to the error.
  for (Eigen::Index k = 0; k < 4; ++k)
    EXPECT_LE((probing.row(k) - exact.row(k).transpose()).cwiseAbs().maxCoeff(),
              tolerance * exact.cwiseAbs().maxCoeff());
}

TEST(DelassusProbing, InfiniteRadiusGivesTheExactMatrixOneColumnPerProbe) {
  sc::RpyMobility rpy(6, sc::RpyParameters{1.0, 1.0}, 3);
  check_probing(rpy, std::numeric_limits<double>::infinity(), 4, 1e-14);
}

// Without hydrodynamic interactions between bodies, contacts that share no body do not
// couple at all: sharing probes loses nothing, and the two clusters need two probes.
TEST(DelassusProbing, FreeDrainingSharedProbesAreExact) {
  sc::FreeDrainingMobility free(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), 6, 3);
  check_probing(free, 8.0, 2, 1e-14);
}

// With RPY the clusters, 30 apart, couple weakly: the shared probes pick up their far field,
// and the cross-cluster entries are dropped; both are small against the near entries.
TEST(DelassusProbing, RpySharedProbesLoseOnlyTheFarField) {
  sc::RpyMobility rpy(6, sc::RpyParameters{1.0, 1.0}, 3);
  check_probing(rpy, 8.0, 2, 1e-2);
}

TEST(DelassusProbing, RejectsANonPositiveRadius) {
  const TwoClusters scene;
  sc::FreeDrainingMobility free(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), 6, 3);
  sc::ContactStep<sc::Sphere, sc::FreeDrainingMobility> step(scene.problem(), free, {});
  test_support::expect_rejects([&] { sc::DelassusProbing(step, 0.0); }, "probe radius");
  test_support::expect_rejects([&] { sc::DelassusProbing(step, NAN); }, "probe radius");
}

// A0 + (Y - A0 S) S^+ maps every step to its change and leaves A0 on the complement of span(S).
TEST(SecantCorrection, HonoursEverySecantAndKeepsA0Elsewhere) {
  std::mt19937_64 rng(7);
  const Eigen::Index n = 8;
  const auto random_matrix = [&](Eigen::Index rows, Eigen::Index cols) {
    sc::MatX m(rows, cols);
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = test_support::uniform(rng, -1.0, 1.0);
    return m;
  };
  const sc::MatX A0 = random_matrix(n, n), A = random_matrix(n, n);
  // The working set: 5 of 8 entries of the full space, steps supported on it.
  const std::vector<Eigen::Index> rows = {1, 2, 4, 6, 7};
  sc::SecantCorrection secant;
  sc::MatX S = sc::MatX::Zero(5, 3);
  for (int l = 0; l < 3; ++l) {
    sc::VecX s = sc::VecX::Zero(n);
    for (std::size_t r = 0; r < rows.size(); ++r) s(rows[r]) = test_support::uniform(rng, -1.0, 1.0);
    secant.add(s, A * s);
    for (std::size_t r = 0; r < rows.size(); ++r) S(static_cast<Eigen::Index>(r), l) = s(rows[r]);
  }
  secant.add(sc::VecX::Zero(n), sc::VecX::Ones(n));  // no information: ignored
  EXPECT_EQ(secant.size(), 3u);
  sc::MatX A0_W(5, 5), A_W(5, 5);
  for (Eigen::Index r = 0; r < 5; ++r)
    for (Eigen::Index c = 0; c < 5; ++c) {
      A0_W(r, c) = A0(rows[static_cast<std::size_t>(r)], rows[static_cast<std::size_t>(c)]);
      A_W(r, c) = A(rows[static_cast<std::size_t>(r)], rows[static_cast<std::size_t>(c)]);
    }
  const sc::MatX corrected = secant.corrected(A0_W, rows);
  EXPECT_LE((corrected * S - A_W * S).cwiseAbs().maxCoeff(), 1e-12);
  // A direction orthogonal to every step.
  const Eigen::HouseholderQR<sc::MatX> qr(S);
  const sc::VecX orthogonal = sc::MatX(qr.householderQ()).col(4);
  EXPECT_LE((S.transpose() * orthogonal).norm(), 1e-12);
  EXPECT_LE((corrected * orthogonal - A0_W * orthogonal).norm(), 1e-12);
  secant.clear();
  EXPECT_EQ(secant.corrected(A0_W, rows), A0_W);
}

}  // namespace

namespace {

TEST(PositiveDefinite, KeepsADefiniteMatrixAndLiftsAnIndefiniteOne) {
  sc::MatX A(3, 3);
  A << 2, 1, 0, 1, 2, 0, 0, 0, 1;
  EXPECT_EQ(sc::detail::positive_definite(A), A);
  sc::MatX B(2, 2);
  B << 1, 2, 2, 1;  // eigenvalues 3 and -1, eigenvectors (1, 1) and (1, -1) / sqrt 2
  const sc::MatX lifted = sc::detail::positive_definite(B, 1e-3);
  sc::MatX expected(2, 2);
  expected << 1.5 + 1.5e-3, 1.5 - 1.5e-3, 1.5 - 1.5e-3, 1.5 + 1.5e-3;  // eigenvalues 3 and 3e-3
  EXPECT_LE((lifted - expected).cwiseAbs().maxCoeff(), 1e-14);
}

// A hard case: a simple-cubic lattice (5^3 spheres, gaps 0.01, phi ~ 0.52) squeezed towards
// its centre, RPY mobility, matrix free: hundreds of contacts in one cluster, where probes
// cannot be shared much and the probed model may be indefinite. The default must separate it
// at complementarity, with no more force than the LCP sequence (which stops at its first
// separated iterate and overshoots).
TEST(DefaultSolver, SqueezedLatticeIsSeparatedAtComplementarity) {
  std::vector<sc::Pose> poses;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = 0; k < 5; ++k) poses.push_back({2.01 * sc::Vec3(i, j, k), sc::Quat::Identity()});
  std::mt19937_64 rng(5);
  sc::VecX U(3 * static_cast<Eigen::Index>(poses.size()));
  for (std::size_t b = 0; b < poses.size(); ++b)
    U.segment<3>(3 * static_cast<Eigen::Index>(b)) =
        -2.0 * (poses[b].x - sc::Vec3::Constant(4.02)) + test_support::random_unit_vector(rng);
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  const sc::ContactStepProblem<sc::Sphere> p{shapes, poses, U, 0.01, 0.005, 0.0, 1.0, {}};
  sc::ContactStepOptions options;
  options.cost = sc::MobilityCost::matrix_free;
  sc::RpyMobility m1(poses.size(), sc::RpyParameters{1.0, 1.0}, 3), m2 = m1;
  const sc::ContactStepResult def = sc::solve_contact_step_defect_correction(p, m1, options);
  const sc::ContactStepResult lcp = sc::solve_contact_step_lcp_sequence(p, m2, options);
  for (const sc::ContactStepResult* r : {&def, &lcp})
    std::printf("[lattice] status %d Nc %zu apps %zu iters %d sum %.6f min d/d_hat %.9f compl %.2e\n",
                static_cast<int>(r->status), r->flagged_pairs, r->mobility_applications, r->iterations, r->lambda_sum,
                r->min_distance_ratio, r->complementarity_residual);
  EXPECT_EQ(def.status, sc::ContactStepStatus::converged) << def.message;
  EXPECT_GE(def.flagged_pairs, 200u);
  EXPECT_GE(def.min_distance_ratio, 1.0 - 1e-9);
  EXPECT_LE(def.complementarity_residual, 1e-3);
  EXPECT_EQ(lcp.status, sc::ContactStepStatus::converged) << lcp.message;
  EXPECT_LE(def.lambda_sum, lcp.lambda_sum * (1.0 + 1e-3));
}

}  // namespace
