// The probed Delassus matrix (delassus_probing.hpp) against the exact dt D^T M D, and the
// multisecant correction (secant_update.hpp) against its defining conditions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/solvers/delassus_probing.hpp"
#include "stokescontact/contact/solvers/secant_update.hpp"
#include "stokescontact/contact/solvers/defect_correction.hpp"
#include "stokescontact/contact/solvers/lcp_sequence.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/rpy_mobility.hpp"
#include "stokescontact/scenes/random.hpp"
#include "stokescontact/scenes/sphere_packing.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace delassus_probing_tests {

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
  const sc::MatX probed(probing.matrix());
  EXPECT_EQ(probed, probed.transpose());
  const double error = (probed - exact).cwiseAbs().maxCoeff() / exact.cwiseAbs().maxCoeff();
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

// At scale the model is sparse and, with free-draining bodies, exact wherever it reads: 3000
// spheres at packing 0.3 pushed at random; every entry between contacts closer than radius / 2
// against the exact column (one application each), every other entry 0, and O(1) entries per
// working-set contact.
TEST(DelassusProbing, FreeDrainingModelAtScaleIsSparseAndExactWhereRead) {
  const std::size_t n = 3000;
  const sc::SpherePacking packing = sc::random_sequential_addition(n, 0.3, 11);
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  sc::Rng rng(11);
  const std::vector<sc::Vec3> f = sc::random_forces(n, 100.0, rng);
  sc::FreeDrainingMobility free(sc::sphere_mobility(shapes[0], 1.0), n, 3);
  sc::VecX F(3 * static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k) F.segment<3>(3 * static_cast<Eigen::Index>(k)) = f[k];
  free.set_configuration(packing.poses);
  const sc::VecX U = free.apply(F);
  const sc::ContactStepProblem<sc::Sphere> problem{shapes, packing.poses, U, 0.01, 0.01};
  sc::ContactStepOptions options;
  options.cost = sc::MobilityCost::matrix_free;
  sc::ContactStep<sc::Sphere, sc::FreeDrainingMobility> step(problem, free, options);
  std::vector<Eigen::Index> W;  // the pairs the trial step brings below d_hat
  const sc::ContactEvaluation& trial = step.evaluate(sc::VecX::Zero(step.nc()));
  for (Eigen::Index k = 0; k < step.nc(); ++k)
    if (trial.distances(k) < problem.d_hat) W.push_back(k);
  ASSERT_GE(W.size(), 100u);
  const double radius = 4.0;
  sc::DelassusProbing probing(step, radius);
  probing.add(step, W);
  EXPECT_LE(probing.probes(), 12);
  const sc::MatX exact = exact_delassus(step, W);
  const sc::MatX probed(probing.matrix());
  const auto position = [&](Eigen::Index k) {
    const sc::ContactPair& p = step.pairs()[static_cast<std::size_t>(k)];
    return sc::Vec3(p.points.point_a + 0.5 * p.points.distance * p.points.normal);
  };
  const auto w = static_cast<Eigen::Index>(W.size());
  for (Eigen::Index r = 0; r < w; ++r)
    for (Eigen::Index c = 0; c < w; ++c) {
      const bool read = 2.0 * (position(W[static_cast<std::size_t>(r)]) - position(W[static_cast<std::size_t>(c)])).norm() < radius;
      EXPECT_NEAR(probed(r, c), read ? exact(r, c) : 0.0, 1e-12 * exact.cwiseAbs().maxCoeff()) << r << ", " << c;
    }
  EXPECT_LE(probing.matrix().nonZeros(), 8 * w);
  std::printf("[probing at scale] %lld contacts of %lld flagged, %d probes, %lld nonzeros\n", static_cast<long long>(w),
              static_cast<long long>(step.nc()), probing.probes(), static_cast<long long>(probing.matrix().nonZeros()));
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
  const auto corrected = secant.corrected(A0_W, rows);
  for (Eigen::Index l = 0; l < 3; ++l)
    EXPECT_LE((corrected(S.col(l)) - A_W * S.col(l)).cwiseAbs().maxCoeff(), 1e-12);
  // A direction orthogonal to every step.
  const Eigen::HouseholderQR<sc::MatX> qr(S);
  const sc::VecX orthogonal = sc::MatX(qr.householderQ()).col(4);
  EXPECT_LE((S.transpose() * orthogonal).norm(), 1e-12);
  EXPECT_LE((corrected(orthogonal) - A0_W * orthogonal).norm(), 1e-12);
  secant.clear();
  EXPECT_EQ(secant.corrected(A0_W, rows)(orthogonal), A0_W * orthogonal);
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

// The sparse lift: below the dense limit the same as the dense one; above it the first shift
// A + tau I of the sequence floor x Gershgorin bound x 4^k that a Cholesky factorisation accepts.
TEST(PositiveDefinite, SparseLiftShiftsBeyondTheDenseLimit) {
  const auto tridiagonal = [](Eigen::Index n, double diagonal, double off) {
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index i = 0; i < n; ++i) {
      t.emplace_back(static_cast<int>(i), static_cast<int>(i), diagonal);
      if (i + 1 < n) {
        t.emplace_back(static_cast<int>(i), static_cast<int>(i + 1), off);
        t.emplace_back(static_cast<int>(i + 1), static_cast<int>(i), off);
      }
    }
    Eigen::SparseMatrix<double> A(n, n);
    A.setFromTriplets(t.begin(), t.end());
    return A;
  };
  // Definite (eigenvalues 2 + 2 cos(k pi / (n + 1)) > 0): unchanged at any size.
  const Eigen::SparseMatrix<double> definite = tridiagonal(300, 2.0, -1.0);
  EXPECT_EQ(sc::MatX(sc::detail::positive_definite(definite, 1e-3, 200)), sc::MatX(definite));
  // Indefinite (eigenvalues 1 + 2 cos(k pi / (n + 1)), down to about -1).
  const Eigen::SparseMatrix<double> small = tridiagonal(50, 1.0, 1.0);
  EXPECT_LE((sc::MatX(sc::detail::positive_definite(small, 1e-3, 200)) -
             sc::detail::positive_definite(sc::MatX(small), 1e-3))
                .cwiseAbs()
                .maxCoeff(),
            1e-14);
  const Eigen::SparseMatrix<double> large = tridiagonal(300, 1.0, 1.0);
  const sc::MatX lifted(sc::detail::positive_definite(large, 1e-3, 200));
  const double tau = lifted(0, 0) - 1.0;
  EXPECT_LE((lifted - sc::MatX(large) - tau * sc::MatX::Identity(300, 300)).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(Eigen::LLT<sc::MatX>(lifted).info(), Eigen::Success);
  const double gershgorin = 3.0;  // largest absolute row sum
  const double k = std::log(tau / (1e-3 * gershgorin)) / std::log(4.0);
  EXPECT_NEAR(k, std::round(k), 1e-9);  // on the sequence
  EXPECT_NE(Eigen::LLT<sc::MatX>(sc::MatX(large) + 0.25 * tau * sc::MatX::Identity(300, 300)).info(), Eigen::Success);
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

// The probed model on the working set W embedded among all flagged pairs, as the LCP sequence
// that finishes a round takes it: W's entries at W's positions (brute force, entry by entry),
// every other pair alone on its row with the mean of W's diagonal.
TEST(DefaultSolver, ModelOnFlaggedPairsKeepsTheWorkingSetsEntries) {
  sc::MatX model(3, 3);
  model << 4, -1, 0, -1, 5, -2, 0, -2, 6;
  const Eigen::SparseMatrix<double> sparse = model.sparseView();
  const std::vector<Eigen::Index> W{5, 1, 3};
  const sc::MatX embedded(sc::detail::model_on_flagged_pairs(sparse, W, 7));
  for (Eigen::Index r = 0; r < 7; ++r)
    for (Eigen::Index c = 0; c < 7; ++c) {
      const auto in_W = [&](Eigen::Index k) { return std::find(W.begin(), W.end(), k) - W.begin(); };
      const auto i = in_W(r), j = in_W(c);
      const double expected = i < 3 && j < 3 ? model(i, j) : (r == c ? 5.0 : 0.0);
      EXPECT_EQ(embedded(r, c), expected) << r << ", " << c;
    }
  try {
    sc::detail::model_on_flagged_pairs(sparse, std::vector<Eigen::Index>{0, 1}, 7);
    ADD_FAILURE() << "a model of the wrong size was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("model"), std::string::npos) << e.what();
  }
}

// A jammed packing in matrix-free mode, where probes are shared and the corrections do not
// contract: the round is finished by the LCP sequence with exact products, whose Newton starts
// from and is preconditioned by the probed model. It must give the blocks mode's answer
// (exact model, no fallback) and cost fewer applications than the LCP sequence alone, polished
// to complementarity the same way.
TEST(DefaultSolver, JammedMatrixFreeRoundIsFinishedFromTheProbedModel) {
  constexpr std::size_t n = 300;
  std::mt19937_64 rng(11);
  const sc::SpherePacking packing = sc::dense_packing(n, 0.6, rng());
  const std::vector<sc::Vec3> forces = sc::random_forces(n, 100.0, rng);
  const std::vector<sc::Sphere> shapes{sc::Sphere{1.0}};
  const auto mobility = [&] {
    sc::FreeDrainingMobility m(sc::sphere_mobility(shapes[0], 1.0), n, 3);
    m.set_configuration(packing.poses);
    return m;
  };
  sc::VecX F(3 * static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) F.segment<3>(3 * static_cast<Eigen::Index>(i)) = forces[i];
  auto m0 = mobility();
  const sc::ContactStepProblem<sc::Sphere> p{shapes, packing.poses, m0.apply(F), 0.01, 1e-4};
  sc::ContactStepOptions blocks, matrix_free;
  blocks.cost = sc::MobilityCost::blocks;
  matrix_free.cost = sc::MobilityCost::matrix_free;
  auto m1 = mobility(), m2 = mobility(), m3 = mobility();
  const sc::ContactStepResult exact = sc::solve_contact_step_defect_correction(p, m1, blocks);
  const sc::ContactStepResult probed = sc::solve_contact_step_defect_correction(p, m2, matrix_free);
  const sc::DefectCorrectionOptions corrections;
  sc::LcpSequenceOptions polished;  // to complementarity, as the default solver finishes a round
  polished.tol = corrections.tol;
  polished.margin = corrections.margin;
  const sc::ContactStepResult sequence = sc::solve_contact_step_lcp_sequence(p, m3, matrix_free, polished);
  std::printf("  jammed %zu spheres: %zu flagged; matrix-free default %zu applications (%s), LCP sequence %zu\n", n,
              probed.flagged_pairs, probed.mobility_applications, probed.message.c_str(),
              sequence.mobility_applications);
  EXPECT_NE(probed.message.find("finished by the LCP sequence"), std::string::npos) << probed.message;
  for (const sc::ContactStepResult* r : {&exact, &probed}) {
    EXPECT_EQ(r->status, sc::ContactStepStatus::converged) << r->message;
    EXPECT_GE(r->min_distance_ratio, 1.0);
    EXPECT_LE(r->complementarity_residual, 1e-3);
  }
  EXPECT_NEAR(probed.lambda_sum, exact.lambda_sum, 1e-4 * exact.lambda_sum);
  EXPECT_LE(2 * probed.mobility_applications, sequence.mobility_applications);
}

}  // namespace

}  // namespace delassus_probing_tests
