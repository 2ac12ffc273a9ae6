#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>

#include "stokescontact/geometry/mass_tensors.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace mass_tensors_tests {

namespace sc = stokescontact;
using sc::Mat3;
using sc::Vec3;

namespace {

const double pi = std::numbers::pi;

// Uniform double in [0, 1) from the top 53 bits: the same stream on every platform.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Plain Monte Carlo over a box of the indicator "distance to the centre curve <= radius"
// times 1, x and x x^T, with the standard error of each estimate from the same samples.
struct MonteCarlo {
  double volume = 0, volume_error = 0;
  Vec3 first = Vec3::Zero(), first_error = Vec3::Zero();
  Mat3 second = Mat3::Zero(), second_error = Mat3::Zero();
};

template <typename S>
MonteCarlo monte_carlo(const S& shape, const Vec3& lo, const Vec3& hi, long samples,
                       std::uint64_t seed) {
  const auto curve = sc::centre_curve(shape);
  std::mt19937_64 rng(seed);
  double s0 = 0;
  Vec3 s1 = Vec3::Zero(), q1 = Vec3::Zero();
  Mat3 s2 = Mat3::Zero(), q2 = Mat3::Zero();
  for (long i = 0; i < samples; ++i) {
    Vec3 x;
    for (int k = 0; k < 3; ++k) x[k] = lo[k] + (hi[k] - lo[k]) * uniform01(rng);
    if (sc::closest_point(curve, x).distance > shape.radius) continue;
    const Mat3 xx = x * x.transpose();
    s0 += 1;
    s1 += x;
    q1 += x.cwiseProduct(x);
    s2 += xx;
    q2 += xx.cwiseProduct(xx);
  }
  const double box = (hi - lo).prod(), n = static_cast<double>(samples);
  // For f >= 0 sampled n times: mean = S/n, standard error sqrt((Q/n - mean^2) / n).
  auto err = [&](double sum, double sq) { return box * std::sqrt((sq / n - (sum / n) * (sum / n)) / n); };
  MonteCarlo mc;
  mc.volume = box * s0 / n;
  mc.volume_error = err(s0, s0);
  for (int k = 0; k < 3; ++k) {
    mc.first[k] = box * s1[k] / n;
    mc.first_error[k] = err(s1[k], q1[k]);
    for (int l = 0; l < 3; ++l) {
      mc.second(k, l) = box * s2(k, l) / n;
      mc.second_error(k, l) = err(s2(k, l), q2(k, l));
    }
  }
  return mc;
}

// Bounding box of the solid from its centre-curve pieces (an arc inside its full circle).
template <std::size_t NS, std::size_t NA>
void curve_box(const sc::CentreCurve<NS, NA>& c, double r, Vec3& lo, Vec3& hi) {
  lo = Vec3::Constant(1e300);
  hi = Vec3::Constant(-1e300);
  for (const auto& s : c.segments) {
    lo = lo.cwiseMin(s.p0).cwiseMin(s.p1);
    hi = hi.cwiseMax(s.p0).cwiseMax(s.p1);
  }
  // Arcs through 257 points; between them the arc bulges at most R_b (1 - cos(step / 2)).
  double bulge = 0;
  for (const auto& a : c.arcs) {
    for (int i = 0; i <= 256; ++i) {
      lo = lo.cwiseMin(a.point(a.angle * i / 256));
      hi = hi.cwiseMax(a.point(a.angle * i / 256));
    }
    bulge = std::max(bulge, a.radius * (1 - std::cos(a.angle / 512)));
  }
  lo -= Vec3::Constant(r + bulge);
  hi += Vec3::Constant(r + bulge);
}

// The analytic tensors against the Monte Carlo estimates, within 5 standard errors.
template <typename S>
void expect_matches_monte_carlo(const S& shape, long samples, std::uint64_t seed) {
  SCOPED_TRACE("Monte Carlo seed " + std::to_string(seed));
  Vec3 lo, hi;
  curve_box(sc::centre_curve(shape), shape.radius, lo, hi);
  const MonteCarlo mc = monte_carlo(shape, lo, hi, samples, seed);
  const sc::MassTensors t = sc::mass_tensors(shape);
  const Vec3 first = sc::first_moment(shape);
  EXPECT_NEAR(mc.volume, sc::volume(shape), 5 * mc.volume_error);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(mc.first[k], first[k], 5 * mc.first_error[k]) << "component " << k;
    for (int l = 0; l < 3; ++l) {
      EXPECT_NEAR(mc.second(k, l), t.N(k, l), 5 * mc.second_error(k, l) + 1e-12)
          << "N(" << k << "," << l << ")";
    }
  }
  // The estimates are sharp: 5 standard errors are well under 1% of the largest entry.
  EXPECT_LT(5 * mc.second_error.maxCoeff(), 1e-2 * t.N.maxCoeff());
}

