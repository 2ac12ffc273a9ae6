#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/dynamics/collision_stress.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/geometry/mass_tensors.hpp"
#include "stokescontact/mobility/free_draining.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace collision_stress_tests {

namespace sc = stokescontact;

namespace {

using sc::Mat3;
using sc::Vec3;
using test_support::expect_rejects;
using test_support::random_rotation;
using test_support::random_unit_vector;
using test_support::Rng;
using test_support::uniform;
using test_support::uniform_vector;

double levi_civita(int i, int j, int k) { return 0.5 * (i - j) * (j - k) * (k - i); }

// Eq. 15 written out with the Levi-Civita symbol: s^G_ij = eps_jkl N_il omega_k, omega = G_M^-1 tau,
// N and G_M rotated by hand, entry by entry.
Mat3 eq15_by_hand(const sc::MassTensors& body, const sc::Pose& pose, const Vec3& torque) {
  const Mat3 R = pose.q.toRotationMatrix();
  Mat3 N = Mat3::Zero(), G = Mat3::Zero();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) {
          N(a, b) += R(a, c) * body.N(c, d) * R(b, d);
          G(a, b) += R(a, c) * body.G_M(c, d) * R(b, d);
        }
  const Vec3 omega = G.inverse() * torque;
  Mat3 s = Mat3::Zero();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) s(i, j) += levi_civita(j, k, l) * N(i, l) * omega(k);
  return s;
}

// Eq. 16 by hand: body 1 gets F_1 at p_1, body 2 gets -F_1 at p_2; each body's geometric term
// with the force it receives (sign = -1 in front of body 1's gives the paper's printed form).
Mat3 eq16_by_hand(const sc::MassTensors& m1, const sc::Pose& pose1, const Vec3& p1, const sc::MassTensors& m2,
                  const sc::Pose& pose2, const Vec3& p2, const Vec3& F1, double body1_sign = 1.0) {
  Mat3 virial;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) virial(i, j) = (pose1.x(i) - pose2.x(i)) * F1(j);
  return virial + body1_sign * eq15_by_hand(m1, pose1, (p1 - pose1.x).cross(F1)) +
         eq15_by_hand(m2, pose2, (p2 - pose2.x).cross(Vec3(-F1)));
}

Vec3 axial(const Mat3& s) {  // eps_mij s_ij
  return Vec3(s(1, 2) - s(2, 1), s(2, 0) - s(0, 2), s(0, 1) - s(1, 0));
}

double rel(const Mat3& a, const Mat3& b) { return (a - b).norm() / std::max(b.norm(), 1e-300); }

// Two equal homogeneous frictionless spheres touching: the force along the line of centres at
// the contact point. Eq. 16 reduces to eq. 19, (r^2 - r^1) F_C^T with the paper's F_C (the force
// on sphere 2) = (x1 - x2) F_1^T with the force F_1 on sphere 1.
TEST(CollisionStress, EqualFrictionlessSpheresGiveTheVirialFormula) {
  Rng rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const double r = uniform(rng, 0.2, 3.0), f = uniform(rng, 0.1, 10.0);
    const Vec3 e = random_unit_vector(rng);  // from sphere 1 to sphere 2
    const sc::Pose p1{uniform_vector(rng, -5, 5), random_rotation(rng)};
    const sc::Pose p2{p1.x + 2.0 * r * e, random_rotation(rng)};
    const Vec3 contact = p1.x + r * e;
    const Vec3 F1 = -f * e;  // repulsion: sphere 1 pushed away from sphere 2
    const Mat3 sigma = sc::collision_stress(sc::Sphere{r}, p1, contact, sc::Sphere{r}, p2, contact, F1);
    const Vec3 F_C = -F1;  // the paper's
    const Mat3 eq19 = (p2.x - p1.x) * F_C.transpose();
    EXPECT_LT(rel(sigma, eq19), 1e-14);
    EXPECT_LT(rel(sigma, (p1.x - p2.x) * F1.transpose()), 1e-14);
    // Compressive-positive: the pressure of a push is |F| |x1 - x2| / 3 = 2 r f / 3.
    EXPECT_NEAR(sc::collision_pressure(sigma), 2.0 * r * f / 3.0, 1e-13 * r * f);
    EXPECT_LT(rel(sigma, sigma.transpose()), 1e-14);
  }
}

