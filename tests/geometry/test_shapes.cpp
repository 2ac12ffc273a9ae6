#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "stokescontact/geometry/shapes.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace shapes_tests {

namespace sc = stokescontact;

static_assert(sc::Shape<sc::Sphere> && sc::Shape<sc::Spherocylinder> && sc::Shape<sc::Boomerang>);

TEST(Shapes, RejectInvalidParameters) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(sc::validate(sc::Sphere{0.0}), std::invalid_argument);
  EXPECT_THROW(sc::validate(sc::Sphere{nan}), std::invalid_argument);
  EXPECT_THROW(sc::validate(sc::Spherocylinder{-1.0, 0.5}), std::invalid_argument);
  EXPECT_THROW(sc::validate(sc::Spherocylinder{1.0, -0.5}), std::invalid_argument);
  EXPECT_THROW(sc::validate(sc::Boomerang{1.0, 0.5, 0.4}), std::invalid_argument);
  EXPECT_THROW(sc::validate(sc::Boomerang{-1.0, 0.5, 0.5}), std::invalid_argument);
  EXPECT_NO_THROW(sc::validate(sc::Spherocylinder{0.0, 0.5}));
  EXPECT_NO_THROW(sc::validate(sc::broms_tornberg_boomerang()));
  try {
    sc::validate(sc::Boomerang{1.0, 0.5, 0.4});
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("Boomerang.bend_radius"), std::string::npos);
  }
}

TEST(Shapes, SpherocylinderCentreSegmentAlongBodyZ) {
  const auto c = sc::centre_curve(sc::Spherocylinder{3.0, 0.25});
  EXPECT_EQ(c.segments[0].p0, sc::Vec3(0, 0, -1.5));
  EXPECT_EQ(c.segments[0].p1, sc::Vec3(0, 0, 1.5));
  EXPECT_DOUBLE_EQ(sc::bounding_radius(sc::Spherocylinder{3.0, 0.25}), 1.75);
}

TEST(Shapes, BoomerangCentreCurveIsTangentContinuous) {
  for (const sc::Boomerang b : {sc::broms_tornberg_boomerang(), sc::Boomerang{2.0, 0.3, 1.1}}) {
    const auto c = sc::centre_curve(b);
    const sc::Segment& z_arm = c.segments[0];
    const sc::Segment& x_arm = c.segments[1];
    const sc::Arc& bend = c.arcs[0];
    EXPECT_LT((z_arm.p1 - bend.point(0.0)).norm(), 1e-15);
    EXPECT_LT((bend.point(bend.angle) - x_arm.p0).norm(), 1e-15);
    // Arms along body -z (towards the bend) and +x (away from it), tangents continuous.
    EXPECT_LT(((z_arm.p1 - z_arm.p0).normalized() - bend.tangent(0.0)).norm(), 1e-15);
    EXPECT_LT(((x_arm.p1 - x_arm.p0).normalized() - bend.tangent(bend.angle)).norm(), 1e-15);
    EXPECT_LT(((x_arm.p1 - x_arm.p0).normalized() - sc::Vec3::UnitX()).norm(), 1e-15);
    EXPECT_NEAR(z_arm.length(), b.arm_length, 1e-14);
    EXPECT_NEAR(bend.length(), 0.5 * std::numbers::pi * b.bend_radius, 1e-14);
  }
}

// Volume and centre of mass from a midpoint grid over the bounding box, counting the
// cells whose centre lies within one radius of the centre curve: an estimate independent
// of the analytic decomposition (cylinders, caps, Pappus torus) used in shapes.hpp.
TEST(Shapes, BoomerangVolumeAndMassCentreMatchGridIntegration) {
  const sc::Boomerang b{1.5, 0.5, 0.5};
  const auto curve = sc::centre_curve(b);
  const double bound = sc::bounding_radius(b);
  const int n = 160;
  const double h = 2.0 * bound / n;
  double volume = 0.0;
  sc::Vec3 moment = sc::Vec3::Zero();
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const sc::Vec3 p = sc::Vec3(i + 0.5, j + 0.5, k + 0.5) * h - sc::Vec3::Constant(bound);
        if (sc::closest_point(curve, p).distance <= b.radius) {
          volume += h * h * h;
          moment += h * h * h * p;
        }
      }
  EXPECT_NEAR(volume / sc::volume(b), 1.0, 2e-3);
  EXPECT_LT(moment.norm() / volume, 2e-3);
}

TEST(Shapes, BoundingRadiusContainsTheShape) {
  const sc::Boomerang b{0.7, 0.2, 0.9};
  const auto c = sc::centre_curve(b);
  double reach = 0.0;
  for (int i = 0; i <= 1000; ++i) {
    const double s = i / 1000.0;
    reach = std::max({reach, c.segments[0].point(s).norm(), c.segments[1].point(s).norm(),
                      c.arcs[0].point(s * c.arcs[0].angle).norm()});
  }
  EXPECT_GE(sc::bounding_radius(b), reach + b.radius);
  EXPECT_LT(sc::bounding_radius(b), reach + b.radius + 0.5);
}

}  // namespace shapes_tests
