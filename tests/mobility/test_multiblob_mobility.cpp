#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "stokescontact/mobility/blob_models.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/multiblob_mobility.hpp"
#include "common/test_support.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace multiblob_mobility_tests {

namespace sc = stokescontact;

static_assert(sc::DenseMobilityOperator<sc::MultiblobMobility>);

namespace {

using test_support::expect_rejects;

constexpr double kPi = std::numbers::pi;

sc::MultiblobOptions options(sc::MultiblobSolver solver, double tolerance = 1e-10, double eta = 1.0) {
  sc::MultiblobOptions o;
  o.viscosity = eta;
  o.solver = solver;
  o.gmres.tolerance = tolerance;
  return o;
}

// Random poses: centres on a jittered cubic lattice of spacing `spacing`, random rotations.
std::vector<sc::Pose> lattice_poses(int n, double spacing, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<sc::Pose> poses;
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n))));
  for (int i = 0; i < n; ++i) {
    sc::Pose p;
    p.x = spacing * sc::Vec3(i % side + jitter(rng), (i / side) % side + jitter(rng), i / (side * side) + jitter(rng));
    p.q = sc::Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
    poses.push_back(p);
  }
  return poses;
}

sc::VecX random_forces(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  sc::VecX f(n);
  for (Eigen::Index i = 0; i < n; ++i) f(i) = g(rng);
  return f;
}

// Block-diagonal rotation of (u, omega) for every body.
sc::MatX body_rotation(const sc::Mat3& r, Eigen::Index bodies) {
  sc::MatX q = sc::MatX::Zero(6 * bodies, 6 * bodies);
  for (Eigen::Index k = 0; k < 2 * bodies; ++k) q.block<3, 3>(3 * k, 3 * k) = r;
  return q;
}

// Two models with one blob radius: a 12-blob shell of R_h = 1 and a rod whose blobs are
// given the shell's blob radius.
std::vector<sc::BlobModel> shell_and_rod() {
  sc::BlobModel shell = sc::sphere_shell(12, 1.0);
  sc::BlobModel rod = sc::rod_blob_model({3.0, 0.6}, {6, 0.0, shell.blob_radius});
  return {shell, rod};
}

}  // namespace

TEST(BlobRpy, ProductMatchesTheDenseMatrixInEveryBranch) {
  // Blobs far apart, overlapping (r < 2a), at exactly r = 2a, and coincident (r = 0).
  sc::Mat3X x(3, 6);
  x << 0.0, 5.0, 1.3, 2.0, 0.0, -0.4,  //
      0.0, 1.0, 0.4, 0.0, 0.0, 0.2,    //
      0.0, -2.0, 0.2, 0.0, 0.0, 0.1;
  const sc::VecX lambda = random_forces(18, 3);
  const sc::MatX m = sc::rpy_blob_matrix(x);
  EXPECT_LT((sc::rpy_blob_product(x, lambda) - m * lambda).norm(), 1e-14 * (m * lambda).norm());
  EXPECT_LT((m - m.transpose()).norm(), 1e-15);
  // Blob units: the matrix is RPY over mu0 = 1 / (6 pi eta a) with positions over a.
  const double a = 0.3, eta = 1.7;
  EXPECT_LT((m.block<3, 3>(0, 3) * sc::stokes_mobility(a, eta) -
             sc::rpy_translation(a * (x.col(0) - x.col(1)), a, eta)).norm(), 1e-15);
  EXPECT_LT((m.block<3, 3>(0, 6) * sc::stokes_mobility(a, eta) -
             sc::rpy_translation(a * (x.col(0) - x.col(2)), a, eta)).norm(), 1e-15);
}

// The product multiblob runs (the shared RPY direct sum) against the dense reference matrix
// over several blocks: 12-blob shells, neighbours' blobs overlapping, as in a packed scene.
TEST(BlobRpy, ProductMatchesTheDenseMatrixForManyBodies) {
  const sc::BlobModel shell = sc::sphere_shell(12, 1.0);
  const auto poses = lattice_poses(40, 2.1, 5);  // 480 blobs, 4 blocks
  sc::Mat3X x(3, 40 * shell.size());
  for (std::size_t i = 0; i < poses.size(); ++i)
    x.middleCols(static_cast<Eigen::Index>(i) * shell.size(), shell.size()) =
        ((poses[i].rotation() * shell.positions).colwise() + poses[i].x) / shell.blob_radius;
  const sc::VecX lambda = random_forces(3 * x.cols(), 6);
  const sc::VecX expected = sc::rpy_blob_matrix(x) * lambda;
  EXPECT_LT((sc::rpy_blob_product(x, lambda) - expected).cwiseAbs().maxCoeff(),
            1e-14 * expected.cwiseAbs().maxCoeff());
}

