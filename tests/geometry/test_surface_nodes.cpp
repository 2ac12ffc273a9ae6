#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "stokescontact/geometry/surface_nodes.hpp"
#include "common/test_support.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace surface_nodes_tests {

namespace sc = stokescontact;
using sc::Vec3;

namespace {

using test_support::uniform;

// Nearest-neighbour distance of every node, by brute force.
std::vector<double> nearest_neighbour(const sc::Mat3X& p) {
  std::vector<double> nn(static_cast<std::size_t>(p.cols()), std::numeric_limits<double>::infinity());
  for (Eigen::Index i = 0; i < p.cols(); ++i)
    for (Eigen::Index j = i + 1; j < p.cols(); ++j) {
      const double d = (p.col(i) - p.col(j)).norm();
      nn[static_cast<std::size_t>(i)] = std::min(nn[static_cast<std::size_t>(i)], d);
      nn[static_cast<std::size_t>(j)] = std::min(nn[static_cast<std::size_t>(j)], d);
    }
  return nn;
}

// Every node one radius from the shape's own centre curve, its normal the outward unit
// vector from the closest curve point, and its recorded curve point that closest point.
template <typename S>
void expect_on_surface(const S& shape, double h) {
  const auto nodes = sc::surface_nodes(shape, h);
  const auto curve = sc::centre_curve(shape);
  const double r = shape.radius;
  ASSERT_EQ(nodes.normals.cols(), nodes.size());
  ASSERT_EQ(nodes.curve_points.cols(), nodes.size());
  EXPECT_EQ(nodes.spacing, h);
  for (Eigen::Index i = 0; i < nodes.size(); ++i) {
    const Vec3 p = nodes.points.col(i);
    const sc::CurvePoint c = sc::closest_point(curve, p);
    ASSERT_NEAR(c.distance, r, 1e-12 * r) << "node " << i;
    ASSERT_NEAR(nodes.normals.col(i).norm(), 1.0, 1e-14) << "node " << i;
    ASSERT_LT((nodes.normals.col(i) - (p - c.point) / r).norm(), 1e-12) << "node " << i;
    ASSERT_LT((nodes.curve_points.col(i) - c.point).norm(), 1e-12 * r) << "node " << i;
    // Outward: a step along the normal leaves the solid, a step against it enters it.
    EXPECT_GT(sc::closest_point(curve, p + 1e-3 * r * nodes.normals.col(i)).distance, r);
    EXPECT_LT(sc::closest_point(curve, p - 1e-3 * r * nodes.normals.col(i)).distance, r);
  }
}

// Quasi-uniformity: nearest-neighbour distances within [0.6 h, 1.2 h] (measured: 0.70 h
// to 1.08 h, the low end at the horn torus' pinch point), no surface point farther than
// 0.9 h from a node (measured 0.69 h to 0.86 h, the high end at the pinch of a horn torus
// with zero-length arms, where lines shorter than h/2 round to no nodes; a square grid of
// pitch h has 0.71 h), and the node count within 10% of area / h^2 (measured 0.94 to 1.01).
template <typename S>
void expect_quasi_uniform(const S& shape, double h, std::uint64_t seed) {
  SCOPED_TRACE("h = " + std::to_string(h) + ", seed " + std::to_string(seed));
  const auto nodes = sc::surface_nodes(shape, h);
  const auto nn = nearest_neighbour(nodes.points);
  const auto [lo, hi] = std::minmax_element(nn.begin(), nn.end());
  EXPECT_GT(*lo, 0.6 * h);  // also: no duplicates
  EXPECT_LT(*hi, 1.2 * h);
  const double ratio = static_cast<double>(nodes.size()) * h * h / sc::surface_area(shape);
  EXPECT_GT(ratio, 0.9);
  EXPECT_LT(ratio, 1.1);
  // Covering radius from surface points got by projecting random points of the bounding
  // cube onto the surface along the shortest-distance direction.
  const auto curve = sc::centre_curve(shape);
  const double br = sc::bounding_radius(shape);
  std::mt19937_64 rng(seed);
  double cover = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const Vec3 x(uniform(rng, -br, br), uniform(rng, -br, br), uniform(rng, -br, br));
    const sc::CurvePoint c = sc::closest_point(curve, x);
    if (c.distance == 0.0) continue;
    const Vec3 q = c.point + shape.radius * (x - c.point) / c.distance;
    cover = std::max(cover, (nodes.points.colwise() - q).colwise().norm().minCoeff());
  }
  EXPECT_LT(cover, 0.9 * h);
}

}  // namespace

