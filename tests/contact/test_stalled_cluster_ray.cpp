// The ray a stalled round of the default solver searches (defect_correction.hpp,
// stalled_cluster_ray): only the forces of the clusters not yet separated are scaled, and its
// M D is that of the forces it stands for.
//
// Five spheres of radius 1 on the x axis, free draining (blocks mode: M D exact and free):
// 0-1 and 1-2 share body 1 (one cluster), 3-4 is a cluster of its own, far away. Each pair
// is pushed together so that the trial step flags it.
#include <gtest/gtest.h>

#include <vector>

#include "stokescontact/contact/solvers/defect_correction.hpp"
#include "stokescontact/mobility/free_draining.hpp"

namespace stalled_cluster_ray_tests {

namespace sc = stokescontact;

namespace {

const sc::Sphere kSphere{1.0};
constexpr double kDHat = 0.01;

struct Scene {
  std::vector<sc::Sphere> shapes{kSphere};
  std::vector<sc::Pose> poses;
  sc::VecX U;
  sc::FreeDrainingMobility mobility{sc::sphere_mobility(kSphere, 1.0), 5, 3};

  Scene() {
    for (const double x : {0.0, 2.02, 4.04, 20.0, 22.02}) poses.push_back({sc::Vec3(x, 0.0, 0.0), sc::Quat::Identity()});
    U = sc::VecX::Zero(15);
    U(0) = 1.0;   // 0 towards 1
    U(6) = -1.0;  // 2 towards 1
    U(9) = 1.0;   // 3 towards 4
    mobility.set_configuration(poses);
  }
  sc::ContactStepProblem<sc::Sphere> problem() const { return {shapes, poses, U, 0.01, kDHat, 0.0, 1.0, {}}; }
};

// Pair index of (i, j) among the flagged pairs.
Eigen::Index pair_index(const std::vector<sc::ContactPair>& pairs, Eigen::Index i, Eigen::Index j) {
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (pairs[k].i == i && pairs[k].j == j) return static_cast<Eigen::Index>(k);
  ADD_FAILURE() << "pair " << i << ", " << j << " not flagged";
  return 0;
}

}  // namespace

TEST(StalledClusterRay, ScalesOnlyTheClustersNotYetSeparated) {
  Scene scene;
  sc::ContactStep<sc::Sphere, sc::FreeDrainingMobility> step(scene.problem(), scene.mobility, {});
  ASSERT_EQ(step.nc(), 3);
  const Eigen::Index a = pair_index(step.pairs(), 0, 1), b = pair_index(step.pairs(), 1, 2),
                     c = pair_index(step.pairs(), 3, 4);
  const double target = kDHat;
  sc::VecX lambda(3), distances(3);
  lambda(a) = 2.0;
  lambda(b) = 1.0;
  lambda(c) = 3.0;
  // Pair 1-2 short: its cluster (0-1, 1-2, linked by body 1) is scaled, 3-4 held.
  distances(a) = 2.0 * target;
  distances(b) = 0.5 * target;
  distances(c) = 2.0 * target;
  const sc::VecX MD = step.MD_times(lambda);
  sc::detail::ForceRay ray = sc::detail::stalled_cluster_ray(step, lambda, MD, distances, target);
  EXPECT_EQ(ray.direction(a), 2.0);
  EXPECT_EQ(ray.direction(b), 1.0);
  EXPECT_EQ(ray.direction(c), 0.0);
  EXPECT_EQ(ray.base(c), 3.0);
  EXPECT_EQ(ray.base(a), 0.0);
  for (const double s : {0.5, 1.0, 3.0}) {
    const sc::VecX expected = step.MD_times(ray.lambda(s));
    EXPECT_LT((ray.MD(s) - expected).norm(), 1e-12 * expected.norm()) << "s " << s;
  }
  EXPECT_EQ(ray.lambda(1.0), lambda);

  // Pair 3-4 short instead: only its own force scaled.
  distances(b) = 2.0 * target;
  distances(c) = 0.5 * target;
  ray = sc::detail::stalled_cluster_ray(step, lambda, MD, distances, target);
  EXPECT_EQ(ray.direction(a), 0.0);
  EXPECT_EQ(ray.direction(b), 0.0);
  EXPECT_EQ(ray.direction(c), 3.0);

  // Both clusters short: the whole iterate, the ray through lambda.
  distances(b) = 0.5 * target;
  ray = sc::detail::stalled_cluster_ray(step, lambda, MD, distances, target);
  EXPECT_EQ(ray.direction, lambda);
  EXPECT_TRUE(ray.base.isZero(0.0));
  EXPECT_EQ(ray.MD_direction, MD);

  // A pair with neither force nor shortfall links nothing: 1-2 unpushed and separated leaves
  // 0-1 a cluster of its own.
  lambda(b) = 0.0;
  distances(b) = 2.0 * target;
  distances(a) = 0.5 * target;
  distances(c) = 2.0 * target;
  ray = sc::detail::stalled_cluster_ray(step, lambda, step.MD_times(lambda), distances, target);
  EXPECT_EQ(ray.direction(a), 2.0);
  EXPECT_EQ(ray.direction(c), 0.0);
  EXPECT_EQ(ray.base(c), 3.0);
}

}  // namespace stalled_cluster_ray_tests
