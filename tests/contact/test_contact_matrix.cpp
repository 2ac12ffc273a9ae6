#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/contact_matrix.hpp"
#include "stokescontact/core/rigid_motion.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace contact_matrix_tests {

namespace sc = stokescontact;
using test_support::expect_rejects;
using test_support::uniform;
using test_support::uniform_vector;
using sc::Pose;
using sc::Vec3;
using sc::VecX;

namespace {

// Force and torque of body b in column k of a dense D with 6 dofs per body.
Vec3 force(const sc::MatX& d, Eigen::Index k, Eigen::Index b) { return d.block<3, 1>(6 * b, k); }
Vec3 torque(const sc::MatX& d, Eigen::Index k, Eigen::Index b) { return d.block<3, 1>(6 * b + 3, k); }

// A pose for body b near body a: centre at a random direction and distance in [lo, hi].
Pose pose_nearby(std::mt19937_64& rng, const Pose& a, double lo, double hi) {
  const Vec3 dir = test_support::random_unit_vector(rng);
  return {a.x + uniform(rng, lo, hi) * dir, test_support::random_rotation(rng)};
}

VecX stack(const Vec3& ua, const Vec3& wa, const Vec3& ub, const Vec3& wb) {
  VecX u(12);
  u << ua, wa, ub, wb;
  return u;
}

// D^T U for one pair against the central difference of d^P under the rigid motions
// advance(pose, u, omega, +-h): D^T U must be dd/dt, the test that fixes signs and lever arms.
// h = 1e-6: truncation ~ h^2 |d'''| and rounding ~ 1e-16 / h, far below 1e-6 (1 + |U|).
// Configurations whose centre curves come within 0.05 of meeting (no unique normal) are
// skipped; the count of checked ones is required to be large.
template <sc::Shape A, sc::Shape B>
void expect_rate_matches_finite_difference(const A& a, const B& b, double lo, double hi, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  int checked = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const Pose pa{uniform_vector(rng, -2.0, 2.0), test_support::random_rotation(rng)};
    const Pose pb = pose_nearby(rng, pa, lo, hi);
    const VecX u = stack(uniform_vector(rng, -1, 1), uniform_vector(rng, -1, 1), uniform_vector(rng, -1, 1),
                         uniform_vector(rng, -1, 1));
    const sc::ClosestPoints cp = sc::closest_points(a, pa, b, pb);
    if (cp.distance + a.radius + b.radius < 0.05) continue;
    const std::vector<Pose> poses = {pa, pb};
    const std::vector<sc::ContactPair> pair = {{0, 1, Vec3::Zero(), cp, std::nullopt, std::nullopt}};
    const double rate = (sc::contact_matrix(pair, poses).transpose() * u)(0);
    const double h = 1e-6;
    auto distance_at = [&](double t) {
      return sc::closest_points(a, sc::advance(pa, u.segment<3>(0), u.segment<3>(3), t), b,
                                sc::advance(pb, u.segment<3>(6), u.segment<3>(9), t))
          .distance;
    };
    const double fd = (distance_at(h) - distance_at(-h)) / (2.0 * h);
    EXPECT_NEAR(rate, fd, 1e-6 * (1.0 + u.norm())) << "seed " << seed << " trial " << trial;
    ++checked;
  }
  EXPECT_GT(checked, 100) << "seed " << seed;
}

// Newton's third law for every column: forces on the two bodies cancel exactly; in open
// space the total torque about the origin, sum of torque + x x force, vanishes to 1e-14
// relative to the positions' size (surface columns: 1e-13, a sum over many node pairs).
void expect_newton_third_law(const Eigen::SparseMatrix<double>& d_sparse, const std::vector<Pose>& poses,
                             double torque_tolerance) {
  const sc::MatX d(d_sparse);
  for (Eigen::Index k = 0; k < d.cols(); ++k) {
    std::vector<Eigen::Index> bodies;
    for (Eigen::Index b = 0; b < static_cast<Eigen::Index>(poses.size()); ++b)
      if (d.col(k).segment<6>(6 * b).squaredNorm() > 0.0) bodies.push_back(b);
    ASSERT_EQ(bodies.size(), 2u) << "column " << k;
    Vec3 f = Vec3::Zero(), t = Vec3::Zero();
    double scale = 1.0;
    for (const Eigen::Index b : bodies) {
      const Vec3 x = poses[static_cast<std::size_t>(b)].x;
      f += force(d, k, b);
      t += torque(d, k, b) + x.cross(force(d, k, b));
      scale = std::max(scale, x.norm());
    }
    EXPECT_EQ(f.norm(), 0.0) << "column " << k;
    EXPECT_LT(t.norm(), torque_tolerance * scale) << "column " << k;
  }
}

