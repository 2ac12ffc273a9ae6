#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokescontact/mobility/pair_mobility_exact.hpp"
#include "stokescontact/mobility/rpy_mobility.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace pair_mobility_exact_tests {

namespace sc = stokescontact;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kFunctions = 10;
const std::array<const char*, kFunctions> kNames{"x11a", "x12a", "y11a", "y12a", "y11b",
                                                 "y12b", "x11c", "x12c", "y11c", "y12c"};

std::array<double, kFunctions> as_array(const sc::TwoSphereMobilityFunctions& m) {
  return {m.x11a, m.x12a, m.y11a, m.y12a, m.y11b, m.y12b, m.x11c, m.x12c, m.y11c, m.y12c};
}

// The functions read off a 12 x 12 mobility of spheres at 0 and s a e_x (e = e_x):
// omega_1 = mu_b y11b f_1 x e, and e_y x e_x = -e_z.
sc::TwoSphereMobilityFunctions functions_of(const sc::Mat12& M, double a, double eta) {
  const double mu_t = 1.0 / (6.0 * kPi * eta * a), mu_b = 1.0 / (4.0 * kPi * eta * a * a),
               mu_r = 1.0 / (8.0 * kPi * eta * a * a * a);
  sc::TwoSphereMobilityFunctions m;
  m.x11a = M(0, 0) / mu_t;
  m.y11a = M(1, 1) / mu_t;
  m.x12a = M(0, 6) / mu_t;
  m.y12a = M(1, 7) / mu_t;
  m.y11b = -M(5, 1) / mu_b;
  m.y12b = -M(5, 7) / mu_b;
  m.x11c = M(3, 3) / mu_r;
  m.y11c = M(4, 4) / mu_r;
  m.x12c = M(3, 9) / mu_r;
  m.y12c = M(4, 10) / mu_r;
  return m;
}

// The 12 x 12 RPY matrix of RpyMobility for spheres at x1, x2.
sc::Mat12 rpy_pair_matrix(const sc::Vec3& x1, const sc::Vec3& x2, double a, double eta) {
  sc::RpyMobility rpy(2, {eta, a}, 6);
  std::vector<sc::Pose> poses(2);
  poses[0].x = x1;
  poses[1].x = x2;
  rpy.set_configuration(poses);
  return rpy.dense_matrix();
}

sc::TwoSphereMobilityFunctions rpy_functions_of_model(double s) {
  return functions_of(rpy_pair_matrix(sc::Vec3::Zero(), sc::Vec3(s, 0, 0), 1.0, 1.0), 1.0, 1.0);
}

// RPY's functions in closed form for s > 2 (far branches of the pair blocks).
sc::TwoSphereMobilityFunctions rpy_functions(double s) {
  sc::TwoSphereMobilityFunctions m;
  m.x12a = 1.5 / s - 1.0 / (s * s * s);
  m.y12a = 0.75 / s + 0.5 / (s * s * s);
  m.y12b = -0.5 / (s * s);
  m.x12c = 1.0 / (s * s * s);
  m.y12c = -0.5 / (s * s * s);
  return m;
}

// Coefficient of s^-k in the series of one function (the series are in powers of 2/s).
double coefficient(const std::vector<double>& c, int k) { return std::ldexp(c[static_cast<std::size_t>(k)], k); }

}  // namespace