// Frictional equal spheres, any force at the contact point: the geometric terms add the
// antisymmetric part back, sigma = (d F_1^T + F_1 d^T) / 2, d = x1 - x2 (derived by hand with
// N = (4 pi/15) R^5 I, G_M = 2 N: s^G = (a F^T - F a^T) / 2 for lever arm a). Eq. 20 prints
// d F_1^T itself, which the printed signs of eq. 16 give (see collision_stress.hpp).
TEST(CollisionStress, EqualFrictionalSpheresGiveTheSymmetrisedVirial) {
  Rng rng(12);
  for (int trial = 0; trial < 50; ++trial) {
    const double r = uniform(rng, 0.2, 3.0);
    const Vec3 e = random_unit_vector(rng);
    const sc::Pose p1{uniform_vector(rng, -5, 5), random_rotation(rng)};
    const sc::Pose p2{p1.x + 2.0 * r * e, random_rotation(rng)};
    const Vec3 contact = p1.x + r * e;
    const Vec3 F1 = uniform_vector(rng, -3, 3);
    const Mat3 sigma = sc::collision_stress(sc::Sphere{r}, p1, contact, sc::Sphere{r}, p2, contact, F1);
    const Vec3 d = p1.x - p2.x;
    EXPECT_LT(rel(sigma, 0.5 * (d * F1.transpose() + F1 * d.transpose())), 1e-14);
    const sc::MassTensors m = sc::mass_tensors(sc::Sphere{r});
    EXPECT_LT(rel(eq16_by_hand(m, p1, contact, m, p2, contact, F1, -1.0), d * F1.transpose()), 1e-13);  // eq. 20
  }
}

// Spherocylinders, force perpendicular to both axes at points on the axes (App. C: x_C x F
// needs the axis point only). Body frame: N = diag(n_perp, n_perp, n_par), G_M = (n_perp + n_par)
// on the perpendicular axes (A3-A5), so for x_C = x n, J perpendicular to n,
//     s^G = (n_par x_C J^T - n_perp J x_C^T) / (n_perp + n_par),
// which tends to eq. 22, x_C J^T, as R -> 0: eq. 16 becomes eq. 23.
TEST(CollisionStress, RodsMatchTheClosedFormAndThinRodsEq23) {
  Rng rng(13);
  auto rod_sg = [](const sc::Spherocylinder& s, const Vec3& x_c, const Vec3& J) {
    const double c = std::numbers::pi * std::pow(s.radius, 5), beta = s.length / (2.0 * s.radius);
    const double n_perp = c * (15.0 * beta + 8.0) / 30.0;
    const double n_par = c * (10.0 * beta * beta * beta + 20.0 * beta * beta + 15.0 * beta + 4.0) / 15.0;
    return Mat3((n_par * x_c * J.transpose() - n_perp * J * x_c.transpose()) / (n_perp + n_par));
  };
  for (const sc::Spherocylinder rod : {sc::Spherocylinder{2.0, 0.3}, sc::Spherocylinder{1.0, 1e-5}}) {
    double worst = 0.0, worst23 = 0.0;
    for (int trial = 0; trial < 50; ++trial) {
      const sc::Pose p1{uniform_vector(rng, -2, 2), random_rotation(rng)};
      const sc::Pose p2{uniform_vector(rng, -2, 2), random_rotation(rng)};
      const Vec3 n1 = p1.direction_to_world(Vec3::UnitZ()), n2 = p2.direction_to_world(Vec3::UnitZ());
      const Vec3 x1 = uniform(rng, -0.5, 0.5) * rod.length * n1, x2 = uniform(rng, -0.5, 0.5) * rod.length * n2;
      const Vec3 F1 = uniform(rng, 0.5, 2.0) * n1.cross(n2).normalized();
      const Mat3 sigma = sc::collision_stress(rod, p1, Vec3(p1.x + x1), rod, p2, Vec3(p2.x + x2), F1);
      const Mat3 closed = (p1.x - p2.x) * F1.transpose() + rod_sg(rod, x1, F1) + rod_sg(rod, x2, -F1);
      const Mat3 eq23 = (p1.x + x1 - p2.x - x2) * F1.transpose();  // (r^2 + x^2 - r^1 - x^1) F_C^T
      worst = std::max(worst, rel(sigma, closed));
      worst23 = std::max(worst23, rel(sigma, eq23));
    }
    std::printf("[rod L = %g R = %g] max rel. difference to the closed form %.3g, to eq. 23 %.3g\n", rod.length,
                rod.radius, worst, worst23);
    EXPECT_LT(worst, 1e-12);
    if (rod.radius < 1e-3) EXPECT_LT(worst23, 1e-6);
    else EXPECT_GT(worst23, 1e-3);  // a thick rod is not a line
  }
}

