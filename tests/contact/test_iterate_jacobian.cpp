// The default solver's model at the iterate (DefectCorrectionOptions::jacobian_at_iterate,
// defect_correction.hpp): dt D_k^T M D on the working set, D_k the contact matrix at Q(lambda_k).
//   - It is the derivative of the flagged distances at the iterate, against central finite
//     differences of the measured distances: for spheres exactly (to the differences' error);
//     for turning rods to first order in the turn of the step (a pose is advanced by the
//     exponential map, whose derivative at a turn theta differs from the body twist by
//     O(theta)), checked with a bound proportional to that turn.
//   - On dense rods it takes fewer corrections than the model at Q* with secants, to the same
//     kind of answer: converged, separated, complementary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/scenes/periodic_placement.hpp"
#include "stokescontact/scenes/random.hpp"

namespace iterate_jacobian_tests {

namespace sc = stokescontact;

namespace {

constexpr double kDt = 0.01;
constexpr double kDHat = 0.01;

template <sc::Shape S>
struct Scene {
  std::vector<S> shapes;
  std::vector<sc::Pose> poses;
  sc::VecX U;
  sc::PeriodicBox box;
  sc::FreeDrainingMobility mobility;
  sc::ContactStepProblem<S> problem() const { return {shapes, poses, U, kDt, kDHat, 0.0, 1.0, box}; }
};

// n bodies at random in a periodic cube with gaps >= 0.01, velocities of `speed` and angular
// velocities of `spin` (rods) in random directions.
template <sc::Shape S>
Scene<S> scene(const S& shape, const sc::Mat6& body_mobility, int dofs, std::size_t n, double side, double speed,
               double spin, std::uint64_t seed) {
  Scene<S> s{{shape}, sc::periodic_random_placement(shape, n, side, 0.01, seed), {},
             sc::PeriodicBox{sc::Vec3::Constant(side)},
             sc::FreeDrainingMobility(body_mobility, n, dofs)};
  sc::Rng rng(seed + 1);
  const std::vector<sc::Vec3> u = sc::random_forces(n, speed, rng), w = sc::random_forces(n, spin, rng);
  s.U.resize(dofs * static_cast<Eigen::Index>(n));
  for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(n); ++k) {
    s.U.template segment<3>(dofs * k) = u[static_cast<std::size_t>(k)];
    if (dofs == 6) s.U.template segment<3>(dofs * k + 3) = w[static_cast<std::size_t>(k)];
  }
  s.mobility.set_configuration(s.poses);
  return s;
}

// Spheres of radius 1 at packing 0.31, |U| = 15: dt |U| = 0.15.
Scene<sc::Sphere> spheres() {
  return scene(sc::Sphere{1.0}, sc::sphere_mobility(sc::Sphere{1.0}, 1.0), 3, 300, 16.0, 15.0, 0.0, 3);
}

// Rods L = 4, R = 0.5 at random in a box of side 14 (eta 0.18), |U| = 20 and |omega| = 10:
// a trial turn of 0.1 rad.
Scene<sc::Spherocylinder> rods() {
  const sc::Spherocylinder rod{4.0, 0.5};
  return scene(rod, sc::spherocylinder_mobility(rod, 1.0), 6, 120, 14.0, 20.0, 10.0, 5);
}

// Compares dt D_k^T M D delta with central differences of the measured distances along
// delta at lambda (uniform in [0, lambda_scale]), for every flagged pair that is not carried
// (a carried pair is measured by its gap, not d^P): max_k |J delta - fd|_k / max_k |fd_k| is
// at most `relative`, or a quarter of the iterate's largest turn dt |omega| where that is
// larger (rods: measured 0.08 of it).
template <sc::Shape S>
void expect_derivative(Scene<S>& s, const sc::ContactStepOptions& options, double lambda_scale, double relative) {
  sc::ContactStep<S, sc::FreeDrainingMobility> step(s.problem(), s.mobility, options);
  ASSERT_EQ(step.cost(), sc::MobilityCost::blocks);
  const Eigen::Index nc = step.nc();
  ASSERT_GT(nc, 20);
  sc::Rng rng(17);
  sc::VecX lambda(nc), delta(nc);
  for (Eigen::Index k = 0; k < nc; ++k) {
    lambda(k) = sc::uniform(rng, 0.0, lambda_scale);
    delta(k) = sc::uniform(rng, -1.0, 1.0);
  }
  std::vector<Eigen::Index> W(static_cast<std::size_t>(nc));
  for (Eigen::Index k = 0; k < nc; ++k) W[static_cast<std::size_t>(k)] = k;
  const sc::ContactEvaluation at = step.measure(step.MD_times(lambda));
  const Eigen::SparseMatrix<double> J = sc::detail::iterate_jacobian(step, at, W);
  ASSERT_EQ(J.rows(), nc);
  const sc::VecX predicted = J * delta;
  const double h = 1e-5;
  const sc::VecX plus = step.measure(step.MD_times(sc::VecX(lambda + h * delta))).distances;
  const sc::VecX minus = step.measure(step.MD_times(sc::VecX(lambda - h * delta))).distances;
  const sc::VecX fd = (plus - minus) / (2.0 * h);
  // The iterate's largest turn, dt |omega| of U + M D lambda (0 for spheres).
  double turn = 0.0;
  if (step.dofs_per_body() == 6)
    for (std::size_t b = 0; b < s.poses.size(); ++b)
      turn = std::max(turn, kDt * (s.U + at.MD_lambda).template segment<3>(6 * static_cast<Eigen::Index>(b) + 3).norm());
  const double bound = std::max(relative, 0.25 * turn);
  const sc::ContactEvaluation trial = step.measure(sc::VecX::Zero(s.U.size()));
  double scale = 0.0, worst = 0.0;
  int compared = 0;
  for (Eigen::Index k = 0; k < nc; ++k) {
    const sc::ContactPair& p = step.pairs()[static_cast<std::size_t>(k)];
    if (trial.distances(k) != p.points.distance) continue;  // carried
    scale = std::max(scale, std::abs(fd(k)));
    worst = std::max(worst, std::abs(predicted(k) - fd(k)));
    ++compared;
  }
  EXPECT_GT(compared, nc / 2);
  ASSERT_GT(scale, 0.0);
  EXPECT_LE(worst, bound * scale) << "turn " << turn << ", worst |J delta - fd| = " << worst << " of max |fd| = " << scale << ", "
                                     << compared << " pairs";
  // The model at Q* is not this derivative: the check can tell them apart.
  const sc::VecX at_trial = kDt * (step.D().transpose() * (*step.sparse_MD() * delta));
  double trial_worst = 0.0;
  for (Eigen::Index k = 0; k < nc; ++k)
    if (trial.distances(k) == step.pairs()[static_cast<std::size_t>(k)].points.distance)
      trial_worst = std::max(trial_worst, std::abs(at_trial(k) - fd(k)));
  EXPECT_GT(trial_worst, 10.0 * worst);
}

sc::ContactStepOptions directions(sc::ContactDirections d) {
  sc::ContactStepOptions o;
  o.directions = d;
  o.cost = sc::MobilityCost::blocks;
  return o;
}

}  // namespace

