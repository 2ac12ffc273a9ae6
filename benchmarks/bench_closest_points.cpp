// Closest-point queries per second for each pair of shape types: the demo's unit sphere,
// rod (length 4, radius 0.5) and Broms-Tornberg boomerang, on a pool of 4096 random pose
// pairs whose bounding balls overlap (what a broad phase hands over: from deep overlap to
// about two radii apart). items_per_second is queries per second.
#include <benchmark/benchmark.h>

#include <cstddef>
#include <vector>

#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/scenes/random.hpp"

namespace {

using namespace stokescontact;

struct PosePair {
  Pose a, b;
};

// Uniform in the ball of this radius (rejection from the cube around it).
Vec3 random_in_ball(Rng& rng, double radius) {
  for (;;) {
    const Vec3 v = uniform_vector(rng, -1, 1);
    if (v.squaredNorm() <= 1.0) return radius * v;
  }
}

std::vector<PosePair> pose_pool(double reach) {
  Rng rng(2024);
  std::vector<PosePair> pool(4096);
  for (PosePair& p : pool) {
    p.a = {random_in_ball(rng, 10.0), random_rotation(rng)};
    p.b = {p.a.x + random_in_ball(rng, reach), random_rotation(rng)};
  }
  return pool;
}

template <Shape A, Shape B>
void run(benchmark::State& state, const A& a, const B& b) {
  const std::vector<PosePair> pool = pose_pool(bounding_radius(a) + bounding_radius(b));
  std::size_t i = 0;
  for (auto _ : state) {
    const PosePair& p = pool[i++ % pool.size()];
    benchmark::DoNotOptimize(closest_points(a, p.a, b, p.b));
  }
  state.SetItemsProcessed(state.iterations());
}

const Sphere kSphere{1.0};
const Spherocylinder kRod{4.0, 0.5};
const Boomerang kBoomerang = broms_tornberg_boomerang();

void BM_SphereSphere(benchmark::State& state) { run(state, kSphere, kSphere); }
void BM_SphereRod(benchmark::State& state) { run(state, kSphere, kRod); }
void BM_SphereBoomerang(benchmark::State& state) { run(state, kSphere, kBoomerang); }
void BM_RodRod(benchmark::State& state) { run(state, kRod, kRod); }
void BM_RodBoomerang(benchmark::State& state) { run(state, kRod, kBoomerang); }
void BM_BoomerangBoomerang(benchmark::State& state) { run(state, kBoomerang, kBoomerang); }

BENCHMARK(BM_SphereSphere);
BENCHMARK(BM_SphereRod);
BENCHMARK(BM_SphereBoomerang);
BENCHMARK(BM_RodRod);
BENCHMARK(BM_RodBoomerang);
BENCHMARK(BM_BoomerangBoomerang);

}  // namespace