// Frictionless collisions (force along the common normal through the closest points) of rods
// and of boomerangs: sigma is symmetric to rounding, and the geometric part is not small. The
// printed signs of eq. 16 (both geometric terms with +F_C) would not be symmetric.
template <sc::Shape S>
void expect_frictionless_symmetric(const S& shape, double spread, std::uint64_t seed, const char* name) {
  Rng rng(seed);
  const sc::MassTensors m = sc::mass_tensors(shape);
  double worst = 0.0, least_geometric = 1e300, printed_min = 1e300;
  int n = 0;
  while (n < 100) {
    const sc::Pose p1{uniform_vector(rng, -spread, spread), random_rotation(rng)};
    const sc::Pose p2{uniform_vector(rng, -spread, spread), random_rotation(rng)};
    const sc::ClosestPoints cp = sc::closest_points(shape, p1, shape, p2);
    if (!(cp.distance > 1e-3)) continue;  // a clear normal
    ++n;
    const Vec3 F1 = -uniform(rng, 0.5, 2.0) * cp.normal;  // pushes body 1 away from body 2
    const Mat3 sigma = sc::collision_stress(shape, p1, cp.point_a, shape, p2, cp.point_b, F1);
    const Mat3 virial = sc::virial_stress(p1.x, p2.x, F1);
    worst = std::max(worst, (sigma - sigma.transpose()).norm() / sigma.norm());
    least_geometric = std::min(least_geometric, (sigma - virial).norm() / sigma.norm());
    EXPECT_LT(rel(sigma, eq16_by_hand(m, p1, cp.point_a, m, p2, cp.point_b, F1)), 1e-12);
    const Mat3 printed = eq16_by_hand(m, p1, cp.point_a, m, p2, cp.point_b, F1, -1.0);
    printed_min = std::min(printed_min, (printed - printed.transpose()).norm() / printed.norm());
  }
  std::printf("[%s] max |sigma - sigma^T| / |sigma| = %.3g; min |geometric| / |sigma| = %.3g; printed signs: min "
              "asymmetry %.3g\n",
              name, worst, least_geometric, printed_min);
  EXPECT_LT(worst, 1e-14);
  EXPECT_GT(least_geometric, 1e-6);
  EXPECT_GT(printed_min, 1e-6);
}

TEST(CollisionStress, FrictionlessRodCollisionIsSymmetric) {
  expect_frictionless_symmetric(sc::Spherocylinder{4.0, 0.5}, 2.5, 14, "rods");
}

TEST(CollisionStress, FrictionlessBoomerangCollisionIsSymmetric) {
  expect_frictionless_symmetric(sc::broms_tornberg_boomerang(), 2.0, 15, "boomerangs");
}