TEST(IterateJacobian, IsTheDerivativeOfSphereDistances) {
  Scene<sc::Sphere> s = spheres();
  expect_derivative(s, directions(sc::ContactDirections::particle), 100.0, 1e-6);
}

// The iterate's largest turn is 0.7-0.8 rad here (U's turn of 0.1 rad and the forces').
TEST(IterateJacobian, IsTheDerivativeOfRodDistancesToFirstOrderInTheTurn) {
  Scene<sc::Spherocylinder> s = rods();
  expect_derivative(s, directions(sc::ContactDirections::particle), 500.0, 1e-6);
  expect_derivative(s, directions(sc::ContactDirections::overlap_ends), 500.0, 1e-6);
}

TEST(IterateJacobian, DenseRodsNeedFewerCorrections) {
  Scene<sc::Spherocylinder> s = scene(sc::Spherocylinder{4.0, 0.5}, sc::spherocylinder_mobility(sc::Spherocylinder{4.0, 0.5}, 1.0),
                                      6, 180, 14.0, 20.0, 10.0, 9);
  sc::ContactStepOptions options = directions(sc::ContactDirections::overlap_ends);
  options.separation_margin = 1e-3;
  int corrections[2] = {0, 0};
  for (const bool at_iterate : {false, true}) {
    SCOPED_TRACE(at_iterate ? "Jacobian at the iterate" : "model at Q* with secants");
    sc::DefectCorrectionOptions solver;
    solver.jacobian_at_iterate = at_iterate;
    solver.far_root_fallback = solver.lcp_sequence_fallback = false;
    const sc::ContactStepResult r = sc::solve_contact_step_defect_correction(s.problem(), s.mobility, options, solver);
    EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    EXPECT_GE(r.min_distance_ratio, 1.0 - 1e-3);
    EXPECT_LT(r.complementarity_residual, 1e-2);
    EXPECT_GT((r.lambda.array() > 0.0).count(), 20);
    corrections[at_iterate] = r.iterations;
  }
  EXPECT_LT(corrections[1], corrections[0]);
  std::printf("corrections: %d at Q* with secants, %d at the iterate\n", corrections[0], corrections[1]);
  RecordProperty("corrections_at_trial", corrections[0]);
  RecordProperty("corrections_at_iterate", corrections[1]);
}

}  // namespace iterate_jacobian_tests