#ifdef _OPENMP
// The matrix-free apply is the same to the last bit on 1 and 2 threads: the RPY sum and the
// preconditioner both keep their order (1200 blobs: both run in parallel).
TEST(MultiblobMobility, MatrixFreeApplyDoesNotDependOnThreadCount) {
  sc::MultiblobMobility m(sc::sphere_shell(12, 1.0), 100, options(sc::MultiblobSolver::matrix_free, 1e-8));
  m.set_configuration(lattice_poses(100, 2.6, 7));
  const sc::VecX f = random_forces(600, 8);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const sc::VecX serial = m.apply(f);
  omp_set_num_threads(2);
  const sc::VecX parallel = m.apply(f);
  omp_set_num_threads(threads);
  EXPECT_EQ(serial, parallel);
}
#endif

TEST(MultiblobMobility, SingleBodyIsTheRotatedBodyFrameMobility) {
  const sc::BlobModel rod = sc::rod_blob_model({2.0, 0.5});
  const sc::Mat6 body = sc::single_body_mobility(rod, 2.0);
  const sc::Pose pose{sc::Vec3(1, -2, 3), sc::Quat(Eigen::AngleAxisd(0.8, sc::Vec3(1, 2, -1).normalized()))};
  for (const auto solver : {sc::MultiblobSolver::dense, sc::MultiblobSolver::matrix_free}) {
    sc::MultiblobMobility m(rod, 1, options(solver, 1e-12, 2.0));
    EXPECT_LT((m.body_frame_mobility(0) - body).norm(), 1e-14 * body.norm());
    m.set_configuration(std::vector<sc::Pose>{pose});
    const sc::MatX q = body_rotation(pose.rotation(), 1);
    EXPECT_LT((m.dense_matrix() - q * body * q.transpose()).norm(), 1e-10 * body.norm());
    // One body: the block-diagonal preconditioner is the exact inverse, rotation included.
    if (solver == sc::MultiblobSolver::matrix_free) {
      EXPECT_LE(m.last_iterations(), 2);
    }
  }
}

TEST(MultiblobMobility, DenseAndMatrixFreeAgreeToTheGmresTolerance) {
  const std::vector<sc::BlobModel> models = shell_and_rod();
  const std::vector<std::size_t> body_models{0, 1, 0, 1, 0, 0, 1, 0};
  const auto poses = lattice_poses(8, 4.5, 21);
  const sc::VecX f = random_forces(48, 22);
  sc::MultiblobMobility dense(models, body_models, options(sc::MultiblobSolver::dense));
  dense.set_configuration(poses);
  const sc::VecX u_dense = dense.apply(f);
  for (const double tolerance : {1e-6, 1e-10}) {
    sc::MultiblobMobility free(models, body_models, options(sc::MultiblobSolver::matrix_free, tolerance));
    EXPECT_FALSE(free.uses_dense());
    free.set_configuration(poses);
    const sc::VecX u_free = free.apply(f);
    EXPECT_LE(free.last_relative_residual(), tolerance);
    EXPECT_GT(free.last_iterations(), 0);
    EXPECT_LT((u_free - u_dense).norm() / u_dense.norm(), 20.0 * tolerance) << tolerance;
  }
}

TEST(MultiblobMobility, IsSymmetricPositiveDefinite) {
  const auto poses = lattice_poses(6, 2.6, 31);  // close: blobs of neighbours near contact
  for (const auto solver : {sc::MultiblobSolver::dense, sc::MultiblobSolver::matrix_free}) {
    sc::MultiblobMobility m(sc::sphere_shell(42, 1.0), 6, options(solver, 1e-12));
    m.set_configuration(poses);
    // Columns by single applications, not symmetrised.
    sc::MatX n(36, 36);
    for (Eigen::Index j = 0; j < 36; ++j) n.col(j) = m.apply(sc::VecX::Unit(36, j));
    EXPECT_LT((n - n.transpose()).norm(), 1e-9 * n.norm());
    const Eigen::SelfAdjointEigenSolver<sc::MatX> eig(0.5 * (n + n.transpose()));
    EXPECT_GT(eig.eigenvalues().minCoeff(), 1e-3 * eig.eigenvalues().maxCoeff());
  }
}

