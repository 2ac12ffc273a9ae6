#pragma once
// Checks every mobility model must pass, shared by the model test suites.
#include <gtest/gtest.h>

#include <cstddef>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

#include "stokescontact/core/pose.hpp"
#include "stokescontact/mobility/mobility_operator.hpp"

namespace mobility_checks {

namespace sc = stokescontact;

inline sc::Quat random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return sc::Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
}

inline double min_eigenvalue(const sc::MatX& m) {
  return Eigen::SelfAdjointEigenSolver<sc::MatX>(m, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

// Centres uniform in a cube of side `box` (overlaps allowed), orientations uniform (a
// normalised Gaussian quaternion).
inline std::vector<sc::Pose> random_poses(std::size_t n, double box, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, box);
  std::vector<sc::Pose> poses(n);
  for (sc::Pose& p : poses) {
    p.x = sc::Vec3(u(rng), u(rng), u(rng));
    p.q = random_rotation(rng);
  }
  return poses;
}

inline sc::VecX random_vector(Eigen::Index n, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  sc::VecX v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = g(rng);
  return v;
}

// apply(F) equals dense_matrix() * F to `tolerance` (max norm, relative), forming the dense
// matrix costs no application, each apply counts one, zero force gives exactly zero, and
// reset_applications() clears the count. The model must be configured.
template <sc::DenseMobilityOperator M>
void expect_apply_matches_dense(M& m, std::mt19937& rng, double tolerance) {
  std::normal_distribution<double> g(0.0, 1.0);
  m.reset_applications();
  const sc::MatX dense = m.dense_matrix();
  EXPECT_EQ(m.applications(), 0u);  // formed directly
  for (std::size_t k = 1; k <= 3; ++k) {
    sc::VecX F(m.size());
    for (auto& f : F) f = g(rng);
    const sc::VecX U = m.apply(F), expected = dense * F;
    EXPECT_LT((U - expected).cwiseAbs().maxCoeff(), tolerance * expected.cwiseAbs().maxCoeff());
    EXPECT_EQ(m.applications(), k);
  }
  EXPECT_EQ(m.apply(sc::VecX::Zero(m.size())).cwiseAbs().maxCoeff(), 0.0);
  m.reset_applications();
  EXPECT_EQ(m.applications(), 0u);
}

}  // namespace mobility_checks
