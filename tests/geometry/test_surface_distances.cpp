#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokescontact/geometry/surface_distances.hpp"
#include "common/test_support.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace surface_distances_tests {

namespace sc = stokescontact;
using sc::PairSource;
using sc::Pose;
using sc::Vec3;

namespace {

// Tolerance on d^S >= d^P and on the d^P pair, relative to the bodies' size.
constexpr double kTol = 1e-10;

using test_support::random_rotation;
using test_support::uniform;

// Dense samples of a centre curve in the world frame, and the largest gap between
// neighbouring samples along it: a sampled distance overestimates the true one by at most
// half that gap.
template <std::size_t NS, std::size_t NA>
std::vector<Vec3> sample_curve(const sc::CentreCurve<NS, NA>& c, int per_piece, double& gap) {
  std::vector<Vec3> out;
  gap = 0.0;
  for (const auto& s : c.segments) {
    for (int i = 0; i <= per_piece; ++i) out.push_back(s.point(static_cast<double>(i) / per_piece));
    gap = std::max(gap, s.length() / per_piece);
  }
  for (const auto& a : c.arcs) {
    for (int i = 0; i <= per_piece; ++i) out.push_back(a.point(a.angle * i / per_piece));
    gap = std::max(gap, a.length() / per_piece);
  }
  return out;
}

double sampled_distance(const std::vector<Vec3>& samples, const Vec3& x) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& s : samples) best = std::min(best, (x - s).squaredNorm());
  return std::sqrt(best);
}

template <typename S>
double distance_to_surface(const S& shape, const Pose& pose, const Vec3& x) {
  return sc::closest_point(sc::to_world(sc::centre_curve(shape), pose), x).distance - shape.radius;
}

// Brute force: every node of `src` whose sampled distance to `other` is below d_try is
// reported, and every reported distance agrees with the sampled one to the sampling error.
template <typename Other>
void expect_nodes_complete(const Pose& ps, const sc::SurfaceNodes& nodes, const Other& other,
                           const Pose& po, double d_try, const sc::SurfaceDistances& sd,
                           PairSource source) {
  double gap = 0.0;
  const auto samples = sample_curve(sc::to_world(sc::centre_curve(other), po), 200, gap);
  std::vector<double> reported(static_cast<std::size_t>(nodes.size()), std::nan(""));
  for (const auto& p : sd.pairs)
    if (p.source == source) reported[static_cast<std::size_t>(p.node)] = p.distance;
  for (Eigen::Index i = 0; i < nodes.size(); ++i) {
    const double sampled = sampled_distance(samples, ps.to_world(nodes.points.col(i))) - other.radius;
    const double r = reported[static_cast<std::size_t>(i)];
    if (sampled <= d_try) {
      ASSERT_FALSE(std::isnan(r)) << "node " << i << " missed, sampled distance " << sampled;
    }
    if (!std::isnan(r)) {
      EXPECT_LE(r, sampled + 1e-12) << "node " << i;
      EXPECT_GE(r, sampled - 0.5 * gap - 1e-12) << "node " << i;
    }
  }
}

