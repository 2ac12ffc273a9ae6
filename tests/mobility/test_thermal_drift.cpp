#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/rpy_mobility.hpp"
#include "stokescontact/mobility/thermal_drift.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace thermal_drift_tests {

namespace sc = stokescontact;

namespace {

using test_support::expect_rejects;
using test_support::Rng;

// Test-only model with a closed-form divergence, the independent reference for the RFD:
//   M(X) = m0 I + alpha s s^T,  s_a = sin(X_a / ell),  X = the stacked centres (3N),
// SPD for alpha >= 0, globally coupled and nonlinear in X, so the centred difference has an
// O(delta^2) error. Its divergence, by hand:
//   sum_b d M_ab / d X_b = alpha / ell (cos(X_a / ell) s_a + s_a sum_b cos(X_b / ell)).
class SineMobility {
 public:
  SineMobility(std::size_t bodies, double m0, double alpha, double ell)
      : n_(3 * static_cast<Eigen::Index>(bodies)), m0_(m0), alpha_(alpha), ell_(ell) {}

  void set_configuration(std::span<const sc::Pose> poses) {
    x_.resize(n_);
    for (std::size_t i = 0; i < poses.size(); ++i) x_.segment<3>(3 * static_cast<Eigen::Index>(i)) = poses[i].x;
  }
  sc::VecX apply(const sc::VecX& F) {
    counter_.count();
    const sc::VecX s = sines();
    return m0_ * F + alpha_ * s * s.dot(F);
  }
  Eigen::Index size() const { return n_; }
  int dofs_per_body() const { return 3; }
  std::size_t applications() const { return counter_.applications(); }
  void reset_applications() { counter_.reset_applications(); }

  sc::VecX closed_form_divergence() const {
    const sc::VecX s = sines(), c = (x_ / ell_).array().cos().matrix();
    return alpha_ / ell_ * (c.cwiseProduct(s) + s * c.sum());
  }

 private:
  sc::VecX sines() const { return (x_ / ell_).array().sin().matrix(); }

  Eigen::Index n_;
  double m0_, alpha_, ell_;
  sc::VecX x_;
  sc::ApplicationCounter counter_;
};

static_assert(sc::MobilityOperator<SineMobility>);
static_assert(!sc::ExactDivergenceMobility<SineMobility>);

sc::Mat3 cross_matrix(const sc::Vec3& r) {
  sc::Mat3 m;
  m << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
  return m;
}

// A sphere (translation mobility a, rotation b) tracked at a point r (body frame) off its
// centre: u_p = u_c + omega x r and tau_c = tau_p + r x f give N_p = T N_c T^T with
// T = [I, -[r x]; 0, I], a coupling block -b [r x] (antisymmetric).
sc::Mat6 off_centre_sphere(double a, double b, const sc::Vec3& r) {
  sc::Mat6 n = sc::Mat6::Zero(), t = sc::Mat6::Identity();
  n.topLeftCorner<3, 3>() = a * sc::Mat3::Identity();
  n.bottomRightCorner<3, 3>() = b * sc::Mat3::Identity();
  t.topRightCorner<3, 3>() = -cross_matrix(r);
  return t * n * t.transpose();
}

// Mean of `samples` RFD samples against `exact`, componentwise within five standard errors
// (the sample standard deviation over sqrt(samples)) plus `bias`; returns the largest standard
// error so a caller can check the test can tell a wrong drift from the right one.
template <typename M>
double expect_rfd_mean(M& model, const std::vector<sc::Pose>& poses, double kT, const sc::VecX& exact,
                       int samples, std::uint64_t seed, const sc::RfdOptions& options, double bias = 0.0) {
  SCOPED_TRACE("seed " + std::to_string(seed) + ", samples " + std::to_string(samples));
  sc::GaussianStream rng(seed);
  const Eigen::Index n = model.size();
  sc::VecX sum = sc::VecX::Zero(n), sum2 = sc::VecX::Zero(n);
  for (int k = 0; k < samples; ++k) {
    const sc::VecX d = sc::random_finite_difference_drift(model, poses, kT, rng, options);
    sum += d;
    sum2 += d.cwiseAbs2();
  }
  const sc::VecX mean = sum / samples;
  const sc::VecX variance = (sum2 / samples - mean.cwiseAbs2()).cwiseMax(0.0);
  const sc::VecX standard_error = (variance / samples).cwiseSqrt();
  for (Eigen::Index i = 0; i < n; ++i)
    EXPECT_LE(std::abs(mean(i) - exact(i)), 5.0 * standard_error(i) + bias)
        << "entry " << i << ": " << mean(i) << " vs " << exact(i) << " (standard error " << standard_error(i) << ")";
  return standard_error.maxCoeff();
}

}  // namespace