void expect_spd(const Mat3& g) {
  EXPECT_LT((g - g.transpose()).norm(), 1e-14 * g.norm());
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(g);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
}

}  // namespace

TEST(MassTensors, SphereExact) {
  for (const double r : {0.5, 1.0, 2.3}) {
    const double rho = 1.7, r5 = std::pow(r, 5);
    const auto t = sc::mass_tensors(sc::Sphere{r}, rho);
    EXPECT_LT((t.N - 4 * pi / 15 * r5 * rho * Mat3::Identity()).norm(), 1e-14 * r5);
    EXPECT_LT((t.G_M - 8 * pi / 15 * r5 * rho * Mat3::Identity()).norm(), 1e-14 * r5);
    EXPECT_EQ(sc::first_moment(sc::Sphere{r}), Vec3::Zero());
  }
}

// Yan A3-A6 against the sum of a cylinder and two hemispheres computed from their own
// moment formulas, and the trace relation tr N = tr G_M / 2 implied by eq. 4 and eq. 6.
TEST(MassTensors, SpherocylinderYanFormulasMatchPieces) {
  for (const sc::Spherocylinder s : {sc::Spherocylinder{4.0, 0.5}, sc::Spherocylinder{0.0, 1.0},
                                     sc::Spherocylinder{7.3, 0.21}}) {
    const auto t = sc::mass_tensors(s);
    const auto pieces = sc::detail::moments(s);
    const double scale = t.N.norm();
    EXPECT_LT((t.N - pieces.second).norm(), 1e-14 * scale);
    EXPECT_LT((t.G_M - (pieces.second.trace() * Mat3::Identity() - pieces.second)).norm(),
              1e-14 * scale);
    EXPECT_NEAR(t.N.trace(), 0.5 * t.G_M.trace(), 1e-14 * scale);
    EXPECT_NEAR(pieces.volume, sc::volume(s), 1e-14 * sc::volume(s));
    EXPECT_LT(sc::first_moment(s).norm(), 1e-14 * scale);
    expect_spd(t.G_M);
  }
  // L = 0 is a sphere.
  const auto ball = sc::mass_tensors(sc::Spherocylinder{0.0, 0.8});
  EXPECT_LT((ball.N - sc::mass_tensors(sc::Sphere{0.8}).N).norm(), 1e-15);
}

TEST(MassTensors, SpherocylinderMatchesMonteCarlo) {
  expect_matches_monte_carlo(sc::Spherocylinder{4.0, 0.5}, 1'000'000, 20230611);
}

TEST(MassTensors, DensityScalesLinearly) {
  const auto b = sc::broms_tornberg_boomerang();
  const auto one = sc::mass_tensors(b), two = sc::mass_tensors(b, 2.5);
  EXPECT_LT((two.N - 2.5 * one.N).norm(), 1e-14 * two.N.norm());
  EXPECT_LT((two.G_M - 2.5 * one.G_M).norm(), 1e-14 * two.G_M.norm());
  EXPECT_THROW(sc::mass_tensors(b, 0.0), std::invalid_argument);
  EXPECT_THROW(sc::mass_tensors(sc::Sphere{1.0}, -1.0), std::invalid_argument);
  EXPECT_THROW(sc::mass_tensors(sc::Boomerang{1.0, 0.5, 0.4}), std::invalid_argument);
}