// A common rigid motion of the whole scene (translation u, rotation omega about c) changes
// no distance: D^T U = 0. Body j moves as its image does, so this checks the image's lever arms.
void expect_rigid_motion_invariance(const Eigen::SparseMatrix<double>& d_sparse, const std::vector<Pose>& poses,
                                    const std::vector<Vec3>& shifts_j, const std::vector<Eigen::Index>& js,
                                    std::mt19937_64& rng) {
  const sc::MatX d(d_sparse);
  const Vec3 u = uniform_vector(rng, -1, 1), omega = uniform_vector(rng, -1, 1), c = uniform_vector(rng, -5, 5);
  for (Eigen::Index k = 0; k < d.cols(); ++k) {
    VecX velocity = VecX::Zero(d.rows());
    for (Eigen::Index b = 0; b < static_cast<Eigen::Index>(poses.size()); ++b) {
      // The column's body j moves with the image it was built with; every other body as is.
      const Vec3 x = poses[static_cast<std::size_t>(b)].x +
                     (b == js[static_cast<std::size_t>(k)] ? shifts_j[static_cast<std::size_t>(k)] : Vec3::Zero());
      velocity.segment<3>(6 * b) = u + omega.cross(x - c);
      velocity.segment<3>(6 * b + 3) = omega;
    }
    EXPECT_NEAR(d.col(k).dot(velocity), 0.0, 1e-12 * (1.0 + velocity.norm())) << "column " << k;
  }
}

template <sc::Shape S>
void check_scene_columns(const S& shape, double box_length, int n, double d_try, std::uint64_t seed) {
  const sc::SurfaceNodes nodes = sc::surface_nodes(shape, 0.15);
  for (const bool periodic : {false, true}) {
    std::mt19937_64 rng(seed);
    const auto poses = test_support::random_poses(n, 0.0, box_length, rng);
    std::optional<sc::PeriodicBox> box;
    if (periodic) box = sc::PeriodicBox{Vec3::Constant(box_length)};
    const auto pairs = sc::find_contact_pairs(shape, poses, d_try, box);
    const auto contacts = sc::find_surface_contacts(shape, poses, nodes, d_try, box);
    ASSERT_GT(pairs.size(), 5u) << "seed " << seed;
    const auto dp = sc::contact_matrix(pairs, poses);
    const auto ds = sc::surface_contact_matrix(contacts, poses, d_try);
    ASSERT_EQ(dp.rows(), 6 * n);
    ASSERT_EQ(dp.cols(), static_cast<Eigen::Index>(pairs.size()));
    ASSERT_EQ(dp.nonZeros(), 12 * dp.cols());
    ASSERT_EQ(ds.cols(), dp.cols());
    std::vector<Vec3> shifts;
    std::vector<Eigen::Index> js;
    for (const auto& p : pairs) {
      shifts.push_back(p.image_shift);
      js.push_back(p.j);
    }
    expect_rigid_motion_invariance(dp, poses, shifts, js, rng);
    expect_rigid_motion_invariance(ds, poses, shifts, js, rng);
    if (!periodic) {
      expect_newton_third_law(dp, poses, 1e-14);
      expect_newton_third_law(ds, poses, 1e-13);
    }
    // Both columns have a unit net force unless the surface column's floor applies.
    const sc::MatX dense_p(dp), dense_s(ds);
    for (Eigen::Index k = 0; k < dp.cols(); ++k) {
      const Eigen::Index j = pairs[static_cast<std::size_t>(k)].j;
      EXPECT_NEAR(force(dense_p, k, j).norm(), 1.0, 1e-14);
      EXPECT_LE(force(dense_s, k, j).norm(), 1.0 + 1e-14);
    }
  }
}

}  // namespace

TEST(ContactMatrix, RateOfRodPairDistance) {
  const sc::Spherocylinder rod{2.0, 0.4};
  expect_rate_matches_finite_difference(rod, rod, 0.5, 2.5, 101);
}

TEST(ContactMatrix, RateOfBoomerangPairDistance) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  expect_rate_matches_finite_difference(b, b, 0.5, 3.0, 102);
}