// Any shapes, points and forces (not along the normal): the trace is the virial term's
// (eq. 17), the antisymmetric part has the axial vector (p1 - p2) x F_1, and the matrix form
// N [omega]_x^T agrees with eq. 15's Levi-Civita sum.
template <sc::Shape A, sc::Shape B>
void expect_trace_is_virial(const A& a, const B& b, std::uint64_t seed) {
  Rng rng(seed);
  for (int trial = 0; trial < 50; ++trial) {
    const sc::Pose p1{uniform_vector(rng, -3, 3), random_rotation(rng)};
    const sc::Pose p2{uniform_vector(rng, -3, 3), random_rotation(rng)};
    const Vec3 q1 = p1.x + uniform_vector(rng, -1, 1), q2 = p2.x + uniform_vector(rng, -1, 1);
    const Vec3 F1 = uniform_vector(rng, -2, 2);
    const Mat3 sigma = sc::collision_stress(a, p1, q1, b, p2, q2, F1);
    const double virial_pressure = (p1.x - p2.x).dot(F1) / 3.0;  // eq. 18
    const double scale = (p1.x - p2.x).norm() * F1.norm() + (q1 - q2).norm() * F1.norm();
    EXPECT_NEAR(sc::collision_pressure(sigma), virial_pressure, 1e-14 * scale);
    EXPECT_LT((axial(sigma) - (q1 - q2).cross(F1)).norm(), 1e-13 * scale);
    EXPECT_LT(rel(sigma, eq16_by_hand(sc::mass_tensors(a), p1, q1, sc::mass_tensors(b), p2, q2, F1)), 1e-12);
    EXPECT_GT((sigma - sc::virial_stress(p1.x, p2.x, F1)).norm(), 1e-6 * scale);  // the geometric part is there
  }
}

TEST(CollisionStress, PressureIsTheVirialTraceForAnyShapesAndForces) {
  expect_trace_is_virial(sc::Spherocylinder{4.0, 0.5}, sc::Spherocylinder{1.5, 0.2}, 21);
  expect_trace_is_virial(sc::broms_tornberg_boomerang(), sc::Boomerang{2.0, 0.3, 1.1}, 22);
  expect_trace_is_virial(sc::Sphere{0.7}, sc::Spherocylinder{2.0, 0.4}, 23);
  expect_trace_is_virial(sc::broms_tornberg_boomerang(), sc::Sphere{1.0}, 24);
}

// Homogeneous density cancels (after eq. 16): N and G_M scale with rho, sigma does not.
TEST(CollisionStress, HomogeneousDensityCancels) {
  Rng rng(31);
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const sc::Spherocylinder rod{3.0, 0.4};
  for (int trial = 0; trial < 20; ++trial) {
    const sc::Pose p1{uniform_vector(rng, -3, 3), random_rotation(rng)};
    const sc::Pose p2{uniform_vector(rng, -3, 3), random_rotation(rng)};
    const Vec3 q1 = p1.x + uniform_vector(rng, -1, 1), q2 = p2.x + uniform_vector(rng, -1, 1);
    const Vec3 F1 = uniform_vector(rng, -2, 2);
    const Mat3 unit = sc::collision_stress(b, p1, q1, rod, p2, q2, F1, 1.0);
    for (const double rho : {1e-3, 7.3, 2.5e4}) {
      EXPECT_LT(rel(sc::collision_stress(b, p1, q1, rod, p2, q2, F1, rho), unit), 1e-13) << "rho " << rho;
      EXPECT_NEAR(sc::mass_tensors(b, rho).N.trace(), rho * sc::mass_tensors(b).N.trace(),
                  1e-13 * rho * sc::mass_tensors(b).N.trace());
    }
  }
  expect_rejects([&] { sc::collision_stress(b, sc::Pose{}, Vec3::Zero(), rod, sc::Pose{}, Vec3::Zero(), Vec3::UnitX(), 0.0); },
                 "density");
}