// Equal spheres (lambda = 1) from the table of nondimensional mobility functions in
// Pecnut/stokesian-dynamics (find_resistance_scalars/scalars_general_mobility_midfield.txt,
// A. Townsend, generated with H. Wilson's twin-multipole code; 9 significant digits). The
// table's differences from our series grow toward contact, where its generator truncates:
// the tolerances are that observed table accuracy, while our sums are converged to ~1e-11
// at s = 2.1 (see pair_mobility_exact.hpp).
TEST(TwoSphereMobility, MatchesPublishedTable) {
  struct Row {
    double s, tolerance;
    std::array<double, kFunctions> expected;  // x11a x12a y11a y12a y11b y12b x11c x12c y11c y12c
  };
  const std::array<Row, 5> rows{{
      {2.1, 3e-8, {8.35613376e-01, 7.00720594e-01, 9.74064522e-01, 4.17673571e-01, 2.46345087e-02,
                   -1.15932540e-01, 9.85188610e-01, 1.11930670e-01, 8.78824263e-01, -2.30913871e-02}},
      {2.2, 1.5e-8, {8.69646947e-01, 6.53456103e-01, 9.83461672e-01, 3.90844352e-01, 1.47032199e-02,
                     -1.04497967e-01, 9.90805812e-01, 9.56025571e-02, 9.25846973e-01, -3.02401733e-02}},
      {2.5, 3e-9, {9.23383272e-01, 5.62687387e-01, 9.93896272e-01, 3.32483820e-01, 4.62088768e-03,
                   -8.02231641e-02, 9.97168218e-01, 6.42126702e-02, 9.74187210e-01, -2.78382986e-02}},
      {3.0, 3e-9, {9.61279741e-01, 4.70760170e-01, 9.98236742e-01, 2.68565327e-01, 1.06254081e-03,
                   -5.55842955e-02, 9.99418264e-01, 3.70511549e-02, 9.92893534e-01, -1.78386690e-02}},
      {4.0, 3e-9, {9.86769359e-01, 3.60470571e-01, 9.99716298e-01, 1.95313979e-01, 1.20213740e-04,
                   -3.12513965e-02, 9.99947843e-01, 1.56252497e-02, 9.98914403e-01, -7.76882817e-03}},
  }};
  for (const Row& row : rows) {
    const sc::TwoSphereMobilityFunctions m = sc::two_sphere_mobility_functions(row.s);
    EXPECT_LT(m.truncation_error, 1e-10) << "s = " << row.s;
    const auto got = as_array(m);
    for (int f = 0; f < kFunctions; ++f)
      EXPECT_NEAR(got[static_cast<std::size_t>(f)], row.expected[static_cast<std::size_t>(f)], row.tolerance)
          << kNames[static_cast<std::size_t>(f)] << " at s = " << row.s;
  }
}

// Far-field expansions (Jeffrey & Onishi 1984; Kim & Karrila 1991, ch. 11) for equal spheres:
// x11a = 1 - 15/(4 s^4) + ..., x12a = 3/(2s) - 1/s^3 + 75/(4 s^7) + ..., y11a = 1 - 17/(16 s^6),
// y12a = 3/(4s) + 1/(2 s^3) + ..., and the point-particle rotation couplings.
TEST(TwoSphereMobility, SeriesStartWithPublishedFarFieldCoefficients) {
  const auto& c = sc::detail::twin_multipole_series();
  const double tol = 1e-13;
  EXPECT_EQ(c.x11a[0], 1.0);
  for (int k = 1; k <= 3; ++k) EXPECT_EQ(c.x11a[static_cast<std::size_t>(k)], 0.0) << k;
  EXPECT_NEAR(coefficient(c.x11a, 4), -15.0 / 4.0, tol);
  EXPECT_NEAR(coefficient(c.x12a, 1), 1.5, tol);
  EXPECT_NEAR(coefficient(c.x12a, 3), -1.0, tol);
  EXPECT_NEAR(coefficient(c.x12a, 5), 0.0, tol);
  EXPECT_NEAR(coefficient(c.x12a, 7), 75.0 / 4.0, tol);
  for (int k = 1; k <= 5; ++k) EXPECT_EQ(c.y11a[static_cast<std::size_t>(k)], 0.0) << k;
  EXPECT_NEAR(coefficient(c.y11a, 6), -17.0 / 16.0, tol);
  EXPECT_NEAR(coefficient(c.y12a, 1), 0.75, tol);
  EXPECT_NEAR(coefficient(c.y12a, 3), 0.5, tol);
  EXPECT_NEAR(coefficient(c.y12b, 2), -0.5, tol);
  EXPECT_NEAR(coefficient(c.x12c, 3), 1.0, tol);
  EXPECT_NEAR(coefficient(c.y12c, 3), -0.5, tol);
}