TEST(MultiblobMobility, InvariantUnderARigidMotionOfTheWholeScene) {
  const std::vector<sc::BlobModel> models = shell_and_rod();
  const std::vector<std::size_t> body_models{1, 0, 1, 0, 0};
  const auto poses = lattice_poses(5, 4.0, 41);
  const sc::Quat turn(Eigen::AngleAxisd(2.1, sc::Vec3(-0.3, 0.8, 0.5).normalized()));
  const sc::Vec3 shift(10.0, -7.0, 3.0);
  std::vector<sc::Pose> moved;
  for (const sc::Pose& p : poses) moved.push_back({turn * p.x + shift, turn * p.q});
  const sc::MatX q = body_rotation(turn.toRotationMatrix(), 5);
  for (const auto solver : {sc::MultiblobSolver::dense, sc::MultiblobSolver::matrix_free}) {
    sc::MultiblobMobility m(models, body_models, options(solver, 1e-12));
    m.set_configuration(poses);
    const sc::MatX n = m.dense_matrix();
    m.set_configuration(moved);
    EXPECT_LT((m.dense_matrix() - q * n * q.transpose()).norm(), 1e-9 * n.norm());
  }
}

TEST(MultiblobMobility, FarApartBodiesCoupleThroughTheOseenTensor) {
  // Two R_h = 1 shells at distance d: self blocks -> 1 / (6 pi eta), translational coupling
  // -> (I + r r^T / d^2) / (8 pi eta d) up to O(1 / d^3).
  const double d = 40.0, eta = 1.0;
  sc::MultiblobMobility m(sc::sphere_shell(42, 1.0), 2, options(sc::MultiblobSolver::dense));
  const sc::Vec3 r = d * sc::Vec3(1, 2, 2) / 3.0;
  m.set_configuration(std::vector<sc::Pose>{{sc::Vec3::Zero(), sc::Quat::Identity()}, {r, sc::Quat::Identity()}});
  const sc::MatX n = m.dense_matrix();
  const sc::Mat3 oseen = (sc::Mat3::Identity() + r * r.transpose() / (d * d)) / (8.0 * kPi * eta * d);
  EXPECT_LT((n.block<3, 3>(0, 6) - oseen).norm(), 2e-3 * oseen.norm());
  EXPECT_NEAR(n(0, 0) * 6.0 * kPi * eta, 1.0, 1e-4);
}

TEST(MultiblobMobility, OverlappingBodiesStayPositiveDefinite) {
  // R_h = 1 shells whose centres are 1.5 apart overlap; the RPY overlap branch keeps N SPD.
  sc::MultiblobMobility m(sc::sphere_shell(12, 1.0), 2, options(sc::MultiblobSolver::dense));
  m.set_configuration(std::vector<sc::Pose>{{sc::Vec3::Zero(), sc::Quat::Identity()},
                                             {sc::Vec3(1.5, 0.0, 0.0), sc::Quat(Eigen::AngleAxisd(0.3, sc::Vec3::UnitZ()))}});
  const Eigen::SelfAdjointEigenSolver<sc::MatX> eig(m.dense_matrix());
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
}

TEST(MultiblobMobility, ZeroForceGivesZeroVelocity) {
  for (const auto solver : {sc::MultiblobSolver::dense, sc::MultiblobSolver::matrix_free}) {
    sc::MultiblobMobility m(sc::sphere_shell(12, 1.0), 3, options(solver));
    m.set_configuration(lattice_poses(3, 3.0, 51));
    EXPECT_EQ(m.apply(sc::VecX::Zero(18)), sc::VecX::Zero(18));
    EXPECT_EQ(m.last_iterations(), 0);
  }
}