TEST(SurfaceNodes, OnSurfaceWithOutwardUnitNormals) {
  expect_on_surface(sc::Sphere{1.0}, 0.1);
  expect_on_surface(sc::Sphere{0.37}, 0.05);
  expect_on_surface(sc::Spherocylinder{4.0, 0.5}, 0.1);
  expect_on_surface(sc::Spherocylinder{0.0, 0.5}, 0.1);
  expect_on_surface(sc::broms_tornberg_boomerang(), 0.05);
  expect_on_surface(sc::Boomerang{2.0, 0.3, 1.1}, 0.05);
  expect_on_surface(sc::Boomerang{0.0, 0.5, 0.5}, 0.05);
}

TEST(SurfaceNodes, QuasiUniformSphere) {
  expect_quasi_uniform(sc::Sphere{1.0}, 0.3, 1);
  expect_quasi_uniform(sc::Sphere{1.0}, 0.1, 2);
  expect_quasi_uniform(sc::Sphere{0.37}, 0.05, 3);
}

TEST(SurfaceNodes, QuasiUniformSpherocylinder) {
  expect_quasi_uniform(sc::Spherocylinder{4.0, 0.5}, 0.1, 4);
  expect_quasi_uniform(sc::Spherocylinder{0.0, 0.5}, 0.1, 5);
  expect_quasi_uniform(sc::Spherocylinder{1.3, 0.8}, 0.07, 6);
}

// Includes the horn torus (bend radius == radius) of the paper's particle.
TEST(SurfaceNodes, QuasiUniformBoomerang) {
  expect_quasi_uniform(sc::broms_tornberg_boomerang(), 0.1, 7);
  expect_quasi_uniform(sc::broms_tornberg_boomerang(), 0.05, 8);
  expect_quasi_uniform(sc::Boomerang{2.0, 0.3, 1.1}, 0.05, 9);
  expect_quasi_uniform(sc::Boomerang{0.0, 0.5, 0.5}, 0.1, 10);
  expect_quasi_uniform(sc::Boomerang{0.0, 0.5, 0.5}, 0.05, 11);
}

// Count ~ area / h^2: a quarter of the spacing gives about 16 times the nodes.
TEST(SurfaceNodes, UpsamplingRefines) {
  const auto b = sc::broms_tornberg_boomerang();
  const auto coarse = sc::surface_nodes(b, 0.2);
  const auto fine = sc::upsampled_surface_nodes(b, 0.2, 4);
  EXPECT_DOUBLE_EQ(fine.spacing, 0.05);
  EXPECT_EQ(fine.size(), sc::surface_nodes(b, 0.05).size());
  const double ratio = static_cast<double>(fine.size()) / static_cast<double>(coarse.size());
  EXPECT_GT(ratio, 16.0 * 0.85);
  EXPECT_LT(ratio, 16.0 * 1.15);
  EXPECT_EQ(sc::upsampled_surface_nodes(b, 0.2, 1).size(), coarse.size());
  EXPECT_THROW(sc::upsampled_surface_nodes(b, 0.2, 0), std::invalid_argument);
}

// A spacing far above the radius still gives a closed, valid point set.
TEST(SurfaceNodes, CoarseSpacingStaysValid) {
  const auto nodes = sc::surface_nodes(sc::Sphere{1.0}, 10.0);
  EXPECT_GE(nodes.size(), 2);
  expect_on_surface(sc::Spherocylinder{2.0, 0.5}, 5.0);
  expect_on_surface(sc::broms_tornberg_boomerang(), 5.0);
}

TEST(SurfaceNodes, RejectsBadSpacing) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double h : {0.0, -0.1, nan, inf}) {
    EXPECT_THROW(sc::surface_nodes(sc::Sphere{1.0}, h), std::invalid_argument) << h;
  }
  EXPECT_THROW(sc::surface_nodes(sc::Sphere{-1.0}, 0.1), std::invalid_argument);
  EXPECT_THROW(sc::surface_nodes(sc::Boomerang{1.0, 0.5, 0.4}, 0.1), std::invalid_argument);
  // About 1.3e7 nodes: refused before any allocation, with the field and the count named.
  try {
    sc::surface_nodes(sc::broms_tornberg_boomerang(), 1e-3);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("spacing"), std::string::npos) << what;
    EXPECT_NE(what.find("surface nodes"), std::string::npos) << what;
  }
}

}  // namespace surface_nodes_tests