// The RFD mean against a divergence worked out by hand (SineMobility), to O(delta^2).
TEST(RandomFiniteDifference, MeanIsTheClosedFormDivergence) {
  Rng rng(41);
  SineMobility model(4, 0.5, 0.8, 1.3);
  const std::vector<sc::Pose> poses = sc::random_poses(4, 0.0, 3.0, rng);
  model.set_configuration(poses);
  const double kT = 2.0;
  const sc::VecX exact = kT * model.closed_form_divergence();
  const double standard_error = expect_rfd_mean(model, poses, kT, exact, 40000, 42, {1e-4, 1.0}, 1e-6);
  // A drift off by 20% of its size would be caught.
  EXPECT_LT(5.0 * standard_error, 0.2 * exact.cwiseAbs().maxCoeff());
}

// Translations scaled by `length`: the same mean (the estimator divides the scaling out).
TEST(RandomFiniteDifference, MeanDoesNotDependOnTheLengthScale) {
  Rng rng(43);
  SineMobility model(3, 0.5, 0.8, 1.3);
  const std::vector<sc::Pose> poses = sc::random_poses(3, 0.0, 3.0, rng);
  model.set_configuration(poses);
  const sc::VecX exact = 0.3 * model.closed_form_divergence();
  expect_rfd_mean(model, poses, 0.3, exact, 20000, 44, {1e-3, 0.25}, 1e-6);
}

// Two applications, and the model is left at the configuration it was given.
TEST(RandomFiniteDifference, CostsTwoApplicationsAndRestoresTheConfiguration) {
  Rng rng(45);
  sc::RpyMobility model(5, {1.0, 1.0}, 6);
  const std::vector<sc::Pose> poses = sc::random_poses(5, 0.0, 4.0, rng);
  model.set_configuration(poses);
  const sc::MatX before = model.dense_matrix();
  model.reset_applications();
  sc::GaussianStream stream(46);
  const sc::VecX drift = sc::random_finite_difference_drift(model, poses, 1.0, stream);
  EXPECT_EQ(model.applications(), 2u);
  EXPECT_TRUE(drift.allFinite());
  EXPECT_EQ(model.dense_matrix(), before);
}

// RPY between spheres is divergence free (translation and rotation, both branches): the
// fallback's mean must vanish.
TEST(RandomFiniteDifference, RpyDriftVanishesOnAverage) {
  Rng rng(47);
  sc::RpyMobility model(4, {1.0, 1.0}, 6);
  const std::vector<sc::Pose> poses = sc::random_poses(4, 0.0, 3.0, rng);  // some pairs overlap
  model.set_configuration(poses);
  expect_rfd_mean(model, poses, 1.0, sc::VecX::Zero(24), 10000, 48, {1e-4, 1.0}, 1e-6);
}

// RpyMobility says so itself (divergence() = 0, checked by the test above): thermal_drift
// then costs no application and draws nothing.
TEST(ThermalDrift, RpyUsesItsExactZeroDivergence) {
  static_assert(sc::ExactDivergenceMobility<sc::RpyMobility>);
  Rng rng(50);
  sc::RpyMobility model(4, {1.0, 1.0}, 6);
  const std::vector<sc::Pose> poses = sc::random_poses(4, 0.0, 3.0, rng);
  model.set_configuration(poses);
  model.reset_applications();
  sc::GaussianStream stream(51);
  const sc::VecX drift = sc::thermal_drift(model, poses, 1.0, stream);
  EXPECT_EQ(drift, sc::VecX::Zero(24));
  EXPECT_EQ(model.applications(), 0u);
  sc::GaussianStream fresh(51);
  EXPECT_EQ(stream(), fresh());  // nothing drawn
}