// Lorentz reciprocity: the rotation of a sphere under a force (Y^B from the force problem)
// equals the translation under a torque (the torque problem), an independent recurrence path.
TEST(TwoSphereMobility, ForceAndTorqueProblemsGiveTheSameCoupling) {
  const auto& c = sc::detail::twin_multipole_series();
  for (std::size_t k = 0; k < c.y11b.size(); ++k) {
    const double scale = std::max({std::abs(c.y11b[k]), std::abs(c.y12b[k]), 1e-300});
    EXPECT_LE(std::abs(c.y11b[k] - c.y11b_from_torque[k]), 1e-12 * scale) << "k = " << k;
    EXPECT_LE(std::abs(c.y12b[k] - c.y12b_from_torque[k]), 1e-12 * scale) << "k = " << k;
  }
}

// Two touching spheres moving along their line of centres have drag 0.645 x 6 pi eta a U
// each (Stimson & Jeffery 1926): x11a + x12a -> 1/0.645 = 1.550 at contact. The series
// (valid to s = 2.05) approaches it monotonically.
TEST(TwoSphereMobility, AxialPairMobilityApproachesStimsonJefferyDoublet) {
  double previous = 0.0;
  for (double s : {4.0, 3.0, 2.5, 2.2, 2.1, 2.05}) {
    const sc::TwoSphereMobilityFunctions m = sc::two_sphere_mobility_functions(s);
    EXPECT_GT(m.x11a + m.x12a, previous) << "s = " << s;
    previous = m.x11a + m.x12a;
    EXPECT_GT(m.x11a - m.x12a, 0.0) << "s = " << s;  // approach is slowed, never reversed
  }
  EXPECT_NEAR(previous, 1.0 / 0.645, 0.01);
}