// Two rods pushed into each other through the default solver (d^P: one point pair). The
// summed stress from D lambda equals eq. 16 by hand with the force lambda n at the closest
// points of Q* (where D was built), and its trace is the virial term's.
TEST(CollisionStress, ContactStepOfTwoRodsIsEq16AtTheClosestPoints) {
  const sc::Spherocylinder rod{4.0, 0.5};
  const std::vector<sc::Spherocylinder> shapes{rod};
  const Eigen::AngleAxisd tilt(0.3, Vec3(1, 2, 0).normalized());
  const std::vector<sc::Pose> poses = {{Vec3(0, 0, 0), sc::Quat::Identity()},
                                       {Vec3(1.05, 0.4, 0.9), sc::Quat(tilt * Eigen::AngleAxisd(0.5 * std::numbers::pi, Vec3::UnitX()))}};
  sc::VecX U(12);
  U << 1.0, 0.0, 0.0, 0.0, 0.3, 0.0, -1.0, 0.0, 0.0, 0.2, 0.0, -0.1;
  const sc::ContactStepProblem<sc::Spherocylinder> problem{shapes, poses, U, 0.1, 0.01, 0.0, 1.0, {}};
  ASSERT_GT(sc::closest_points(rod, poses[0], rod, poses[1]).distance, 0.0);
  sc::FreeDrainingMobility mobility(sc::spherocylinder_mobility(rod, 1.0), poses.size(), 6);
  const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility);
  ASSERT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
  ASSERT_EQ(r.lambda.size(), 1);
  ASSERT_GT(r.lambda(0), 0.0);
  ASSERT_EQ(r.columns.size(), 1u);
  const std::vector<sc::Pose> trial = sc::advance_all(std::span<const sc::Pose>(poses), U, 6, problem.dt);  // Q*
  const sc::ClosestPoints& cp = r.pairs[0].points;  // at Q*
  const Vec3 F0 = -r.lambda(0) * cp.normal;         // on rod 0
  // D lambda is that force at those points.
  EXPECT_LT((r.contact_forces.segment<3>(0) - F0).norm(), 1e-12 * F0.norm());
  EXPECT_LT((r.contact_forces.segment<3>(6) + F0).norm(), 1e-12 * F0.norm());
  EXPECT_LT((r.contact_forces.segment<3>(3) - (cp.point_a - trial[0].x).cross(F0)).norm(), 1e-12 * F0.norm());
  EXPECT_LT((r.contact_forces.segment<3>(9) - (cp.point_b - trial[1].x).cross(Vec3(-F0))).norm(), 1e-12 * F0.norm());
  const sc::MassTensors m = sc::mass_tensors(rod);
  const Mat3 by_hand = eq16_by_hand(m, trial[0], cp.point_a, m, trial[1], cp.point_b, F0);
  const Mat3 sigma = sc::contact_step_stress(problem, r);
  const Mat3 virial = (trial[0].x - trial[1].x) * F0.transpose();
  std::printf("[two rods] lambda = %.6g, tr sigma / 3 = %.6g, |geometric| / |sigma| = %.3g, asymmetry %.3g\n",
              r.lambda(0), sc::collision_pressure(sigma), (sigma - virial).norm() / sigma.norm(),
              (sigma - sigma.transpose()).norm() / sigma.norm());
  EXPECT_LT(rel(sigma, by_hand), 1e-12);
  EXPECT_NEAR(sigma.trace(), virial.trace(), 1e-13 * sigma.norm());
  EXPECT_GT((sigma - virial).norm(), 1e-2 * sigma.norm());  // the geometric part matters here
  EXPECT_GT(sigma.trace(), 0.0);                              // a push: positive pressure
  EXPECT_LT((sigma - sigma.transpose()).norm(), 1e-13 * sigma.norm());
  const std::vector<Mat3> per_pair = sc::contact_step_pair_stresses(problem, r);
  ASSERT_EQ(per_pair.size(), 1u);
  EXPECT_EQ(per_pair[0], sigma);
  // Density cancels here too.
  EXPECT_LT(rel(sc::contact_step_stress(problem, r, 3.7), sigma), 1e-13);
  // A result without columns is refused.
  sc::ContactStepResult stripped = r;
  stripped.columns.clear();
  expect_rejects([&] { sc::contact_step_stress(problem, stripped); }, "result.columns");
}

