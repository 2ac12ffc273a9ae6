#pragma once
// Checks every mobility model must pass, shared by the model test suites.
#include <gtest/gtest.h>

#include <cstddef>
#include <random>

#include <Eigen/Eigenvalues>

#include "stokescontact/mobility/mobility_operator.hpp"
#include "stokescontact/scenes/random.hpp"

namespace mobility_checks {

namespace sc = stokescontact;

inline double min_eigenvalue(const sc::MatX& m) {
  return Eigen::SelfAdjointEigenSolver<sc::MatX>(m, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

inline sc::VecX random_vector(Eigen::Index n, sc::Rng& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  sc::VecX v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = g(rng);
  return v;
}

// apply(F) equals dense_matrix() * F to `tolerance` (max norm, relative), forming the dense
// matrix costs no application, each apply counts one, zero force gives exactly zero, and
// reset_applications() clears the count. The model must be configured.
template <sc::DenseMobilityOperator M>
void expect_apply_matches_dense(M& m, sc::Rng& rng, double tolerance) {
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
