// Broad-phase time for N unit spheres at packing fraction 0.24 (random centres in a cube,
// overlaps allowed), cutoff 0.1, open and periodic; one CellList reused across iterations.
// Kept: the same query answered from candidates kept within a skin of 0.1 (CellList::
// keep_candidates), the bodies moved by up to 0.02 per coordinate since they were kept.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <random>

#include "stokescontact/geometry/broad_phase.hpp"

namespace {

using namespace stokescontact;

void run(benchmark::State& state, bool periodic) {
  const auto n = static_cast<Eigen::Index>(state.range(0));
  const double radius = 1.0, cutoff = 0.1, phi = 0.24;
  const double side = std::cbrt(static_cast<double>(n) * 4.0 / 3.0 * std::numbers::pi / phi);
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, side);
  Mat3X x(3, n);
  for (Eigen::Index i = 0; i < n; ++i) x.col(i) = Vec3(u(rng), u(rng), u(rng));
  const std::optional<PeriodicBox> box =
      periodic ? std::optional<PeriodicBox>(PeriodicBox{Vec3::Constant(side)}) : std::nullopt;
  CellList cells;
  std::size_t pairs = 0;
  for (auto _ : state) {
    const auto& found = cells.find_pairs(x, radius, cutoff, box);
    benchmark::DoNotOptimize(found.data());
    pairs = found.size();
  }
  // Inverted rate of N per iteration: seconds per particle, printed with an SI prefix (e.g. 85ns).
  state.counters["time_per_particle"] = benchmark::Counter(
      static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["pairs"] = static_cast<double>(pairs);
  state.counters["checks_per_particle"] = static_cast<double>(cells.pair_checks()) / static_cast<double>(n);
}

void run_kept(benchmark::State& state, bool periodic) {
  const auto n = static_cast<Eigen::Index>(state.range(0));
  const double radius = 1.0, cutoff = 0.1, phi = 0.24, skin = 0.1;
  const double side = std::cbrt(static_cast<double>(n) * 4.0 / 3.0 * std::numbers::pi / phi);
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, side), move(-0.02, 0.02);
  Mat3X x(3, n);
  for (Eigen::Index i = 0; i < n; ++i) x.col(i) = Vec3(u(rng), u(rng), u(rng));
  const std::optional<PeriodicBox> box =
      periodic ? std::optional<PeriodicBox>(PeriodicBox{Vec3::Constant(side)}) : std::nullopt;
  CellList cells;
  cells.keep_candidates(skin);
  (void)cells.find_pairs(x, radius, cutoff, box);  // keeps the candidates
  for (Eigen::Index i = 0; i < n; ++i) x.col(i) += Vec3(move(rng), move(rng), move(rng));
  std::size_t pairs = 0;
  for (auto _ : state) {
    const auto& found = cells.find_pairs(x, radius, cutoff, box);
    benchmark::DoNotOptimize(found.data());
    pairs = found.size();
  }
  if (!cells.last_query_reused()) state.SkipWithError("the kept candidates did not answer");
  state.counters["time_per_particle"] = benchmark::Counter(
      static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["pairs"] = static_cast<double>(pairs);
  state.counters["checks_per_particle"] = static_cast<double>(cells.pair_checks()) / static_cast<double>(n);
}

void BM_BroadPhaseOpen(benchmark::State& state) { run(state, false); }
void BM_BroadPhasePeriodic(benchmark::State& state) { run(state, true); }

BENCHMARK(BM_BroadPhaseOpen)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BroadPhasePeriodic)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);
void BM_BroadPhaseKeptOpen(benchmark::State& state) { run_kept(state, false); }
void BM_BroadPhaseKeptPeriodic(benchmark::State& state) { run_kept(state, true); }
BENCHMARK(BM_BroadPhaseKeptOpen)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BroadPhaseKeptPeriodic)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);

}  // namespace