// The dense path factorises on the first apply after set_configuration: a configuration set
// and replaced without an apply must not leave its factorisation behind, and one set again
// must be factorised again.
TEST(MultiblobMobility, DenseFactorisationFollowsTheLatestConfiguration) {
  const sc::BlobModel shell = sc::sphere_shell(12, 1.0);
  const auto a = lattice_poses(4, 3.0, 65), b = lattice_poses(4, 3.0, 66), c = lattice_poses(4, 2.6, 67);
  const sc::VecX f = random_forces(24, 68);
  const auto fresh = [&](const std::vector<sc::Pose>& poses) {
    sc::MultiblobMobility m(shell, 4, options(sc::MultiblobSolver::dense));
    m.set_configuration(poses);
    return sc::VecX(m.apply(f));
  };
  sc::MultiblobMobility m(shell, 4, options(sc::MultiblobSolver::dense));
  m.set_configuration(a);
  const sc::VecX u_a = m.apply(f);
  EXPECT_EQ(u_a, fresh(a));
  m.set_configuration(b);  // replaced before any apply
  m.set_configuration(c);
  EXPECT_EQ(m.apply(f), fresh(c));
  EXPECT_GT((fresh(c) - u_a).norm(), 1e-3 * u_a.norm());  // the configurations differ
  m.set_configuration(a);
  EXPECT_EQ(sc::VecX(m.dense_matrix() * f), u_a);
  EXPECT_EQ(m.apply(f), u_a);
}

// adaptive: GMRES until the configuration's products reach adaptive_products_per_blob x
// blobs, then the dense factorisation, again from GMRES after each set_configuration.
TEST(MultiblobMobility, AdaptiveFactorisesOnceItsProductBudgetIsSpent) {
  const sc::BlobModel shell = sc::sphere_shell(12, 1.0);
  const auto poses = lattice_poses(4, 3.0, 69), other = lattice_poses(4, 2.8, 70);
  const sc::VecX f = random_forces(24, 71);
  sc::MultiblobMobility dense(shell, 4, options(sc::MultiblobSolver::dense));
  dense.set_configuration(poses);
  const sc::VecX exact = dense.apply(f);

  sc::MultiblobOptions o = options(sc::MultiblobSolver::adaptive, 1e-10);
  o.adaptive_products_per_blob = 0.1;  // 4 products for 48 blobs: the first apply spends more
  sc::MultiblobMobility m(shell, 4, o);
  EXPECT_EQ(m.solver(), sc::MultiblobSolver::adaptive);
  m.set_configuration(poses);
  const sc::VecX first = m.apply(f);
  EXPECT_GT(m.last_iterations(), 4);
  EXPECT_FALSE(m.factorised());
  EXPECT_LT((first - exact).norm(), 1e-8 * exact.norm());
  const std::size_t iterations = m.total_iterations();
  EXPECT_EQ(m.apply(f), exact);  // factorised now: the dense path's own numbers
  EXPECT_TRUE(m.factorised());
  EXPECT_EQ(m.last_iterations(), 0);
  EXPECT_EQ(m.total_iterations(), iterations);
  EXPECT_EQ(m.applications(), 2u);

  m.set_configuration(other);  // a new configuration starts on GMRES again
  EXPECT_FALSE(m.factorised());
  m.apply(f);
  EXPECT_GT(m.total_iterations(), iterations);

  o.adaptive_products_per_blob = 0.0;  // factorise at once
  sc::MultiblobMobility at_once(shell, 4, o);
  at_once.set_configuration(poses);
  EXPECT_EQ(at_once.apply(f), exact);
  EXPECT_EQ(at_once.total_iterations(), 0u);

  o.dense_max_blobs = 0;  // automatic's bound does not apply to adaptive
  EXPECT_EQ(sc::MultiblobMobility(shell, 4, o).solver(), sc::MultiblobSolver::adaptive);
  o.adaptive_max_blobs = 47;  // too many blobs to factorise: matrix-free throughout
  EXPECT_EQ(sc::MultiblobMobility(shell, 4, o).solver(), sc::MultiblobSolver::matrix_free);
  o.adaptive_max_blobs = 48;
  EXPECT_EQ(sc::MultiblobMobility(shell, 4, o).solver(), sc::MultiblobSolver::adaptive);
  o.adaptive_max_blobs = -1;
  expect_rejects([&] { sc::MultiblobMobility(shell, 4, o); }, "adaptive_max_blobs");
  o.adaptive_max_blobs = 48;
  o.adaptive_products_per_blob = -1.0;
  expect_rejects([&] { sc::MultiblobMobility(shell, 4, o); }, "adaptive_products_per_blob");
}