// The free-draining closed form, against the drift of a tracking point off a sphere's centre:
// isotropic rotational diffusion (D_r = kT b) gives E[R(t)] = exp(-2 D_r t) I, so the point
// x = c + R r drifts towards the centre at -2 D_r R r; the centre itself does not drift and the
// orientation has no drift.
TEST(FreeDrainingDivergence, OffCentreSphereDriftsTowardsItsCentre) {
  const double a = 0.3, b = 0.9;
  const sc::Vec3 r(0.4, -0.7, 0.25);
  sc::FreeDrainingMobility model(off_centre_sphere(a, b, r), 3, 6);
  Rng rng(49);
  const std::vector<sc::Pose> poses = sc::random_poses(3, 0.0, 5.0, rng);
  model.set_configuration(poses);
  const sc::VecX divergence = model.divergence();
  for (std::size_t i = 0; i < 3; ++i) {
    const auto at = 6 * static_cast<Eigen::Index>(i);
    const sc::Vec3 expected = -2.0 * b * (poses[i].q * r);
    EXPECT_LT((divergence.segment<3>(at) - expected).norm(), 1e-14 * expected.norm()) << "body " << i;
    EXPECT_EQ(divergence.segment<3>(at + 3), sc::Vec3::Zero());
  }
}

// Spheres, Yan's rods (anisotropic but uncoupled) and any translation-only model: zero.
TEST(FreeDrainingDivergence, VanishesWithoutAntisymmetricCoupling) {
  Rng rng(50);
  sc::Mat6 symmetric_coupling = sc::spherocylinder_mobility({3.0, 0.5}, 1.0);
  symmetric_coupling.topRightCorner<3, 3>() << 0.01, 0.002, 0, 0.002, -0.01, 0, 0, 0, 0.005;
  symmetric_coupling.bottomLeftCorner<3, 3>() = symmetric_coupling.topRightCorner<3, 3>().transpose();
  const std::vector<sc::Mat6> shapes{sc::sphere_mobility({0.5}, 1.0), sc::spherocylinder_mobility({3.0, 0.5}, 1.0),
                                     symmetric_coupling, off_centre_sphere(0.3, 0.9, {0.4, 0.1, 0.0})};
  for (const int dofs : {6, 3}) {
    sc::FreeDrainingMobility model(shapes, {0, 1, 2, 1, 0, 2}, dofs);
    model.set_configuration(sc::random_poses(6, 0.0, 5.0, rng));
    EXPECT_LT(model.divergence().cwiseAbs().maxCoeff(), 1e-17) << dofs;
  }
  sc::FreeDrainingMobility translation_only(shapes, {3, 3}, 3);  // off-centre, but no rotations
  translation_only.set_configuration(sc::random_poses(2, 0.0, 5.0, rng));
  EXPECT_EQ(translation_only.divergence(), sc::VecX::Zero(6));
}

// The generic RFD, displacing orientations through the quaternion update, agrees with the
// closed form on rotated bodies with general (non-symmetric) coupling.
TEST(FreeDrainingDivergence, AgreesWithTheRandomFiniteDifference) {
  Rng rng(51);
  sc::Mat6 a;
  for (auto& x : a.reshaped()) x = test_support::uniform(rng, -1.0, 1.0);
  const std::vector<sc::Mat6> shapes{a * a.transpose() + 0.3 * sc::Mat6::Identity(),
                                     off_centre_sphere(0.3, 0.9, {0.4, -0.7, 0.25}),
                                     sc::spherocylinder_mobility({3.0, 0.5}, 1.0)};
  sc::FreeDrainingMobility model(shapes, {0, 1, 2}, 6);
  const std::vector<sc::Pose> poses = sc::random_poses(3, 0.0, 5.0, rng);
  model.set_configuration(poses);
  const double kT = 1.5;
  const sc::VecX exact = kT * model.divergence();
  ASSERT_GT(exact.cwiseAbs().maxCoeff(), 0.5);
  const double standard_error = expect_rfd_mean(model, poses, kT, exact, 40000, 52, {1e-4, 1.0}, 1e-6);
  EXPECT_LT(5.0 * standard_error, 0.2 * exact.cwiseAbs().maxCoeff());
}