// Boomerangs with d^S directions (many node pairs per contact): the per-pair stresses summed
// equal eq. 12-15 applied to each body's total force and torque D lambda at Q* (open space:
// sum_pairs x_b F_b = x_b sum_pairs F_b), and the stress is symmetric (every node pair's force
// is along its own normal, so each column's torques balance).
TEST(CollisionStress, SurfaceContactStepOfBoomerangsIsTheStressOfDLambda) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const std::vector<sc::Boomerang> shapes{b};
  Rng rng(41);
  std::size_t checked = 0;
  for (int attempt = 0; attempt < 40 && checked < 3; ++attempt) {
    std::vector<sc::Pose> poses;
    while (poses.size() < 4) {
      const sc::Pose p{uniform_vector(rng, 0.0, 3.0), random_rotation(rng)};
      bool ok = true;
      for (const sc::Pose& q : poses) ok = ok && sc::closest_points(b, p, b, q).distance > 0.05;
      if (ok) poses.push_back(p);
    }
    sc::VecX U(24);
    sc::Vec3 centre = sc::Vec3::Zero();
    for (const sc::Pose& p : poses) centre += p.x / 4.0;
    for (Eigen::Index i = 0; i < 4; ++i) {
      U.segment<3>(6 * i) = 2.0 * (centre - poses[static_cast<std::size_t>(i)].x);
      U.segment<3>(6 * i + 3) = random_unit_vector(rng);
    }
    const sc::ContactStepProblem<sc::Boomerang> problem{shapes, poses, U, 0.05, 0.02, 0.0, 1.0, {}};
    sc::FreeDrainingMobility mobility(sc::spherocylinder_mobility(sc::Spherocylinder{4.0, 0.5}, 1.0), poses.size(), 6);
    sc::ContactStepOptions options;
    options.directions = sc::ContactDirections::surface;
    const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, options);
    if (r.status != sc::ContactStepStatus::converged || r.lambda_max <= 0.0) continue;
    ++checked;
    const std::vector<sc::Pose> trial = sc::advance_all(std::span<const sc::Pose>(poses), U, 6, problem.dt);
    Mat3 from_forces = Mat3::Zero();
    double trace = 0.0;
    for (std::size_t k = 0; k < 4; ++k) {
      const auto row = static_cast<Eigen::Index>(6 * k);
      const Vec3 F = r.contact_forces.segment<3>(row), T = r.contact_forces.segment<3>(row + 3);
      from_forces += trial[k].x * F.transpose() + eq15_by_hand(sc::mass_tensors(b), trial[k], T);
      trace += trial[k].x.dot(F);
    }
    const Mat3 sigma = sc::contact_step_stress(problem, r);
    std::printf("[boomerangs d^S, attempt %d] pairs %zu, lambda_max %.4g, rel. difference to D lambda %.3g, "
                "asymmetry %.3g\n",
                attempt, r.pairs.size(), r.lambda_max, rel(sigma, from_forces),
                (sigma - sigma.transpose()).norm() / sigma.norm());
    EXPECT_LT(rel(sigma, from_forces), 1e-12);
    EXPECT_NEAR(sigma.trace(), trace, 1e-12 * sigma.norm());
    EXPECT_LT((sigma - sigma.transpose()).norm(), 1e-12 * sigma.norm());
  }
  EXPECT_EQ(checked, 3u) << "the scenes did not collide: the test needs contacts";
}

