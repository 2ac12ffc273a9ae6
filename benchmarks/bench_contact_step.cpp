// One contact step of the default solver (detection, solve, whole-step guarantee; only this
// solver is instantiated, to keep the build light) for N unit
// spheres at packing 0.3 (random sequential addition, seed N), random forces |f| = 100, free
// draining, dt = d_hat = 0.01: the scene of examples/contact_step_scaling, per cost mode
// (contact_step.hpp). The scene and U are built once; each iteration is one contact step from
// the same Q_t. Counters: flagged and pushed pairs, mobility applications, time per sphere,
// guarantee rounds.
// N = 1e6 is registered but takes seconds per iteration: select it with --benchmark_filter.
// Also the step's two O(N) geometry passes on the same packing (contact/contact_pairs.hpp):
// detection (find_contact_pairs at d_try = 0.1) and the smallest distance over all pairs
// (minimum_pair_distance), whose pair loops parallel_for shares out over OpenMP threads
// (run with OMP_NUM_THREADS=1 and 2 to see their scaling).
// Counter page_faults: the process's minor page faults per iteration (getrusage), the pages a
// step touches for the first time: on a virtual machine each costs microseconds.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cstddef>
#include <map>
#include <vector>

#include "stokescontact/contact/solvers/defect_correction.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/scenes/random.hpp"
#include "stokescontact/scenes/sphere_packing.hpp"

namespace {

using namespace stokescontact;

long minor_faults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// Minor page faults per iteration since `first` (taken before the loop).
void count_page_faults(benchmark::State& state, long first) {
  state.counters["page_faults"] = benchmark::Counter(static_cast<double>(minor_faults() - first),
                                                     benchmark::Counter::kAvgIterations);
}

void run(benchmark::State& state, MobilityCost cost, const DefectCorrectionOptions& solver = {}) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const double dt = 0.01, d_hat = 0.01;
  const std::vector<Sphere> shapes{Sphere{1.0}};
  const SpherePacking packing = random_sequential_addition(n, 0.3, n);
  Rng rng(n);
  const std::vector<Vec3> f = random_forces(n, 100.0, rng);
  VecX F(3 * static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k) F.segment<3>(3 * static_cast<Eigen::Index>(k)) = f[k];
  FreeDrainingMobility mobility(sphere_mobility(shapes[0], 1.0), n, 3);
  mobility.set_configuration(packing.poses);
  const VecX U = mobility.apply(F);
  const ContactStepProblem<Sphere> problem{shapes, packing.poses, U, dt, d_hat};
  ContactStepOptions options;
  options.cost = cost;
  ContactStepResult r;
  const long faults = minor_faults();
  for (auto _ : state) {
    r = solve_contact_step_defect_correction(problem, mobility, options, solver);
    benchmark::DoNotOptimize(r.lambda.data());
  }
  count_page_faults(state, faults);
  if (r.status != ContactStepStatus::converged) state.SkipWithError(r.message.c_str());
  state.counters["flagged"] = static_cast<double>(r.flagged_pairs);
  state.counters["pushed"] = static_cast<double>((r.lambda.array() > 0.0).count());
  state.counters["applications"] = static_cast<double>(r.mobility_applications);
  state.counters["rounds"] = static_cast<double>(r.guarantee_rounds);
  state.counters["time_per_sphere"] = benchmark::Counter(
      static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_ContactStepBlocks(benchmark::State& state) { run(state, MobilityCost::blocks); }
void BM_ContactStepMatrixFree(benchmark::State& state) { run(state, MobilityCost::matrix_free); }
// The default solver checking the end only after its rounds have converged
// (DefectCorrectionOptions::early_end_check off): from 3e4 spheres on, a second round.
void BM_ContactStepBlocksLateEndCheck(benchmark::State& state) {
  DefectCorrectionOptions late;
  late.early_end_check = false;
  run(state, MobilityCost::blocks, late);
}
void BM_ContactStepFormed(benchmark::State& state) { run(state, MobilityCost::formed); }

// The packing of N spheres of run(), built once per size.
const SpherePacking& packing_of(std::size_t n) {
  static std::map<std::size_t, SpherePacking> cache;
  auto it = cache.find(n);
  if (it == cache.end()) it = cache.emplace(n, random_sequential_addition(n, 0.3, n)).first;
  return it->second;
}

void BM_FindContactPairs(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const SpherePacking& packing = packing_of(n);
  CellList cells;
  std::size_t flagged = 0;
  const long faults = minor_faults();
  for (auto _ : state) {
    const std::vector<ContactPair> pairs = find_contact_pairs(Sphere{1.0}, packing.poses, 0.1, {}, &cells);
    benchmark::DoNotOptimize(pairs.data());
    flagged = pairs.size();
  }
  count_page_faults(state, faults);
  state.counters["flagged"] = static_cast<double>(flagged);
  state.counters["time_per_sphere"] = benchmark::Counter(
      static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_MinimumPairDistance(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const SpherePacking& packing = packing_of(n);
  CellList cells;
  const long faults = minor_faults();
  for (auto _ : state) benchmark::DoNotOptimize(minimum_pair_distance(Sphere{1.0}, packing.poses, {}, &cells).distance);
  count_page_faults(state, faults);
  state.counters["time_per_sphere"] = benchmark::Counter(
      static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

BENCHMARK(BM_FindContactPairs)->RangeMultiplier(10)->Range(10000, 1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MinimumPairDistance)->RangeMultiplier(10)->Range(10000, 1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ContactStepBlocks)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ContactStepMatrixFree)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ContactStepBlocksLateEndCheck)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);
// Formed holds one dense column of M D per working-set pair: O(N x pairs), 1e4 at most here.
BENCHMARK(BM_ContactStepFormed)->RangeMultiplier(10)->Range(1000, 10000)->Unit(benchmark::kMillisecond);

}  // namespace