TEST(TwoSphereMobility, MatrixIsCovariantSymmetricPositiveDefinite) {
  std::mt19937 rng(4242);
  std::normal_distribution<double> g(0.0, 1.0);
  const double a = 0.6, eta = 1.9;
  for (double s : {2.1, 2.5, 4.0, 10.0}) {
    const sc::Vec3 x1(0.3, -0.2, 1.0), x2 = x1 + sc::Vec3(s * a, 0.0, 0.0);
    const sc::Mat12 M = sc::two_sphere_mobility_matrix(x1, x2, a, eta);
    EXPECT_LT((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-15 * M.cwiseAbs().maxCoeff()) << "s = " << s;
    EXPECT_EQ(Eigen::LLT<sc::Mat12>(M).info(), Eigen::Success) << "s = " << s;
    // The layout reads back the functions it was built from.
    const auto back = as_array(functions_of(sc::two_sphere_mobility_matrix(sc::Vec3::Zero(),
                                                                           sc::Vec3(s * a, 0, 0), a, eta),
                                            a, eta));
    const auto direct = as_array(sc::two_sphere_mobility_functions(s));
    for (std::size_t f = 0; f < kFunctions; ++f) EXPECT_NEAR(back[f], direct[f], 1e-14) << kNames[f];
    // Rotating and shifting both spheres rotates every 3 x 3 block.
    const sc::Quat q = sc::Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
    const sc::Vec3 shift(1.0, 2.0, -3.0);
    const sc::Mat12 Mq = sc::two_sphere_mobility_matrix(q * x1 + shift, q * x2 + shift, a, eta);
    sc::Mat12 Q = sc::Mat12::Zero();
    for (int k = 0; k < 4; ++k) Q.block<3, 3>(3 * k, 3 * k) = q.toRotationMatrix();
    EXPECT_LT((Mq - Q * M * Q.transpose()).cwiseAbs().maxCoeff(), 1e-14 * M.cwiseAbs().maxCoeff()) << "s = " << s;
  }
}

// The assembly's conventions are RpyMobility's: RPY's closed-form functions assembled by
// two_sphere_mobility_matrix give RpyMobility's dense matrix in any orientation.
TEST(TwoSphereMobility, AssemblyMatchesRpyMobilityConventions) {
  const double a = 1.2, eta = 0.4;
  for (double s : {2.3, 5.0}) {
    const auto model = as_array(rpy_functions_of_model(s)), closed = as_array(rpy_functions(s));
    for (std::size_t f = 0; f < kFunctions; ++f) EXPECT_NEAR(model[f], closed[f], 1e-14) << kNames[f];
    const sc::Vec3 x1(0.5, 1.0, -2.0), x2 = x1 + s * a * sc::Vec3(1.0, -2.0, 0.5).normalized();
    const sc::Mat12 expected = rpy_pair_matrix(x1, x2, a, eta);
    const sc::Mat12 M = sc::two_sphere_mobility_matrix(rpy_functions(s), x1, x2, a, eta);
    EXPECT_LT((M - expected).cwiseAbs().maxCoeff(), 1e-14 * expected.cwiseAbs().maxCoeff()) << "s = " << s;
  }
}

// RPY is exact to O(s^-3): every error decays faster than s^-3.
TEST(TwoSphereMobility, RpyIsExactToThirdOrderInFarField) {
  std::array<double, kFunctions> previous{};
  for (double s : {6.0, 12.0, 24.0, 48.0}) {
    const auto exact = as_array(sc::two_sphere_mobility_functions(s)), rpy = as_array(rpy_functions_of_model(s));
    for (std::size_t f = 0; f < kFunctions; ++f) {
      const double error = std::abs(rpy[f] - exact[f]);
      if (s > 6.0 && previous[f] > 1e-13) {
        EXPECT_LT(error, previous[f] / 8.0) << kNames[f] << " at s = " << s;
      }
      previous[f] = error;
    }
  }
}

// The error table of RPY against the exact functions at gaps 0.1 ... 4 radii: printed for the
// docs, and the errors shrink as the gap opens.
TEST(TwoSphereMobility, RpyErrorTableShrinksWithGap) {
  const std::array<double, 6> gaps{0.1, 0.2, 0.5, 1.0, 2.0, 4.0};
  std::printf("RPY - exact (units of each function; s = r/a = 2 + gap/a)\n%6s", "gap/a");
  for (const char* name : kNames) std::printf(" %11s", name);
  std::printf("\n");
  std::array<double, kFunctions> previous;
  previous.fill(std::numeric_limits<double>::infinity());
  double previous_worst = std::numeric_limits<double>::infinity();
  for (double gap : gaps) {
    const auto exact = as_array(sc::two_sphere_mobility_functions(2.0 + gap));
    const auto rpy = as_array(rpy_functions_of_model(2.0 + gap));
    std::printf("%6.1f", gap);
    double worst = 0.0;
    for (std::size_t f = 0; f < kFunctions; ++f) {
      const double error = rpy[f] - exact[f];
      std::printf(" %11.3e", error);
      EXPECT_LT(std::abs(error), previous[f]) << kNames[f] << " at gap " << gap;
      previous[f] = std::abs(error);
      worst = std::max(worst, std::abs(error));
    }
    std::printf("\n");
    EXPECT_LT(worst, previous_worst) << "gap " << gap;
    previous_worst = worst;
  }
  std::printf("exact values:\n");
  for (double gap : gaps) {
    std::printf("%6.1f", gap);
    for (double v : as_array(sc::two_sphere_mobility_functions(2.0 + gap))) std::printf(" %11.8f", v);
    std::printf("\n");
  }
}

TEST(TwoSphereMobility, RefusesContactAndBadInput) {
  EXPECT_THROW(sc::two_sphere_mobility_functions(2.0), std::invalid_argument);
  EXPECT_THROW(sc::two_sphere_mobility_functions(1.5), std::invalid_argument);
  EXPECT_THROW(sc::two_sphere_mobility_functions(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(sc::two_sphere_mobility_functions(std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW(sc::two_sphere_mobility_functions(2.02), std::domain_error);  // series too short there
  EXPECT_NO_THROW(sc::two_sphere_mobility_functions(2.05));
  EXPECT_THROW(sc::two_sphere_mobility_matrix(sc::Vec3::Zero(), sc::Vec3(1.5, 0, 0), 1.0, 1.0),
               std::invalid_argument);
  EXPECT_THROW(sc::two_sphere_mobility_matrix(sc::Vec3::Zero(), sc::Vec3(3, 0, 0), 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(sc::two_sphere_mobility_matrix(sc::Vec3::Zero(), sc::Vec3(3, 0, 0), 1.0, -1.0), std::invalid_argument);
}

}  // namespace pair_mobility_exact_tests
