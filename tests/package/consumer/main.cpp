// A separate project that uses the installed package through its umbrella header: closest
// points, and one contact step by the default solver chosen by value. EXPECT_NLOPT (0 or 1)
// says whether the installed package was configured with the barrier solver.
#include <stokescontact/stokescontact.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

int main() {
  namespace sc = stokescontact;
  const sc::Sphere sphere{1.0};
  const sc::Pose a{sc::Vec3(0, 0, 0), sc::Quat::Identity()};
  const sc::Pose b{sc::Vec3(3, 0, 0), sc::Quat::Identity()};
  const auto cp = sc::closest_points(sphere, a, sphere, b);
  std::printf("consumer: sphere gap %.3f\n", cp.distance);
  if (std::abs(cp.distance - 1.0) > 1e-14) return 1;

  // Two unit spheres 0.1 apart, pushed together at 10 each: the step must hold d_hat.
  const std::vector<sc::Pose> poses{{sc::Vec3(0, 0, 0), sc::Quat::Identity()}, {sc::Vec3(2.1, 0, 0), sc::Quat::Identity()}};
  const std::vector<sc::Sphere> shapes{sphere};
  sc::FreeDrainingMobility mobility(sc::sphere_mobility(sphere, 1.0), poses.size(), 3);
  sc::VecX U(6);
  U << 10, 0, 0, -10, 0, 0;
  const sc::ContactStepProblem<sc::Sphere> problem{.shapes = shapes, .poses = poses, .U = U, .dt = 0.01, .d_hat = 0.01};
  const sc::ContactStepResult r =
      sc::solve_contact_step(problem, mobility, {}, sc::contact_solver_from_name("default"));
  std::printf("consumer: contact step %s, min d / d_hat = %.6f\n", r.status == sc::ContactStepStatus::converged ? "converged" : "FAILED",
              r.min_distance_ratio);
  if (r.status != sc::ContactStepStatus::converged || r.min_distance_ratio < 1.0 - 1e-9) return 1;

  const std::vector<std::string> names = sc::contact_solver_names();
  const bool has_barrier = std::find(names.begin(), names.end(), "barrier-slsqp") != names.end();
  std::printf("consumer: barrier solvers %s\n", has_barrier ? "available" : "not built (no NLopt)");
  return has_barrier == (EXPECT_NLOPT != 0) ? 0 : 1;
}
