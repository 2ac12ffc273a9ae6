// A separate project that uses the installed package through its umbrella header.
#include <stokescontact/stokescontact.hpp>

#include <cmath>
#include <cstdio>

int main() {
  using namespace stokescontact;
  const Sphere sphere{1.0};
  const Pose a{Vec3(0, 0, 0), Quat::Identity()};
  const Pose b{Vec3(3, 0, 0), Quat::Identity()};
  const auto cp = closest_points(sphere, a, sphere, b);
  std::printf("consumer: sphere gap %.3f\n", cp.distance);
  return std::abs(cp.distance - 1.0) < 1e-14 ? 0 : 1;
}