TEST(ContactMatrix, RateOfMixedPairDistances) {
  const sc::Spherocylinder rod{1.5, 0.3};
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const sc::Sphere sphere{0.6};
  expect_rate_matches_finite_difference(rod, b, 0.5, 3.0, 103);
  expect_rate_matches_finite_difference(sphere, b, 0.5, 2.5, 104);
  expect_rate_matches_finite_difference(rod, sphere, 0.5, 2.0, 105);
  expect_rate_matches_finite_difference(sphere, sphere, 0.8, 2.0, 106);
}

// In a periodic box the column uses the image of body j: D^T U matches the central
// difference of the distance to that image.
TEST(ContactMatrix, RateAcrossPeriodicBoundary) {
  const sc::Spherocylinder rod{2.0, 0.4};
  const sc::PeriodicBox box{Vec3::Constant(8.0)};
  std::mt19937_64 rng(107);
  const auto poses = test_support::random_poses(40, 0.0, 8.0, rng);
  const auto pairs = sc::find_contact_pairs(rod, poses, 0.4, box);
  const sc::MatX d(sc::contact_matrix(pairs, poses));
  const VecX u = VecX::NullaryExpr(6 * 40, [&] { return uniform(rng, -1, 1); });
  int across = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& p = pairs[k];
    if (p.points.distance + 2 * rod.radius < 0.05) continue;
    across += p.image_shift != Vec3::Zero();
    const auto i = static_cast<std::size_t>(p.i), j = static_cast<std::size_t>(p.j);
    auto distance_at = [&](double t) {
      const Pose a = sc::advance(poses[i], u.segment<3>(6 * p.i), u.segment<3>(6 * p.i + 3), t);
      const Pose b = sc::advance(poses[j], u.segment<3>(6 * p.j), u.segment<3>(6 * p.j + 3), t);
      return sc::closest_points(rod, a, rod, sc::shifted(b, p.image_shift)).distance;
    };
    const double h = 1e-6;
    EXPECT_NEAR(d.col(static_cast<Eigen::Index>(k)).dot(u), (distance_at(h) - distance_at(-h)) / (2 * h), 1e-5)
        << "pair " << k;
  }
  EXPECT_GT(across, 0);
}

// lambda > 0 pushes apart: with U = D e_k (an identity mobility), dd_k/dt = |D e_k|^2 > 0.
TEST(ContactMatrix, PositiveMagnitudeSeparatesBodies) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  std::mt19937_64 rng(108);
  for (int trial = 0; trial < 50; ++trial) {
    const Pose pa{Vec3::Zero(), test_support::random_rotation(rng)};
    const Pose pb = pose_nearby(rng, pa, 1.0, 2.5);
    const std::vector<Pose> poses = {pa, pb};
    const std::vector<sc::ContactPair> pair = {{0, 1, Vec3::Zero(), sc::closest_points(b, pa, b, pb), std::nullopt, std::nullopt}};
    if (pair[0].points.distance + 2 * b.radius < 0.05) continue;  // curves (nearly) meet
    const VecX u = sc::MatX(sc::contact_matrix(pair, poses)).col(0);
    const double h = 1e-4;
    const double later = sc::closest_points(b, sc::advance(pa, u.segment<3>(0), u.segment<3>(3), h), b,
                                            sc::advance(pb, u.segment<3>(6), u.segment<3>(9), h))
                             .distance;
    EXPECT_GT(later, pair[0].points.distance) << "trial " << trial;
  }
}

// Two spheres: the column is -n, +n (n the unit centre-to-centre direction), no torque.
TEST(ContactMatrix, SphereColumnMatchesClosedForm) {
  const std::vector<sc::Sphere> spheres = {{0.5}, {0.8}};
  const Vec3 n = Vec3(1.0, -2.0, 0.5).normalized();
  std::mt19937_64 rng(109);
  const std::vector<Pose> poses = {{Vec3(0.1, 0.2, 0.3), test_support::random_rotation(rng)},
                                   {Vec3(0.1, 0.2, 0.3) + 1.35 * n, sc::Quat::Identity()}};
  const auto pairs = sc::find_contact_pairs(std::span<const sc::Sphere>(spheres), poses, 0.1);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_NEAR(pairs[0].points.distance, 0.05, 1e-15);
  const sc::MatX d3(sc::contact_matrix(pairs, poses, sc::contact_dofs_per_body<sc::Sphere>));
  ASSERT_EQ(d3.rows(), 6);
  EXPECT_LT((d3.col(0).head<3>() + n).norm(), 1e-15);
  EXPECT_LT((d3.col(0).tail<3>() - n).norm(), 1e-15);
  const sc::MatX d6(sc::contact_matrix(pairs, poses, 6));
  EXPECT_LT((force(d6, 0, 0) + n).norm(), 1e-15);
  EXPECT_LT((force(d6, 0, 1) - n).norm(), 1e-15);
  EXPECT_LT(torque(d6, 0, 0).norm(), 1e-15);
  EXPECT_LT(torque(d6, 0, 1).norm(), 1e-15);
}