template <typename A, typename B>
void check_configuration(const A& a, const Pose& pa, const sc::SurfaceNodes& na, const B& b,
                         const Pose& pb, const sc::SurfaceNodes& nb, double d_try) {
  const auto sd = sc::surface_distances(a, pa, na, b, pb, nb, d_try);
  const double scale = sc::bounding_radius(a) + sc::bounding_radius(b);
  const double dp = sd.particle.distance;
  int count_a = 0, count_b = 0, count_p = 0;
  std::set<Eigen::Index> seen_a, seen_b;
  for (const auto& p : sd.pairs) {
    EXPECT_LE(p.distance, d_try);
    EXPECT_GE(p.distance, dp - kTol * scale);  // d^S >= d^P
    EXPECT_NEAR(p.normal.norm(), 1.0, 1e-12);
    // The pair realises its distance along its normal, from a to b.
    EXPECT_LT((p.point_b - p.point_a - p.distance * p.normal).norm(), 1e-12 * scale);
    EXPECT_NEAR(std::abs(p.distance), (p.point_b - p.point_a).norm(), 1e-12 * scale);
    // Both points lie on their surfaces, one radius above their curve points.
    EXPECT_NEAR(distance_to_surface(a, pa, p.point_a), 0.0, 1e-12 * scale);
    EXPECT_NEAR(distance_to_surface(b, pb, p.point_b), 0.0, 1e-12 * scale);
    EXPECT_NEAR((p.point_a - p.curve_point_a).norm(), a.radius, 1e-12 * scale);
    EXPECT_NEAR((p.point_b - p.curve_point_b).norm(), b.radius, 1e-12 * scale);
    if (p.source == PairSource::node_of_a) {
      ++count_a;
      EXPECT_TRUE(seen_a.insert(p.node).second) << "node reported twice";
      EXPECT_LT((p.point_a - pa.to_world(na.points.col(p.node))).norm(), 1e-12 * scale);
    } else if (p.source == PairSource::node_of_b) {
      ++count_b;
      EXPECT_TRUE(seen_b.insert(p.node).second) << "node reported twice";
      EXPECT_LT((p.point_b - pb.to_world(nb.points.col(p.node))).norm(), 1e-12 * scale);
    } else {
      ++count_p;
      EXPECT_EQ(p.node, -1);
      EXPECT_EQ(p.distance, dp);
      EXPECT_EQ(p.point_a, sd.particle.point_a);
      EXPECT_EQ(p.point_b, sd.particle.point_b);
    }
  }
  // The d^P pair is present exactly when it is within the threshold, and listed first.
  EXPECT_EQ(count_p, dp <= d_try ? 1 : 0);
  if (count_p == 1) {
    EXPECT_EQ(sd.pairs.front().source, PairSource::closest_points);
  }
  // Closest surface points lie within the covering radius (< h) of a node, and distances
  // are 1-Lipschitz: so both directions have pairs once d^P <= d_try - h.
  if (dp <= d_try - std::max(na.spacing, nb.spacing)) {
    EXPECT_GT(count_a, 0);
    EXPECT_GT(count_b, 0);
  }
  expect_nodes_complete(pa, na, b, pb, d_try, sd, PairSource::node_of_a);
  expect_nodes_complete(pb, nb, a, pa, d_try, sd, PairSource::node_of_b);
}