// The torus quadrature against closed forms for a quarter torus centred at the origin:
// with Q = pi r^2 R_b (R_b^2 + 3 r^2 / 4) the cross-section integral of rho^3,
// int (x.e1)^2 = Q pi/4, int (x.e1)(x.e2) = Q / 2, int (x.a)^2 = (pi/2) R_b pi r^4 / 4,
// int x.e1 = int x.e2 = r^2 pi (R_b^2 + r^2 / 4) (Pappus-type centroid), volume pi r^2 R_b pi/2.
TEST(MassTensors, TorusSectionQuadratureMatchesClosedForms) {
  for (const auto [rb, r] : {std::array{0.5, 0.5}, std::array{1.1, 0.3}, std::array{2.0, 1.9}}) {
    const sc::Arc quarter{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), rb, 0.5 * pi};
    const auto m = sc::detail::torus_section_moments(quarter, r);
    const double q = pi * r * r * rb * (rb * rb + 0.75 * r * r);
    const double c = pi * r * r * (rb * rb + 0.25 * r * r);
    Mat3 expected;
    expected << q * pi / 4, q / 2, 0, q / 2, q * pi / 4, 0, 0, 0, 0.5 * pi * rb * pi * std::pow(r, 4) / 4;
    EXPECT_NEAR(m.volume, pi * r * r * rb * 0.5 * pi, 1e-14 * m.volume);
    EXPECT_LT((m.first - Vec3(c, c, 0)).norm(), 1e-14 * c);
    EXPECT_LT((m.second - expected).norm(), 1e-14 * expected.norm());
  }
}

// Broms & Tornberg boomerang: pieces sum to the analytic volume, the body origin is the
// centre of mass (eq. 5, an independent check of the shape's analytic offset), the x <-> z
// mirror symmetry holds, G_M is SPD, and tensors scale like length^5.
TEST(MassTensors, BoomerangStructure) {
  for (const sc::Boomerang b : {sc::broms_tornberg_boomerang(), sc::Boomerang{2.0, 0.3, 1.1},
                                sc::Boomerang{0.0, 0.5, 0.5}}) {
    const auto t = sc::mass_tensors(b);
    const double scale = t.N.norm();
    EXPECT_NEAR(sc::detail::moments(b).volume, sc::volume(b), 1e-14 * sc::volume(b));
    EXPECT_LT(sc::first_moment(b).norm(), 1e-14 * sc::volume(b) * sc::bounding_radius(b));
    EXPECT_NEAR(t.N(0, 0), t.N(2, 2), 1e-14 * scale);
    EXPECT_NEAR(t.N(0, 1), 0.0, 1e-14 * scale);
    EXPECT_NEAR(t.N(1, 2), 0.0, 1e-14 * scale);
    EXPECT_NEAR(t.N.trace(), 0.5 * t.G_M.trace(), 1e-14 * scale);
    expect_spd(t.G_M);
    const sc::Boomerang big{2.0 * b.arm_length, 2.0 * b.radius, 2.0 * b.bend_radius};
    EXPECT_LT((sc::mass_tensors(big).N - 32.0 * t.N).norm(), 1e-13 * 32.0 * scale);
  }
}

TEST(MassTensors, BoomerangMatchesMonteCarlo) {
  expect_matches_monte_carlo(sc::broms_tornberg_boomerang(), 4'000'000, 4242);
  expect_matches_monte_carlo(sc::Boomerang{2.0, 0.3, 1.1}, 3'000'000, 777);
}

}  // namespace mass_tensors_tests