TEST(ContactMatrix, RodScenesObeyNewtonAndRigidInvariance) {
  check_scene_columns(sc::Spherocylinder{2.0, 0.4}, 9.0, 50, 0.3, 111);
}

TEST(ContactMatrix, BoomerangScenesObeyNewtonAndRigidInvariance) {
  check_scene_columns(sc::broms_tornberg_boomerang(), 9.0, 30, 0.3, 112);
}

// Two spheres on the body z axis: the node rings are symmetric about the line of centres,
// so the surface-node column reduces to the d^P column exactly (to rounding).
TEST(ContactMatrix, SurfaceColumnOfAlignedSpheresIsParticleColumn) {
  const sc::Sphere s{1.0};
  const sc::SurfaceNodes nodes = sc::surface_nodes(s, 0.1);
  const std::vector<Pose> poses = {Pose{}, {Vec3(0.0, 0.0, 2.05), sc::Quat::Identity()}};
  const auto contacts = sc::find_surface_contacts(s, poses, nodes, 0.2);
  const auto pairs = sc::find_contact_pairs(s, poses, 0.2);
  ASSERT_EQ(contacts.size(), 1u);
  ASSERT_GT(contacts[0].distances.pairs.size(), 10u);
  const sc::MatX ds(sc::surface_contact_matrix(contacts, poses, 0.2)), dp(sc::contact_matrix(pairs, poses));
  EXPECT_LT((ds - dp).norm(), 1e-12);
  const sc::MatX ds3(sc::surface_contact_matrix(contacts, poses, 0.2, 3));
  EXPECT_LT((ds3 - sc::MatX(sc::contact_matrix(pairs, poses, 3))).norm(), 1e-12);
}

// Randomly oriented spheres: the node grid is no longer symmetric about the line of
// centres, and the surface column is the d^P column up to the grid's asymmetry (at h = 0.1 R
// measured: force direction within 7e-3 rad, torques below 1.6e-2; bounds 2e-2 and 5e-2).
TEST(ContactMatrix, SurfaceColumnOfSpheresIsCloseToParticleColumn) {
  const sc::Sphere s{1.0};
  const sc::SurfaceNodes nodes = sc::surface_nodes(s, 0.1);
  std::mt19937_64 rng(113);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pa{uniform_vector(rng, -1, 1), test_support::random_rotation(rng)};
    Pose pb = pose_nearby(rng, pa, 2.02, 2.1);
    const std::vector<Pose> poses = {pa, pb};
    const auto contacts = sc::find_surface_contacts(s, poses, nodes, 0.2);
    const auto pairs = sc::find_contact_pairs(s, poses, 0.2);
    ASSERT_EQ(contacts.size(), 1u);
    const sc::MatX ds(sc::surface_contact_matrix(contacts, poses, 0.2)), dp(sc::contact_matrix(pairs, poses));
    const double angle = std::acos(std::min(1.0, force(ds, 0, 1).dot(force(dp, 0, 1))));
    EXPECT_LT(angle, 2e-2) << "trial " << trial;
    EXPECT_NEAR(force(ds, 0, 1).norm(), 1.0, 1e-14);
    EXPECT_LT(torque(ds, 0, 0).norm() + torque(ds, 0, 1).norm(), 5e-2) << "trial " << trial;
  }
}