TEST(MultiblobMobility, CountsApplicationsAndGmresIterations) {
  sc::MultiblobMobility dense(sc::sphere_shell(12, 1.0), 4, options(sc::MultiblobSolver::dense));
  sc::MultiblobMobility free(sc::sphere_shell(12, 1.0), 4, options(sc::MultiblobSolver::matrix_free));
  const auto poses = lattice_poses(4, 3.0, 61);
  const sc::VecX f = random_forces(24, 62);
  for (sc::MultiblobMobility* m : {&dense, &free}) {
    m->set_configuration(poses);
    EXPECT_EQ(m->applications(), 0u);
    m->apply(f);
    m->apply(f);
    EXPECT_EQ(m->applications(), 2u);
    m->dense_matrix();
    EXPECT_EQ(m->applications(), m == &dense ? 2u : 26u);  // matrix-free: one per column
    m->reset_applications();
    EXPECT_EQ(m->applications(), 0u);
    EXPECT_EQ(m->total_iterations(), 0u);
  }
  free.apply(f);
  const int once = free.last_iterations();
  free.apply(2.0 * f);
  EXPECT_EQ(free.total_iterations(), static_cast<std::size_t>(once + free.last_iterations()));
  EXPECT_EQ(dense.last_iterations(), 0);
}

TEST(MultiblobMobility, BlockPreconditionerKeepsIterationsFlatInTheNumberOfBodies) {
  std::vector<int> iterations;
  for (const int n : {2, 8, 27}) {
    sc::MultiblobMobility m(sc::sphere_shell(12, 1.0), static_cast<std::size_t>(n),
                            options(sc::MultiblobSolver::matrix_free, 1e-8));
    m.set_configuration(lattice_poses(n, 3.2, 71));
    m.apply(random_forces(6 * n, 72));
    iterations.push_back(m.last_iterations());
  }
  std::printf("GMRES iterations for 2, 8, 27 bodies: %d %d %d\n", iterations[0], iterations[1], iterations[2]);
  EXPECT_LE(iterations[2], 2 * iterations[0] + 4);
  EXPECT_LE(iterations[2], 30);
}

TEST(MultiblobMobility, ScalesInverselyWithViscosity) {
  const auto poses = lattice_poses(3, 3.0, 81);
  sc::MultiblobMobility one(sc::sphere_shell(12, 1.0), 3, options(sc::MultiblobSolver::matrix_free, 1e-12, 1.0));
  sc::MultiblobMobility four(sc::sphere_shell(12, 1.0), 3, options(sc::MultiblobSolver::matrix_free, 1e-12, 4.0));
  one.set_configuration(poses);
  four.set_configuration(poses);
  const sc::VecX f = random_forces(18, 82);
  EXPECT_LT((4.0 * four.apply(f) - one.apply(f)).norm(), 1e-10 * one.apply(f).norm());
}

TEST(MultiblobMobility, AutomaticSolverChoosesByBlobCount) {
  sc::MultiblobOptions o;
  o.dense_max_blobs = 100;
  EXPECT_TRUE(sc::MultiblobMobility(sc::sphere_shell(12, 1.0), 8, o).uses_dense());    // 96 blobs
  EXPECT_FALSE(sc::MultiblobMobility(sc::sphere_shell(12, 1.0), 9, o).uses_dense());   // 108 blobs
}

TEST(MultiblobMobility, SolverNamesRoundTripAndUnknownNamesAreRefusedByField) {
  for (const auto s : {sc::MultiblobSolver::automatic, sc::MultiblobSolver::dense, sc::MultiblobSolver::matrix_free,
                       sc::MultiblobSolver::adaptive})
    EXPECT_EQ(sc::multiblob_solver_from_name(sc::multiblob_solver_name(s), "solver"), s);
  EXPECT_STREQ(sc::multiblob_solver_name(sc::MultiblobSolver::matrix_free), "matrix-free");
  expect_rejects([] { sc::multiblob_solver_from_name("matrix_free", "--multiblob-solver"); }, "--multiblob-solver");
}