// Eq. 51-52 per volume: for a hand-made set of pair stresses, Z = 1 + sum tr / (3 N kT), the
// virial equation of state P V = N kT + (1/3) sum r . F.
TEST(CollisionStress, SystemStressAndPressure) {
  Rng rng(51);
  const std::size_t bodies = 40;
  const double V = 1000.0, kT = 0.8;
  Mat3 sum = Mat3::Zero();
  double virial = 0.0;
  for (int c = 0; c < 25; ++c) {
    const Vec3 d = uniform_vector(rng, -2, 2), F = uniform_vector(rng, -3, 3);
    sum += d * F.transpose();
    virial += d.dot(F);
  }
  const Mat3 Sigma = sc::system_stress(sum, bodies, V, kT);
  const double n = static_cast<double>(bodies) / V;
  EXPECT_LT(rel(Sigma, Mat3(n * kT * Mat3::Identity() + sum / V)), 1e-15);
  const double P = sc::system_pressure(Sigma);
  EXPECT_NEAR(P * V, static_cast<double>(bodies) * kT + virial / 3.0, 1e-12 * std::abs(P * V));
  const double Z = sc::compressibility_factor(P, n, kT);
  EXPECT_NEAR(Z, 1.0 + virial / (3.0 * static_cast<double>(bodies) * kT), 1e-13);
  EXPECT_NEAR(Z, 1.0 + sc::collision_pressure_per_body(sum, bodies) / kT, 1e-13);
  EXPECT_EQ(sc::compressibility_factor(sc::system_pressure(sc::system_stress(Mat3::Zero(), bodies, V, kT)), n, kT), 1.0);
  expect_rejects([&] { sc::system_stress(sum, bodies, 0.0, kT); }, "volume");
  expect_rejects([&] { sc::system_stress(sum, 0, V, kT); }, "bodies");
  expect_rejects([&] { sc::compressibility_factor(P, n, 0.0); }, "kT");
}

// The contact observer: once per committed contact sub-step, with that sub-step's problem and
// lambda; a failed attempt that was sub-stepped is never reported, nor a step that failed.
using SphereStepper = sc::TimeStepper<sc::Sphere, sc::FreeDrainingMobility>;

