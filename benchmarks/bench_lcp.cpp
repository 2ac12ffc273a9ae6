// The LCP solvers on contact-like problems (Yan et al. eq. 39-41): A = D^T M D applied
// matrix-free as three sparse products, b = Phi / dt + D^T U_known.
//  - Bodies: N = Nc / 2 on a cubic lattice of spacing 1 with jitter 0.05, 6 dofs each.
//  - Contacts: Nc distinct lattice-neighbour pairs drawn at random; unit normal along the centre
//    line, contact point at the midpoint moved 0.1 off the line (so contacts exert torques);
//    columns of D as in contact/contact_matrix.hpp (body i: -n, s_i x -n; body j: n, s_j x n).
//  - M: block diagonal, per body diag(1/(3 pi) I, 1/pi I) (spheres of radius 1/2, viscosity 1)
//    plus 0.02 G G^T / 6 with G a random 6 x 6 (coupling, as for non-spherical bodies).
//  - Phi: gaps uniform in [0, 0.02], dt = 0.01; U_known: standard normal per dof.
// BM_Lcp<Solver>/Nc: one cold solve per iteration, tolerance 1e-8 (lcp.hpp's relative rule);
// counters: solver iterations, A applications, converged, residual, fraction of active contacts.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <Eigen/Sparse>

#include "stokescontact/lcp/apgd.hpp"
#include "stokescontact/lcp/bbpgd.hpp"
#include "stokescontact/lcp/minimum_map_newton.hpp"