// eq. 23 by hand: node pairs along x at d = 0.05 and along y at d = 0.2 with d_try = 0.3
// weigh 1/0.05 = 20 and 1/0.2 = 5 (b0); an overlapping pair below the cap at
// 1e-2 d_try = 3e-3 weighs 1/3e-3.
TEST(ContactMatrix, SurfaceWeightsFollowB0) {
  const std::vector<Pose> poses = {Pose{}, {Vec3(3, 0, 0), sc::Quat::Identity()}};
  auto node_pair = [](const Vec3& a, const Vec3& n, double d) {
    sc::SurfacePair p;
    p.source = sc::PairSource::node_of_a;
    p.point_a = a;
    p.point_b = a + d * n;
    p.normal = n;
    p.distance = d;
    return p;
  };
  sc::SurfaceContact c{0, 1, Vec3::Zero(), {}};
  c.distances.pairs = {node_pair(Vec3(1, 0, 0), Vec3::UnitX(), 0.05), node_pair(Vec3(1, 0, 0), Vec3::UnitY(), 0.2)};
  sc::ContactColumn col = sc::surface_contact_column(c, poses, 0.3);
  EXPECT_LT((col.force_j - Vec3(20, 5, 0).normalized()).norm(), 1e-15);
  // Torque on i: -(s x n) weighted: only the y pair has a lever arm across its normal.
  EXPECT_LT((col.torque_i - (-5.0 * Vec3(1, 0, 0).cross(Vec3::UnitY())) / Vec3(20, 5, 0).norm()).norm(), 1e-15);

  c.distances.pairs.push_back(node_pair(Vec3(1, 0, 0), Vec3::UnitZ(), -0.1));
  col = sc::surface_contact_column(c, poses, 0.3);
  EXPECT_LT((col.force_j - Vec3(20, 5, 1.0 / 3e-3).normalized()).norm(), 1e-14);

  // A pair at d_try exactly weighs nothing.
  c.distances.pairs = {node_pair(Vec3(1, 0, 0), Vec3::UnitX(), 0.05), node_pair(Vec3(1, 0, 0), Vec3::UnitY(), 0.3)};
  EXPECT_LT((sc::surface_contact_column(c, poses, 0.3).force_j - Vec3::UnitX()).norm(), 1e-15);
}

// Node forces that cancel: the normalisation is floored at 1e-3 sum(w), so the column stays
// bounded: two pairs with opposite normals and lever arms (1, +-0.5, 0) give a pure torque.
TEST(ContactMatrix, SurfaceNormalisationFloorKeepsColumnBounded) {
  const std::vector<Pose> poses = {Pose{}, {Vec3(0, 0, 5), sc::Quat::Identity()}};
  sc::SurfaceContact c{0, 1, Vec3::Zero(), {}};
  sc::SurfacePair p1, p2;
  p1.point_a = Vec3(1, 0.5, 0), p1.normal = Vec3::UnitX(), p1.distance = 0.1;
  p1.point_b = p1.point_a + 0.1 * p1.normal;
  p2.point_a = Vec3(-1, -0.5, 0), p2.normal = -Vec3::UnitX(), p2.distance = 0.1;
  p2.point_b = p2.point_a + 0.1 * p2.normal;
  c.distances.pairs = {p1, p2};
  const sc::ContactColumn col = sc::surface_contact_column(c, poses, 0.3);
  EXPECT_LT(col.force_j.norm(), 1e-15);
  // torque_i = -(10 (s1 x n1) + 10 (s2 x n2)) / (1e-3 * 20), s x n = (0, 0, -0.5) for both.
  EXPECT_LT((col.torque_i - Vec3(0, 0, 500)).norm(), 1e-10);
}