TEST(CollisionStress, ContactObserverSeesCommittedSubStepsOnly) {
  const double mu = 1.0 / (6.0 * std::numbers::pi), dt = 0.02, d_hat = 0.01;
  int calls = 0;
  bool fail_next = false;
  std::vector<sc::VecX> returned;  // lambda of every successful solve, in order
  std::vector<double> returned_dt;
  SphereStepper::CustomContactSolver solver = [&](const sc::ContactStepProblem<sc::Sphere>& p,
                                                  sc::FreeDrainingMobility& m, const sc::ContactStepOptions& o) {
    ++calls;
    sc::ContactStepResult r = sc::solve_contact_step(p, m, o);
    if (fail_next) {  // an attempt with forces that must not be reported
      fail_next = false;
      EXPECT_GT(r.lambda_max, 0.0);
      r.status = sc::ContactStepStatus::failed_separation;
      r.message = "failed separation (provoked)";
    } else {
      returned.push_back(r.lambda);
      returned_dt.push_back(p.dt);
    }
    return r;
  };
  auto mobility = sc::FreeDrainingMobility(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), 2, 3);
  sc::TimeStepperOptions o;
  o.dt = dt;
  o.d_hat = d_hat;
  SphereStepper stepper({sc::Sphere{1.0}}, {{Vec3(0, 0, 0), sc::Quat::Identity()}, {Vec3(2.03, 0, 0), sc::Quat::Identity()}},
                        mobility, solver, o);
  sc::VecX F(6);
  F << 1.0 / mu, 0, 0, -1.0 / mu, 0, 0;  // speed 1 each: closes 0.04 per step
  stepper.set_external_forces(F);
  struct Seen {
    sc::VecX lambda;
    double dt;
    double pressure;
    double expected_pressure;  // lambda |x1* - x0*| / 3 by hand, x* = x + dt U (spheres translate)
    long steps_taken;
  };
  std::vector<Seen> seen;
  std::vector<std::string> order;
  stepper.add_contact_observer([&](const sc::ContactStepProblem<sc::Sphere>& p, const sc::ContactStepResult& r) {
    const double gap = (p.poses[1].x + p.dt * p.U.segment<3>(3) - p.poses[0].x - p.dt * p.U.segment<3>(0)).norm();
    seen.push_back({r.lambda, p.dt, sc::collision_pressure(sc::contact_step_stress(p, r)),
                    r.lambda.size() == 1 ? r.lambda(0) * gap / 3.0 : 0.0, stepper.steps_taken()});
    order.push_back("contact");
  });
  stepper.add_step_observer([&](const sc::StepDiagnostics&, std::span<const sc::Pose>) { order.push_back("step"); });
  // Step 1: the first attempt "fails", the two halves succeed.
  fail_next = true;
  const sc::StepDiagnostics d1 = stepper.step();
  EXPECT_EQ(d1.substeps, 2);
  EXPECT_EQ(calls, 3);
  ASSERT_EQ(returned.size(), 2u);
  ASSERT_EQ(seen.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(seen[k].lambda, returned[k]) << "sub-step " << k;
    EXPECT_EQ(seen[k].dt, 0.5 * dt);
    EXPECT_EQ(seen[k].steps_taken, 1);  // after the commit
  }
  EXPECT_EQ(order, (std::vector<std::string>{"contact", "contact", "step"}));
  // Step 2: one contact step, in contact: a positive collision pressure.
  stepper.step();
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[2].lambda, returned[2]);
  EXPECT_EQ(seen[2].dt, dt);
  ASSERT_EQ(seen[2].lambda.size(), 1);
  EXPECT_GT(seen[2].lambda(0), 0.0);
  EXPECT_GT(seen[2].pressure, 0.0);
  // Spheres, dofs 3: the stress is the virial term at Q*, its trace lambda |x1* - x0*| / 3.
  EXPECT_NEAR(seen[2].pressure, seen[2].expected_pressure, 1e-12 * seen[2].pressure);
  // A step that fails altogether reports nothing, and the next one only itself.
  sc::TimeStepperOptions strict = o;
  strict.max_substep_halvings = 0;
  int strict_seen = 0;
  std::vector<double> strict_lambda;
  SphereStepper::CustomContactSolver flaky = [&](const sc::ContactStepProblem<sc::Sphere>& p,
                                                 sc::FreeDrainingMobility& m, const sc::ContactStepOptions& opt) {
    sc::ContactStepResult r = sc::solve_contact_step(p, m, opt);
    if (fail_next) {
      fail_next = false;
      r.status = sc::ContactStepStatus::failed_separation;
      r.message = "failed separation (provoked)";
    } else {
      strict_lambda.push_back(r.lambda_sum);
    }
    return r;
  };
  auto mobility2 = sc::FreeDrainingMobility(sc::sphere_mobility(sc::Sphere{1.0}, 1.0), 2, 3);
  SphereStepper s2({sc::Sphere{1.0}}, stepper.poses(), mobility2, flaky, strict);
  s2.set_external_forces(F);
  s2.add_contact_observer([&](const sc::ContactStepProblem<sc::Sphere>&, const sc::ContactStepResult& r) {
    ++strict_seen;
    EXPECT_EQ(r.lambda_sum, strict_lambda.back());
  });
  fail_next = true;
  EXPECT_THROW(s2.step(), std::runtime_error);
  EXPECT_EQ(strict_seen, 0);
  s2.step();
  EXPECT_EQ(strict_seen, 1);
  expect_rejects([&] { s2.add_contact_observer(nullptr); }, "contact_observer");
}

}  // namespace

}  // namespace collision_stress_tests
