// Mobility applications. Scenes: N unit spheres (or rods) with random centres in a cube at
// packing fraction 0.24, overlaps allowed, viscosity 1.
//  - BM_RpyBlobProduct/N/threads: the blob-blob RPY product M lambda that the multiblob GMRES
//    runs (rpy_blob_product, i.e. the shared direct sum of rpy_direct_sum.hpp with 3 dofs, on
//    the instruction set chosen at run time), N blobs of radius 1, on `threads` OpenMP
//    threads (1 without OpenMP). Reports pairs per second (N^2 per product) and GFLOP/s as
//    executed (executed_flops below).
//  - BM_RpyBlobProductIsa/N/isa: the same product on one thread with the tile loop compiled
//    for isa 0 (baseline x86-64, SSE2), 1 (AVX2 + FMA) or 2 (AVX-512): the dispatch's gain.
//  - BM_Apply<model>/N: one full apply per model on all threads: free-draining spheres
//    (3 dofs), free-draining rods (6 dofs, rotated per body), RPY 3 dofs, RPY 6 dofs
//    (RpyMobility, the same direct sum).
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "stokescontact/mobility/blob_rpy.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/mobility/rpy_mobility.hpp"
#include "stokescontact/scenes/sphere_packing.hpp"

namespace {

using namespace stokescontact;

// Adds and multiplies per pair as executed by the 3-dof tile loop (detail::rpy_tile<false, .>),
// an FMA counted as 2: separation and r^2 (8), 1/sqrt of r^2 + 1e-60 by four Newton steps (18,
// no sqrt or division), 1/r^2, 1/r^3, r, the branch test and both branches of f and h (13),
// r.f, the velocity and its accumulation (18) for one target; a pair of an off-diagonal tile
// acts on both blobs (another 18). Loop invariants and the O(b) fold per tile are not counted.
constexpr double kFlopsOneWay = 57.0, kFlopsBothWays = 75.0;

// Flops of one product of n blobs, padding included: diagonal tiles one way, the others both.
double executed_flops(Eigen::Index n) {
  const detail::RpyBlocks b = detail::rpy_blocks(n);
  const auto c = static_cast<double>(b.count), pairs_per_tile = static_cast<double>(b.size * b.size);
  return pairs_per_tile * (c * kFlopsOneWay + 0.5 * c * (c - 1.0) * kFlopsBothWays);
}

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

// Blob centres (in blob radii) of the RPY scene.
Mat3X random_blobs(Eigen::Index n) {
  const std::vector<Pose> poses = random_poses(n, 42);
  Mat3X x(3, n);
  for (Eigen::Index i = 0; i < n; ++i) x.col(i) = poses[static_cast<std::size_t>(i)].x;
  return x;
}

void set_product_counters(benchmark::State& state, Eigen::Index n) {
  const double pairs = static_cast<double>(n) * static_cast<double>(n);
  state.counters["pairs_per_s"] = benchmark::Counter(pairs, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["GFLOP_per_s"] =
      benchmark::Counter(executed_flops(n) * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_RpyBlobProduct(benchmark::State& state) {
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
  const Mat3X x = random_blobs(n);
  const VecX lambda = random_forces(3 * n, 7);
  for (auto _ : state) {
    VecX u = rpy_blob_product(x, lambda);
    benchmark::DoNotOptimize(u.data());
  }
  set_product_counters(state, n);
  state.SetLabel(rpy_instruction_set_name(rpy_best_instruction_set()));
#ifdef _OPENMP
  omp_set_num_threads(default_threads);
#endif
}

void BM_RpyBlobProductIsa(benchmark::State& state) {
  const Eigen::Index n = state.range(0);
  const auto isa = static_cast<RpyInstructionSet>(state.range(1));
  if (!rpy_instruction_set_supported(isa)) {
    state.SkipWithError("instruction set not supported by this CPU");
    return;
  }
#ifdef _OPENMP
  const int default_threads = omp_get_max_threads();
  omp_set_num_threads(1);
#endif
  const Mat3X x = random_blobs(n);
  const VecX lambda = random_forces(3 * n, 7);
  for (auto _ : state) {
    VecX u = rpy_direct_sum(x, lambda, 3, isa);
    benchmark::DoNotOptimize(u.data());
  }
  set_product_counters(state, n);
  state.SetLabel(rpy_instruction_set_name(isa));
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
// 6144 blobs: the 512-body multiblob scene of bench_multiblob.
void product_arguments(benchmark::internal::Benchmark* b) {
  for (const long n : {100L, 300L, 1000L, 3000L, 6144L, 10000L, 30000L})
    for (const long threads : {1L, 2L}) b->Args({n, threads});
}

BENCHMARK(BM_RpyBlobProduct)->Apply(product_arguments)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RpyBlobProductIsa)->ArgsProduct({{1000, 6144}, {0, 1, 2}})->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ApplyFreeDrainingSpheres)->RangeMultiplier(10)->Range(100, 100000)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ApplyFreeDrainingRods)->RangeMultiplier(10)->Range(100, 100000)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ApplyRpy3)->RangeMultiplier(10)->Range(100, 10000)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ApplyRpy6)->RangeMultiplier(10)->Range(100, 10000)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