TEST(ContactMatrix, RejectsBadInput) {
  const std::vector<Pose> poses = {Pose{}, {Vec3(1.05, 0, 0), sc::Quat::Identity()}};
  const sc::Sphere s{0.5};
  const auto pairs = sc::find_contact_pairs(s, poses, 0.1);
  ASSERT_EQ(pairs.size(), 1u);
  expect_rejects([&] { sc::contact_matrix(pairs, poses, 4); }, "dofs_per_body");
  const std::vector<Pose> one = {Pose{}};
  expect_rejects([&] { sc::contact_matrix(pairs, one); }, "pairs[0]");
  std::vector<sc::ContactPair> bad = pairs;
  bad[0].points.normal *= 2.0;
  expect_rejects([&] { sc::contact_matrix(bad, poses); }, "pairs[0].points");
  bad = pairs;
  bad[0].j = 0;
  expect_rejects([&] { sc::contact_matrix(bad, poses); }, "pairs[0]");
  std::vector<Pose> bad_poses = poses;
  bad_poses[1].x.x() = std::nan("");
  expect_rejects([&] { sc::contact_matrix(pairs, bad_poses); }, "poses[1].x");
  expect_rejects([&] { sc::find_contact_pairs(s, poses, -1e-3); }, "d_try");
  const sc::SurfaceNodes nodes = sc::surface_nodes(s, 0.2);
  expect_rejects([&] { sc::find_surface_contacts(s, poses, nodes, -1e-3); }, "d_try");
  const auto contacts = sc::find_surface_contacts(s, poses, nodes, 0.1);
  expect_rejects([&] { sc::surface_contact_matrix(contacts, poses, -0.1); }, "d_try");
  expect_rejects([&] { sc::surface_contact_matrix(contacts, poses, 0.0); }, "d_try");
  expect_rejects([&] { sc::surface_contact_matrix(contacts, one, 0.1); }, "contacts[0]");
  expect_rejects([&] { sc::surface_contact_matrix(contacts, poses, 0.1, 6, {.min_net_force_fraction = 0.0}); },
                 "SurfaceWeights.min_net_force_fraction");
  const std::vector<sc::ContactColumn> columns = {{0, 2}};
  expect_rejects([&] { sc::assemble_contact_matrix(columns, 2, 6); }, "columns[0]");
  const std::vector<sc::ContactColumn> same_body = {{0, 1}, {1, 1}};
  expect_rejects([&] { sc::assemble_contact_matrix(same_body, 2, 3); }, "columns[1]");
}

// assemble_contact_matrix fills compressed column storage directly: the same matrix, entry
// for entry (explicit zeros and the order of each column's rows included), as the triplets
// of its definition through Eigen's setFromTriplets; pairs given as (i, j) and as (j, i).
TEST(ContactMatrix, AssemblyIsTheTripletsMatrixEntryForEntry) {
  std::mt19937_64 rng(31);
  for (const int dofs : {3, 6}) {
    const std::size_t bodies = 40;
    std::vector<sc::ContactColumn> columns;
    for (int k = 0; k < 300; ++k) {
      const auto i = static_cast<Eigen::Index>(rng() % bodies);
      const auto j = static_cast<Eigen::Index>((static_cast<std::size_t>(i) + 1 + rng() % (bodies - 1)) % bodies);
      sc::ContactColumn c{i, j, uniform_vector(rng, -1.0, 1.0), uniform_vector(rng, -1.0, 1.0),
                          uniform_vector(rng, -1.0, 1.0)};
      if (k % 7 == 0) c.force_j.y() = 0.0;  // an explicit zero stays an entry
      columns.push_back(c);
    }
    std::vector<Eigen::Triplet<double>> entries;
    for (std::size_t k = 0; k < columns.size(); ++k) {
      const sc::ContactColumn& c = columns[k];
      const auto col = static_cast<Eigen::Index>(k);
      for (int r = 0; r < 3; ++r) {
        entries.emplace_back(c.i * dofs + r, col, -c.force_j[r]);
        entries.emplace_back(c.j * dofs + r, col, c.force_j[r]);
        if (dofs == 6) {
          entries.emplace_back(c.i * dofs + 3 + r, col, c.torque_i[r]);
          entries.emplace_back(c.j * dofs + 3 + r, col, c.torque_j[r]);
        }
      }
    }
    Eigen::SparseMatrix<double> expected(static_cast<Eigen::Index>(bodies) * dofs,
                                         static_cast<Eigen::Index>(columns.size()));
    expected.setFromTriplets(entries.begin(), entries.end());
    const Eigen::SparseMatrix<double> d = sc::assemble_contact_matrix(columns, bodies, dofs);
    ASSERT_EQ(d.rows(), expected.rows());
    ASSERT_EQ(d.cols(), expected.cols());
    ASSERT_EQ(d.nonZeros(), expected.nonZeros());
    ASSERT_TRUE(d.isCompressed());
    for (Eigen::Index k = 0; k <= d.cols(); ++k) EXPECT_EQ(d.outerIndexPtr()[k], expected.outerIndexPtr()[k]);
    for (Eigen::Index e = 0; e < d.nonZeros(); ++e) {
      EXPECT_EQ(d.innerIndexPtr()[e], expected.innerIndexPtr()[e]) << "entry " << e << ", dofs " << dofs;
      EXPECT_EQ(d.valuePtr()[e], expected.valuePtr()[e]) << "entry " << e << ", dofs " << dofs;
    }
  }
  EXPECT_EQ(sc::assemble_contact_matrix({}, 5, 6).nonZeros(), 0);
}