// Random poses: a at a random place and orientation, b along a random direction at the
// offset where d^P (found by bisection) equals a random gap in [-0.1, 0.2] x d_try scale.
template <typename A, typename B>
void random_configurations(const A& a, double ha, const B& b, double hb, double d_try,
                           std::uint64_t seed0, int count) {
  const auto na = sc::surface_nodes(a, ha);
  const auto nb = sc::surface_nodes(b, hb);
  for (int k = 0; k < count; ++k) {
    const std::uint64_t seed = seed0 + static_cast<std::uint64_t>(k);
    SCOPED_TRACE("configuration seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    Pose pa, pb;
    pa.x = Vec3(uniform(rng, -2, 2), uniform(rng, -2, 2), uniform(rng, -2, 2));
    pa.q = random_rotation(rng);
    pb.q = random_rotation(rng);
    Vec3 dir(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    dir.normalize();
    const double target = uniform(rng, -0.1, 2.0) * d_try;
    double lo = 0.0, hi = sc::bounding_radius(a) + sc::bounding_radius(b) + 2.0 * d_try + 1.0;
    for (int it = 0; it < 50; ++it) {
      const double mid = 0.5 * (lo + hi);
      pb.x = pa.x + mid * dir;
      (sc::closest_points(a, pa, b, pb).distance < target ? lo : hi) = mid;
    }
    pb.x = pa.x + hi * dir;
    check_configuration(a, pa, na, b, pb, nb, d_try);
    if (::testing::Test::HasFailure()) return;  // one failing seed is enough
  }
}

}  // namespace

TEST(SurfaceDistances, SpheresHeadOn) {
  const sc::Sphere s{1.0};
  const auto nodes = sc::surface_nodes(s, 0.1);
  const Pose pa{Vec3::Zero(), sc::Quat::Identity()};
  const Pose pb{Vec3(2.05, 0, 0), sc::Quat::Identity()};
  const auto sd = sc::surface_distances(s, pa, nodes, s, pb, nodes, 0.1);
  EXPECT_NEAR(sd.particle.distance, 0.05, 1e-14);
  ASSERT_FALSE(sd.pairs.empty());
  EXPECT_EQ(sd.pairs.front().source, PairSource::closest_points);
  int from_a = 0, from_b = 0;
  for (const auto& p : sd.pairs) {
    if (p.source == PairSource::closest_points) continue;
    // For spheres: d = |node - other centre| - 1 and the normal is the centre-to-node
    // direction of the other sphere, reversed for a's nodes.
    const bool of_a = p.source == PairSource::node_of_a;
    const Vec3 node = of_a ? p.point_a : p.point_b;
    const Vec3 other = of_a ? pb.x : pa.x;
    EXPECT_NEAR(p.distance, (node - other).norm() - 1.0, 1e-14);
    const Vec3 u = (node - other).normalized();
    EXPECT_LT((p.normal - (of_a ? -u : u)).norm(), 1e-14);
    EXPECT_GT(p.normal.x(), 0.9);  // from a to b, along +x
    (of_a ? from_a : from_b) += 1;
  }
  EXPECT_GT(from_a, 0);
  EXPECT_GT(from_b, 0);
}

// Swapping the bodies swaps the sources and reverses the normals, pair for pair.
TEST(SurfaceDistances, SwappingBodiesMirrorsPairs) {
  const auto b = sc::broms_tornberg_boomerang();
  const sc::Spherocylinder rod{4.0, 0.5};
  const auto nb = sc::surface_nodes(b, 0.1), nr = sc::surface_nodes(rod, 0.1);
  const Pose pb{Vec3(0.1, 0.2, -0.3), sc::Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()))};
  const Pose pr{Vec3(0.9, 0.0, 1.6), sc::Quat(Eigen::AngleAxisd(1.9, Vec3(0, 1, 0)))};
  const auto ab = sc::surface_distances(b, pb, nb, rod, pr, nr, 0.3);
  const auto ba = sc::surface_distances(rod, pr, nr, b, pb, nb, 0.3);
  ASSERT_EQ(ab.pairs.size(), ba.pairs.size());
  ASSERT_GT(ab.pairs.size(), 2u);
  for (const auto& p : ab.pairs) {
    const PairSource mirrored = p.source == PairSource::node_of_a   ? PairSource::node_of_b
                                : p.source == PairSource::node_of_b ? PairSource::node_of_a
                                                                    : PairSource::closest_points;
    const auto q = std::find_if(ba.pairs.begin(), ba.pairs.end(), [&](const sc::SurfacePair& c) {
      return c.source == mirrored && c.node == p.node;
    });
    ASSERT_NE(q, ba.pairs.end());
    EXPECT_NEAR(q->distance, p.distance, 1e-12);
    EXPECT_LT((q->normal + p.normal).norm(), 1e-12);
    EXPECT_LT((q->point_a - p.point_b).norm(), 1e-12);
    EXPECT_LT((q->point_b - p.point_a).norm(), 1e-12);
  }
}

