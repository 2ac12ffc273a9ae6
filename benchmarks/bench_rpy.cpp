// Mobility applications. Scenes: N unit spheres (or rods) with random centres in a cube at
// packing fraction 0.24, overlaps allowed, viscosity 1.
//  - BM_RpyTranslationProduct/N/threads: the blob-blob RPY product U = M_tt F (RpyMobility with
//    3 dofs), all N^2 pairs, on `threads` OpenMP threads (1 without OpenMP). Reports pair
//    interactions per second and GFLOP/s at kFlopsPerPair flops per pair interaction.
//  - BM_Apply<model>/N: one full apply per model on all threads: free-draining spheres
//    (3 dofs), free-draining rods (6 dofs, rotated per body), RPY 3 dofs, RPY 6 dofs.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/rpy_mobility.hpp"
#include "stokescontact/scenes/sphere_packing.hpp"

namespace {

using namespace stokescontact;

// Adds and multiplies per pair as executed by the 3-dof kernel (rpy_target_block<false>):
// separation and r^2 (8), 1/sqrt of r^2 + 1e-300 by four Newton steps (18, no sqrt or
// division), r, 1/r^2, the branch masks and both branches of f and h (25), r.f and the three
// updates (18). Loop-invariant products are not counted.
constexpr double kFlopsPerPair = 69.0;

std::vector<Pose> random_poses(Eigen::Index n, unsigned seed) {
  Rng rng(seed);
  const auto count = static_cast<std::size_t>(n);
  return stokescontact::random_poses(count, 0.0, cube_side(count, 0.24), rng);
}

VecX random_forces(Eigen::Index size, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  VecX f(size);
  for (Eigen::Index i = 0; i < size; ++i) f(i) = g(rng);
  return f;
}

template <typename Model>
void time_applications(benchmark::State& state, Model& model, Eigen::Index n) {
  model.set_configuration(random_poses(n, 42));
  const VecX F = random_forces(model.size(), 7);
  for (auto _ : state) {
    VecX U = model.apply(F);
    benchmark::DoNotOptimize(U.data());
  }
  state.counters["time_per_body"] = benchmark::Counter(
      static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_RpyTranslationProduct(benchmark::State& state) {
  const Eigen::Index n = state.range(0);
  const auto threads = static_cast<int>(state.range(1));
#ifdef _OPENMP
  const int default_threads = omp_get_max_threads();
  omp_set_num_threads(threads);
#else
  if (threads != 1) {
    state.SkipWithError("built without OpenMP");
    return;
  }
#endif
  RpyMobility model(static_cast<std::size_t>(n), {1.0, 1.0}, 3);
  time_applications(state, model, n);
  const double pairs = static_cast<double>(n) * static_cast<double>(n);
  state.counters["pairs_per_s"] = benchmark::Counter(pairs, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["GFLOP_per_s"] =
      benchmark::Counter(pairs * kFlopsPerPair * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
#ifdef _OPENMP
  omp_set_num_threads(default_threads);
#endif
}

void BM_ApplyFreeDrainingSpheres(benchmark::State& state) {
  const Eigen::Index n = state.range(0);
  FreeDrainingMobility model(sphere_mobility({1.0}, 1.0), static_cast<std::size_t>(n), 3);
  time_applications(state, model, n);
}

void BM_ApplyFreeDrainingRods(benchmark::State& state) {
  const Eigen::Index n = state.range(0);
  FreeDrainingMobility model(spherocylinder_mobility({4.0, 0.5}, 1.0), static_cast<std::size_t>(n), 6);
  time_applications(state, model, n);
}

void BM_ApplyRpy3(benchmark::State& state) {
  const Eigen::Index n = state.range(0);
  RpyMobility model(static_cast<std::size_t>(n), {1.0, 1.0}, 3);
  time_applications(state, model, n);
}

void BM_ApplyRpy6(benchmark::State& state) {
  const Eigen::Index n = state.range(0);
  RpyMobility model(static_cast<std::size_t>(n), {1.0, 1.0}, 6);
  time_applications(state, model, n);
}

// Thread counts 1 and 2 by default; pass e.g. --benchmark_filter to pick, or edit for more cores.
void product_arguments(benchmark::internal::Benchmark* b) {
  for (const long n : {100L, 300L, 1000L, 3000L, 10000L, 30000L})
    for (const long threads : {1L, 2L}) b->Args({n, threads});
}

BENCHMARK(BM_RpyTranslationProduct)->Apply(product_arguments)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ApplyFreeDrainingSpheres)->RangeMultiplier(10)->Range(100, 100000)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ApplyFreeDrainingRods)->RangeMultiplier(10)->Range(100, 100000)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ApplyRpy3)->RangeMultiplier(10)->Range(100, 10000)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ApplyRpy6)->RangeMultiplier(10)->Range(100, 10000)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