namespace {

using namespace stokescontact;
using SparseMat = Eigen::SparseMatrix<double>;

struct ContactProblem {
  SparseMat D, Dt, M;
  VecX b;
  VecX apply(const VecX& gamma) const { return Dt * (M * (D * gamma)); }  // A gamma = D^T M D gamma
};

ContactProblem make_problem(Eigen::Index contacts, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Index bodies = std::max<Eigen::Index>(2, contacts / 2);
  const auto side = static_cast<Eigen::Index>(std::ceil(std::cbrt(static_cast<double>(bodies))));
  std::vector<Vec3> x(static_cast<std::size_t>(bodies));
  for (Eigen::Index i = 0; i < bodies; ++i) {
    const Vec3 site(static_cast<double>(i % side), static_cast<double>((i / side) % side),
                    static_cast<double>(i / (side * side)));
    x[static_cast<std::size_t>(i)] = site + 0.05 * Vec3(normal(rng), normal(rng), normal(rng));
  }
  // Lattice neighbours in +x, +y, +z that exist.
  std::vector<std::pair<Eigen::Index, Eigen::Index>> bonds;
  for (Eigen::Index i = 0; i < bodies; ++i)
    for (const Eigen::Index step : {Eigen::Index{1}, side, side * side}) {
      const Eigen::Index j = i + step;
      const bool wraps = (step == 1 && (i % side) == side - 1) || (step == side && ((i / side) % side) == side - 1);
      if (j < bodies && !wraps) bonds.emplace_back(i, j);
    }
  std::shuffle(bonds.begin(), bonds.end(), rng);
  bonds.resize(std::min<std::size_t>(bonds.size(), static_cast<std::size_t>(contacts)));

  ContactProblem p;
  const auto nc = static_cast<Eigen::Index>(bonds.size());
  std::vector<Eigen::Triplet<double>> d_entries;
  for (Eigen::Index c = 0; c < nc; ++c) {
    const auto [i, j] = bonds[static_cast<std::size_t>(c)];
    const Vec3 xi = x[static_cast<std::size_t>(i)], xj = x[static_cast<std::size_t>(j)];
    const Vec3 n = (xj - xi).normalized();
    const Vec3 off = n.cross(Vec3(normal(rng), normal(rng), normal(rng))).normalized();
    const Vec3 point = 0.5 * (xi + xj) + 0.1 * off;
    const Vec3 torque_i = (point - xi).cross(-n), torque_j = (point - xj).cross(n);
    for (int r = 0; r < 3; ++r) {
      d_entries.emplace_back(6 * i + r, c, -n(r));
      d_entries.emplace_back(6 * i + 3 + r, c, torque_i(r));
      d_entries.emplace_back(6 * j + r, c, n(r));
      d_entries.emplace_back(6 * j + 3 + r, c, torque_j(r));
    }
  }
  p.D.resize(6 * bodies, nc);
  p.D.setFromTriplets(d_entries.begin(), d_entries.end());
  p.Dt = p.D.transpose();

  std::vector<Eigen::Triplet<double>> m_entries;
  for (Eigen::Index body = 0; body < bodies; ++body) {
    Mat6 g;
    for (int r = 0; r < 6; ++r)
      for (int s = 0; s < 6; ++s) g(r, s) = normal(rng);
    Mat6 block = 0.02 * g * g.transpose() / 6.0;
    for (int r = 0; r < 3; ++r) {
      block(r, r) += 1.0 / (3.0 * std::numbers::pi);  // 1 / (6 pi eta a), a = 1/2
      block(3 + r, 3 + r) += 1.0 / std::numbers::pi;  // 1 / (8 pi eta a^3)
    }
    for (int r = 0; r < 6; ++r)
      for (int s = 0; s < 6; ++s) m_entries.emplace_back(6 * body + r, 6 * body + s, block(r, s));
  }
  p.M.resize(6 * bodies, 6 * bodies);
  p.M.setFromTriplets(m_entries.begin(), m_entries.end());

  VecX u_known(6 * bodies);
  for (Eigen::Index k = 0; k < u_known.size(); ++k) u_known(k) = normal(rng);
  const double dt = 0.01;
  p.b = p.Dt * u_known;
  for (Eigen::Index c = 0; c < nc; ++c) p.b(c) += 0.02 * unit(rng) / dt;
  return p;
}

enum class Solver { kBbpgd, kApgd, kMinimumMapNewton };

void run(benchmark::State& state, Solver solver) {
  const ContactProblem problem = make_problem(state.range(0), 7);
  const auto apply = [&problem](const VecX& gamma) { return problem.apply(gamma); };
  const LcpOptions options{.tolerance = 1e-8, .max_iterations = 20000};
  LcpResult result;
  for (auto _ : state) {
    switch (solver) {
      case Solver::kBbpgd: result = solve_lcp_bbpgd(apply, problem.b, options); break;
      case Solver::kApgd: result = solve_lcp_apgd(apply, problem.b, options); break;
      case Solver::kMinimumMapNewton: result = solve_lcp_minimum_map_newton(apply, problem.b, options); break;
    }
    benchmark::DoNotOptimize(result.gamma.data());
  }
  state.counters["Nc"] = static_cast<double>(problem.b.size());
  state.counters["iterations"] = result.iterations;
  state.counters["applications"] = static_cast<double>(result.operator_applications);
  state.counters["converged"] = result.converged ? 1.0 : 0.0;
  state.counters["residual"] = result.residual;
  state.counters["active_fraction"] =
      static_cast<double>((result.gamma.array() > 0.0).count()) / static_cast<double>(problem.b.size());
}

void BM_LcpBbpgd(benchmark::State& state) { run(state, Solver::kBbpgd); }
void BM_LcpApgd(benchmark::State& state) { run(state, Solver::kApgd); }
void BM_LcpMinimumMapNewton(benchmark::State& state) { run(state, Solver::kMinimumMapNewton); }

constexpr std::array<long, 5> kContacts = {100, 300, 1000, 3000, 10000};

void contact_counts(benchmark::internal::Benchmark* b) {
  for (const long nc : kContacts) b->Arg(nc);
  b->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_LcpBbpgd)->Apply(contact_counts);
BENCHMARK(BM_LcpApgd)->Apply(contact_counts);
BENCHMARK(BM_LcpMinimumMapNewton)->Apply(contact_counts);

}  // namespace