// A contact step appends pairs: D grown column batch by column batch is the matrix assembled
// at once, entry for entry, and M D of a block-diagonal M grown with it is Eigen's sparse
// product M * D, entry for entry (bit for bit: the same sums in the same order), for a dense
// 6 x 6 block per body and for a diagonal one (spheres' 3 x 3). A matrix that is not block
// diagonal, or an MD that is not D's first columns, is refused naming it.
TEST(ContactMatrix, AppendedColumnsAndBlockProductAreTheWholeAssembly) {
  std::mt19937_64 rng(37);
  for (const int dofs : {3, 6}) {
    const std::size_t bodies = 30;
    const auto rows = static_cast<Eigen::Index>(bodies) * dofs;
    std::vector<sc::ContactColumn> columns;
    for (int k = 0; k < 200; ++k) {
      const auto i = static_cast<Eigen::Index>(rng() % bodies);
      const auto j = static_cast<Eigen::Index>((static_cast<std::size_t>(i) + 1 + rng() % (bodies - 1)) % bodies);
      columns.push_back({i, j, uniform_vector(rng, -1.0, 1.0), uniform_vector(rng, -1.0, 1.0),
                         uniform_vector(rng, -1.0, 1.0)});
    }
    std::vector<Eigen::Triplet<double>> blocks;
    for (Eigen::Index b = 0; b < static_cast<Eigen::Index>(bodies); ++b)
      for (int r = 0; r < dofs; ++r)
        for (int c = 0; c < dofs; ++c)
          if (dofs == 6 || r == c) blocks.emplace_back(b * dofs + r, b * dofs + c, uniform(rng, -1.0, 1.0));
    Eigen::SparseMatrix<double> M(rows, rows);
    M.setFromTriplets(blocks.begin(), blocks.end());
    const Eigen::SparseMatrix<double> whole = sc::assemble_contact_matrix(columns, bodies, dofs);
    const Eigen::SparseMatrix<double> product = M * whole;
    Eigen::SparseMatrix<double> d, md;
    for (const std::size_t upto : {std::size_t{0}, std::size_t{70}, std::size_t{71}, std::size_t{200}}) {
      const std::span<const sc::ContactColumn> batch(columns.data(), upto);
      sc::append_contact_columns(d, batch, bodies, dofs);
      sc::append_block_diagonal_product(md, M, d, bodies);
      ASSERT_EQ(d.cols(), static_cast<Eigen::Index>(upto));
      ASSERT_EQ(md.cols(), static_cast<Eigen::Index>(upto));
    }
    ASSERT_EQ(d.nonZeros(), whole.nonZeros());
    for (Eigen::Index k = 0; k <= d.cols(); ++k) EXPECT_EQ(d.outerIndexPtr()[k], whole.outerIndexPtr()[k]);
    for (Eigen::Index e = 0; e < d.nonZeros(); ++e) {
      EXPECT_EQ(d.innerIndexPtr()[e], whole.innerIndexPtr()[e]);
      EXPECT_EQ(d.valuePtr()[e], whole.valuePtr()[e]);
    }
    for (Eigen::Index k = 0; k < product.outerSize(); ++k)
      for (Eigen::SparseMatrix<double>::InnerIterator it(product, k); it; ++it)
        EXPECT_EQ(md.coeff(it.row(), it.col()), it.value()) << "dofs " << dofs << ", (" << it.row() << ", " << it.col() << ")";
    EXPECT_EQ(Eigen::MatrixXd(md - product).cwiseAbs().maxCoeff(), 0.0);

    Eigen::SparseMatrix<double> coupled = M;
    coupled.coeffRef(0, dofs) = 1.0;  // body 0 driven by body 1: not block diagonal
    Eigen::SparseMatrix<double> empty;
    expect_rejects([&] { sc::append_block_diagonal_product(empty, coupled, whole, bodies); }, "M");
    Eigen::SparseMatrix<double> longer = product;  // more columns than the D it should belong to
    longer.makeCompressed();
    const Eigen::SparseMatrix<double> first_ten = whole.leftCols(10);
    expect_rejects([&] { sc::append_block_diagonal_product(longer, M, first_ten, bodies); }, "MD");
    Eigen::SparseMatrix<double> too_many = whole;
    expect_rejects([&] { sc::append_contact_columns(too_many, std::span<const sc::ContactColumn>(columns.data(), 10), bodies, dofs); },
                   "d");
  }
}

}  // namespace contact_matrix_tests