// thermal_drift takes the exact divergence when the model has one: no application, nothing
// drawn; otherwise one RFD sample (two applications).
TEST(ThermalDrift, UsesTheExactDivergenceWhenTheModelHasOne) {
  Rng rng(53);
  sc::FreeDrainingMobility model(off_centre_sphere(0.3, 0.9, {0.4, -0.7, 0.25}), 4, 6);
  const std::vector<sc::Pose> poses = sc::random_poses(4, 0.0, 5.0, rng);
  model.set_configuration(poses);
  model.reset_applications();
  sc::GaussianStream stream(54), fresh(54);
  EXPECT_EQ(sc::thermal_drift(model, poses, 2.0, stream), 2.0 * model.divergence());
  EXPECT_EQ(model.applications(), 0u);
  EXPECT_EQ(stream(), fresh());

  SineMobility sine(4, 0.5, 0.8, 1.3);
  sine.set_configuration(poses);
  sc::GaussianStream a(55), b(55);
  EXPECT_EQ(sc::thermal_drift(sine, poses, 2.0, a), sc::random_finite_difference_drift(sine, poses, 2.0, b));
  EXPECT_EQ(sine.applications(), 4u);
}

TEST(ThermalDrift, ZeroTemperatureCostsNothing) {
  Rng rng(56);
  SineMobility model(2, 0.5, 0.8, 1.3);
  const std::vector<sc::Pose> poses = sc::random_poses(2, 0.0, 3.0, rng);
  model.set_configuration(poses);
  sc::GaussianStream stream(57), fresh(57);
  EXPECT_EQ(sc::thermal_drift(model, poses, 0.0, stream), sc::VecX::Zero(6));
  EXPECT_EQ(model.applications(), 0u);
  EXPECT_EQ(stream(), fresh());
}

TEST(ThermalDrift, RejectsBadInputNamingTheField) {
  Rng rng(58);
  std::vector<sc::Pose> poses = sc::random_poses(3, 0.0, 3.0, rng);
  SineMobility sine(3, 0.5, 0.8, 1.3);
  sine.set_configuration(poses);
  sc::FreeDrainingMobility free_draining(sc::sphere_mobility({0.5}, 1.0), 3, 6);
  free_draining.set_configuration(poses);
  sc::GaussianStream stream(59);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto both = [&](auto&& call, const std::string& field) {
    expect_rejects([&] { call(sine); }, field);
    expect_rejects([&] { call(free_draining); }, field);
  };
  both([&](auto& m) { sc::thermal_drift(m, poses, -1.0, stream); }, "kT");
  both([&](auto& m) { sc::thermal_drift(m, poses, nan, stream); }, "kT");
  both([&](auto& m) { sc::thermal_drift(m, poses, 1.0, stream, {0.0, 1.0}); }, "RfdOptions.delta");
  both([&](auto& m) { sc::thermal_drift(m, poses, 1.0, stream, {1e-4, nan}); }, "RfdOptions.length");
  const std::vector<sc::Pose> two(poses.begin(), poses.begin() + 2);
  both([&](auto& m) { sc::thermal_drift(m, two, 1.0, stream); }, "poses");
  std::vector<sc::Pose> bad = poses;
  bad[1].q.coeffs() *= 1.1;
  both([&](auto& m) { sc::random_finite_difference_drift(m, bad, 1.0, stream); }, "poses[1].q");
  bad = poses;
  bad[2].x.x() = nan;
  both([&](auto& m) { sc::random_finite_difference_drift(m, bad, 1.0, stream); }, "poses[2].x");
}

}  // namespace thermal_drift_tests