TEST(MultiblobMobility, RejectsBadInputWithoutChangingState) {
  const sc::BlobModel shell = sc::sphere_shell(12, 1.0);
  expect_rejects([&] { sc::MultiblobMobility(shell, 2, options(sc::MultiblobSolver::dense, 1e-8, -1.0)); },
                                 "viscosity");
  expect_rejects([&] { sc::MultiblobMobility(shell, 2, options(sc::MultiblobSolver::dense, 0.0)); },
                                 "tolerance");
  expect_rejects([&] { sc::MultiblobMobility(shell, 0); }, "body_models");
  expect_rejects([&] { sc::MultiblobMobility({shell}, {0, 1}); }, "body_models[1]");
  // Different blob radii are refused: RPY here is the equal-blob tensor.
  expect_rejects([&] { sc::MultiblobMobility({shell, sc::sphere_shell(12, 2.0)}, {0, 1}); },
                                 "models[1].blob_radius");
  expect_rejects([&] { sc::MultiblobMobility({shell, sc::rod_blob_model({1.0, 0.5})}, {0, 1}); },
                                 "models[1].blob_radius");

  sc::MultiblobMobility m(shell, 2, options(sc::MultiblobSolver::dense));
  EXPECT_THROW(m.apply(sc::VecX::Zero(12)), std::logic_error);  // no configuration yet
  const std::vector<sc::Pose> good = lattice_poses(2, 3.0, 91);
  m.set_configuration(good);
  const sc::VecX f = random_forces(12, 92);
  const sc::VecX before = m.apply(f);

  expect_rejects([&] { m.set_configuration(lattice_poses(3, 3.0, 93)); }, "poses");
  std::vector<sc::Pose> bad = good;
  bad[1].x.y() = std::numeric_limits<double>::quiet_NaN();
  expect_rejects([&] { m.set_configuration(bad); }, "poses[1].x");
  bad = good;
  bad[0].q.coeffs() *= 1.01;
  expect_rejects([&] { m.set_configuration(bad); }, "poses[0].q");
  bad = good;
  bad[1] = bad[0];  // coincident bodies: every blob on top of another
  expect_rejects([&] { m.set_configuration(bad); }, "poses");
  expect_rejects([&] { m.apply(sc::VecX::Zero(6)); }, "F");
  sc::VecX nan_f = f;
  nan_f(3) = std::numeric_limits<double>::infinity();
  expect_rejects([&] { m.apply(nan_f); }, "F");
  EXPECT_EQ(m.apply(f), before);  // nothing was half-updated
}

TEST(MultiblobMobility, MissedToleranceThrowsInsteadOfReturningAWrongVelocity) {
  sc::MultiblobOptions o = options(sc::MultiblobSolver::matrix_free, 1e-14);
  o.gmres.max_iterations = 2;
  sc::MultiblobMobility m(sc::sphere_shell(42, 1.0), 4, o);
  m.set_configuration(lattice_poses(4, 2.3, 101));
  EXPECT_THROW(m.apply(random_forces(24, 102)), std::runtime_error);
  EXPECT_EQ(m.last_iterations(), 2);
  EXPECT_GT(m.last_relative_residual(), 1e-14);
}

// A free-draining scene of an arbitrary shape takes its self-mobility from the shape's
// multiblob model; for one body it must be the multiblob mobility itself, in any pose.
TEST(MultiblobMobility, FreeDrainingFromTheSingleBodyMobilityMatchesOneBody) {
  const sc::BlobModel model = sc::boomerang_surface_blobs(sc::broms_tornberg_boomerang(), 0.5);
  const double eta = 0.7;
  sc::FreeDrainingMobility free_draining(sc::single_body_mobility(model, eta), 1);
  sc::MultiblobOptions options;
  options.viscosity = eta;
  sc::MultiblobMobility multiblob(model, 1, options);
  const std::vector<sc::Pose> pose{{sc::Vec3(0.3, -1.0, 2.0),
                                    sc::Quat(Eigen::AngleAxisd(1.1, sc::Vec3(1, -2, 0.5).normalized()))}};
  free_draining.set_configuration(pose);
  multiblob.set_configuration(pose);
  const sc::MatX a = free_draining.dense_matrix(), b = multiblob.dense_matrix();
  EXPECT_LE((a - b).norm(), 1e-10 * b.norm());
}

}  // namespace multiblob_mobility_tests
