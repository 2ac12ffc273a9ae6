// Rigid multiblob mobility of N sphere shells (12 or 42 blobs, hydrodynamic radius 1) at
// packing fraction 0.2, centres placed by random sequential addition at least 2.2 apart.
//  - BM_MultiblobDenseSetup: set_configuration on the dense path (assemble M, Cholesky,
//    form N) plus one apply: the cost of the first application in a configuration.
//  - BM_MultiblobDenseApply: one apply once N is formed (a 6N x 6N product).
//  - BM_MultiblobMatrixFree: one apply on the matrix-free path (GMRES, block-diagonal
//    preconditioner, tolerance 1e-8); counter gmres_iterations per apply should stay flat.
// Arguments: {blobs per shell, N}.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "stokescontact/mobility/multiblob_mobility.hpp"
#include "stokescontact/mobility/sphere_shell.hpp"

namespace {

using namespace stokescontact;

constexpr double kPacking = 0.2;
constexpr double kMinCentreDistance = 2.2;  // R_h = 1 spheres with a 10% gap

std::vector<Pose> random_packing(int n, unsigned seed) {
  const double side = std::cbrt(n * 4.0 / 3.0 * std::numbers::pi / kPacking);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, side);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Pose> poses;
  while (static_cast<int>(poses.size()) < n) {
    const Vec3 x(u(rng), u(rng), u(rng));
    bool free = true;
    for (const Pose& p : poses) free = free && (p.x - x).norm() >= kMinCentreDistance;
    if (free) poses.push_back({x, Quat(g(rng), g(rng), g(rng), g(rng)).normalized()});
  }
  return poses;
}

MultiblobMobility make(int blobs, int n, MultiblobSolver solver) {
  MultiblobOptions options;
  options.solver = solver;
  options.gmres.tolerance = 1e-8;
  return MultiblobMobility(sphere_shell(blobs, 1.0), static_cast<std::size_t>(n), options);
}

VecX unit_forces(int n) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  VecX f(6 * n);
  for (Eigen::Index i = 0; i < f.size(); ++i) f(i) = g(rng);
  return f;
}

void set_counters(benchmark::State& state, const MultiblobMobility& m) {
  state.counters["bodies"] = static_cast<double>(state.range(1));
  state.counters["blobs"] = static_cast<double>(m.blob_count());
}

void BM_MultiblobDenseSetup(benchmark::State& state) {
  const int blobs = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  MultiblobMobility m = make(blobs, n, MultiblobSolver::dense);
  const std::vector<Pose> poses = random_packing(n, 1);
  const VecX f = unit_forces(n);
  for (auto _ : state) {
    m.set_configuration(poses);
    benchmark::DoNotOptimize(m.apply(f).data());
  }
  set_counters(state, m);
}

void BM_MultiblobDenseApply(benchmark::State& state) {
  const int blobs = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  MultiblobMobility m = make(blobs, n, MultiblobSolver::dense);
  m.set_configuration(random_packing(n, 1));
  const VecX f = unit_forces(n);
  for (auto _ : state) benchmark::DoNotOptimize(m.apply(f).data());
  set_counters(state, m);
}

void BM_MultiblobMatrixFree(benchmark::State& state) {
  const int blobs = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  MultiblobMobility m = make(blobs, n, MultiblobSolver::matrix_free);
  m.set_configuration(random_packing(n, 1));
  const VecX f = unit_forces(n);
  m.reset_applications();
  for (auto _ : state) benchmark::DoNotOptimize(m.apply(f).data());
  set_counters(state, m);
  state.counters["gmres_iterations"] =
      static_cast<double>(m.total_iterations()) / static_cast<double>(m.applications());
}

// Dense: up to ~1000 blobs (the automatic threshold) and a step past it.
BENCHMARK(BM_MultiblobDenseSetup)
    ->ArgsProduct({{12}, {2, 8, 32, 83, 166}})
    ->ArgsProduct({{42}, {2, 8, 24, 48}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MultiblobDenseApply)->ArgsProduct({{12}, {2, 8, 32, 83, 166}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MultiblobMatrixFree)
    ->ArgsProduct({{12}, {2, 8, 32, 128, 512, 1000}})
    ->ArgsProduct({{42}, {2, 8, 32, 128, 256}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