// A node exactly on the other body's centre curve has no shortest-distance direction:
// its own outward normal is used, and the pair still satisfies b - a = d n.
TEST(SurfaceDistances, NodeOnOtherCentreCurve) {
  const sc::Sphere s{1.0};
  const auto nodes = sc::surface_nodes(s, 0.3);
  Eigen::Index top = -1;  // the node at the north pole (0, 0, 1)
  for (Eigen::Index i = 0; i < nodes.size(); ++i)
    if ((nodes.points.col(i) - Vec3::UnitZ()).norm() < 1e-15) top = i;
  ASSERT_GE(top, 0);
  const Pose pa{Vec3(0, 0, -1), sc::Quat::Identity()};
  const Pose pb{Vec3::Zero(), sc::Quat::Identity()};
  const auto sd = sc::surface_distances(s, pa, nodes, s, pb, nodes, 0.0);
  const auto p = std::find_if(sd.pairs.begin(), sd.pairs.end(), [&](const sc::SurfacePair& c) {
    return c.source == PairSource::node_of_a && c.node == top;
  });
  ASSERT_NE(p, sd.pairs.end());
  EXPECT_EQ(p->distance, -1.0);
  EXPECT_LT((p->normal - Vec3::UnitZ()).norm(), 1e-15);
  EXPECT_LT((p->point_b - Vec3(0, 0, -1)).norm(), 1e-15);
  EXPECT_LT((p->point_b - p->point_a - p->distance * p->normal).norm(), 1e-15);
}

TEST(SurfaceDistances, FarApartGivesNoPairs) {
  const sc::Spherocylinder rod{2.0, 0.5};
  const auto n = sc::surface_nodes(rod, 0.1);
  const auto sd = sc::surface_distances(rod, Pose{}, n, rod, Pose{Vec3(5, 0, 0), sc::Quat::Identity()}, n, 0.5);
  EXPECT_TRUE(sd.pairs.empty());
  EXPECT_NEAR(sd.particle.distance, 4.0, 1e-12);
}

TEST(SurfaceDistances, RejectsBadInput) {
  const sc::Sphere s{1.0};
  const auto n = sc::surface_nodes(s, 0.3);
  const Pose p{}, q{Vec3(3, 0, 0), sc::Quat::Identity()};
  EXPECT_THROW(sc::surface_distances(s, p, n, s, q, n, -0.1), std::invalid_argument);
  EXPECT_THROW(sc::surface_distances(s, p, n, s, q, n, std::nan("")), std::invalid_argument);
  Pose bad = q;
  bad.q.coeffs() *= 2.0;
  EXPECT_THROW(sc::surface_distances(s, p, n, s, bad, n, 0.1), std::invalid_argument);
  auto broken = n;
  broken.normals.resize(3, 1);
  EXPECT_THROW(sc::surface_distances(s, p, broken, s, q, n, 0.1), std::invalid_argument);
}

TEST(SurfaceDistances, RandomSpherePairs) {
  random_configurations(sc::Sphere{1.0}, 0.1, sc::Sphere{0.4}, 0.05, 0.2, 1000, 20);
}

TEST(SurfaceDistances, RandomSphereRodPairs) {
  random_configurations(sc::Sphere{0.6}, 0.1, sc::Spherocylinder{3.0, 0.5}, 0.1, 0.2, 2000, 20);
}

TEST(SurfaceDistances, RandomRodPairs) {
  random_configurations(sc::Spherocylinder{4.0, 0.5}, 0.1, sc::Spherocylinder{2.0, 0.3}, 0.1, 0.2,
                        3000, 20);
}

TEST(SurfaceDistances, RandomBoomerangPairs) {
  const auto bt = sc::broms_tornberg_boomerang();
  random_configurations(bt, 0.1, bt, 0.1, 0.2, 4000, 25);
  random_configurations(bt, 0.1, sc::Boomerang{2.0, 0.3, 1.1}, 0.07, 0.15, 5000, 15);
}

TEST(SurfaceDistances, RandomBoomerangRodPairs) {
  random_configurations(sc::broms_tornberg_boomerang(), 0.1, sc::Spherocylinder{4.0, 0.5}, 0.1, 0.2,
                        6000, 20);
}

}  // namespace surface_distances_tests
