// The contact step's cheap measurements give the numbers of its full ones (contact_step.hpp):
//   - ContactStep::min_distance_at (a ray sample of the default solver: only the moved bodies'
//     pairs measured again, no configuration formed) equals measure(...).min_distance(), bit
//     for bit, and leaves the step's state as it was; separated_at (the same sample, its
//     witness pairs measured first) answers min d >= target exactly, at targets on either
//     side of the minimum;
//   - after pairs are added (rebuild computes only the new pairs' columns and measurements at
//     Q*), every pair's measurement at Q* is its distance computed afresh there;
//   - the result's min_distance_ratio (read from the end check's broad phase, or from
//     minimum_pair_distance with the least flagged distance as at_most) is the smallest d^P
//     over all pairs of the new configuration, computed independently;
//   - minimum_pair_distance with an at_most bound gives the same minimum as without;
//   - evaluate(), which reuses the storage of its previous evaluation, gives measure()'s
//     numbers bit for bit, also after pairs are added.
// Scenes: 2000 spheres at packing 0.3 (open space, blocks mode), 300 spheres in a periodic
// box, and 120 rods in a periodic box pushed and turned hard enough that pairs pass through
// each other in the trial step (carried contacts), with particle and overlap-ends directions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/scenes/periodic_placement.hpp"
#include "stokescontact/scenes/random.hpp"
#include "stokescontact/scenes/sphere_packing.hpp"

namespace contact_step_measure_tests {

namespace sc = stokescontact;

namespace {

constexpr double kDt = 0.01;
constexpr double kDHat = 0.01;

template <sc::Shape S>
struct Scene {
  std::vector<S> shapes;
  std::vector<sc::Pose> poses;
  sc::VecX U;
  std::optional<sc::PeriodicBox> box;
  sc::ContactStepProblem<S> problem() const { return {shapes, poses, U, kDt, kDHat, 0.0, 1.0, box}; }
};

// Unit spheres by random sequential addition at packing 0.3 (open space), or placed at random
// in a periodic box of side 16 (n = 300: packing 0.31) with gaps of at least 0.01.
Scene<sc::Sphere> spheres(std::size_t n, bool periodic, std::uint64_t seed) {
  const double side = 16.0;
  Scene<sc::Sphere> s{{sc::Sphere{1.0}}, {}, {}, std::nullopt};
  if (periodic) {
    s.poses = sc::periodic_random_placement(sc::Sphere{1.0}, n, side, 0.01, seed);
    s.box = sc::PeriodicBox{sc::Vec3::Constant(side)};
  } else {
    s.poses = sc::random_sequential_addition(n, 0.3, seed).poses;
  }
  sc::Rng rng(seed);
  const std::vector<sc::Vec3> f = sc::random_forces(n, 100.0, rng);
  s.U.resize(3 * static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k)  // U = f / (6 pi a mu), a = mu = 1
    s.U.segment<3>(3 * static_cast<Eigen::Index>(k)) = f[k] / (6.0 * std::numbers::pi);
  return s;
}

// 120 rods (L = 4, R = 0.5) at random in a periodic box of side 24, speeds of 150 and
// angular speeds of 50 rad/s in random directions: dt |U| = 1.5 and a turn of 0.5 rad,
// enough for rods of diameter 1 to pass through each other in the trial step.
Scene<sc::Spherocylinder> rods(std::uint64_t seed) {
  const sc::Spherocylinder rod{4.0, 0.5};
  const double side = 24.0;
  const std::size_t n = 120;
  Scene<sc::Spherocylinder> s{{rod}, sc::periodic_random_placement(rod, n, side, 0.05, seed), {},
                              sc::PeriodicBox{sc::Vec3::Constant(side)}};
  sc::Rng rng(seed + 1);
  const std::vector<sc::Vec3> u = sc::random_forces(n, 150.0, rng), w = sc::random_forces(n, 50.0, rng);
  s.U.resize(6 * static_cast<Eigen::Index>(n));
  for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(n); ++k) {
    s.U.segment<3>(6 * k) = u[static_cast<std::size_t>(k)];
    s.U.segment<3>(6 * k + 3) = w[static_cast<std::size_t>(k)];
  }
  return s;
}

template <sc::Shape S>
sc::FreeDrainingMobility mobility_for(const Scene<S>& s) {
  const int dofs = static_cast<int>(s.U.size() / static_cast<Eigen::Index>(s.poses.size()));
  sc::FreeDrainingMobility m(dofs == 3 ? sc::sphere_mobility(sc::Sphere{1.0}, 1.0)
                                       : sc::spherocylinder_mobility(sc::Spherocylinder{4.0, 0.5}, 1.0),
                             s.poses.size(), dofs);
  m.set_configuration(s.poses);
  return m;
}

// Forces on every pair, on about a fifth of them, and none; uniform in [0, scale].
std::vector<sc::VecX> force_samples(Eigen::Index nc, double scale, std::uint64_t seed) {
  sc::Rng rng(seed);
  sc::VecX all(nc), some = sc::VecX::Zero(nc);
  for (Eigen::Index k = 0; k < nc; ++k) {
    all(k) = sc::uniform(rng, 0.0, scale);
    if (sc::uniform(rng, 0.0, 1.0) < 0.2) some(k) = sc::uniform(rng, 0.0, scale);
  }
  return {all, some, sc::VecX::Zero(nc)};
}

// Each pair's measurement at Q* (measure with no correction: nothing moves) against its
// distance computed afresh there; carried pairs are measured by their gap, so only the
// others are compared.
template <sc::Shape S>
void expect_trial_measurements_fresh(const sc::ContactStep<S, sc::FreeDrainingMobility>& step, const Scene<S>& s) {
  const int dofs = step.dofs_per_body();
  const std::vector<sc::Pose> trial = sc::advance_all(s.poses, s.U, dofs, kDt);
  const sc::ContactEvaluation e = step.measure(sc::VecX::Zero(s.U.size()));
  std::size_t compared = 0;
  for (std::size_t k = 0; k < step.pairs().size(); ++k) {
    const sc::ContactPair& p = step.pairs()[k];
    const sc::ContactPair fresh =
        sc::remeasured(p, std::span<const S>(s.shapes), std::span<const sc::Pose>(trial), s.box);
    if (p.points.distance != fresh.points.distance) continue;  // carried: its gap, not d^P
    EXPECT_EQ(e.distances(static_cast<Eigen::Index>(k)), fresh.points.distance) << "pair " << k;
    ++compared;
  }
  EXPECT_GT(compared, step.pairs().size() / 2);
}

// evaluate() reuses the storage of the evaluation before (poses, pairs, distances): what it
// returns must be a fresh measurement's numbers, bit for bit, whatever was there.
void expect_same_evaluation(const sc::ContactEvaluation& reused, const sc::ContactEvaluation& fresh) {
  ASSERT_EQ(reused.distances.size(), fresh.distances.size());
  ASSERT_EQ(reused.pairs.size(), fresh.pairs.size());
  ASSERT_EQ(reused.poses.size(), fresh.poses.size());
  EXPECT_TRUE(reused.MD_lambda == fresh.MD_lambda);
  EXPECT_TRUE(reused.distances == fresh.distances);
  for (std::size_t k = 0; k < fresh.pairs.size(); ++k)
    EXPECT_TRUE(reused.pairs[k].points.normal == fresh.pairs[k].points.normal) << "pair " << k;
  for (std::size_t b = 0; b < fresh.poses.size(); ++b) {
    EXPECT_TRUE(reused.poses[b].x == fresh.poses[b].x) << "body " << b;
    EXPECT_TRUE(reused.poses[b].q.coeffs() == fresh.poses[b].q.coeffs()) << "body " << b;
  }
}

template <sc::Shape S>
void expect_min_distance_at_is_measure(const Scene<S>& s, const sc::ContactStepOptions& options, double scale) {
  sc::FreeDrainingMobility m = mobility_for(s);
  sc::ContactStep<S, sc::FreeDrainingMobility> step(s.problem(), m, options);
  ASSERT_GT(step.nc(), 10);
  for (int round = 0; round < 2; ++round) {
    SCOPED_TRACE("round " + std::to_string(round) + ", " + std::to_string(step.nc()) + " pairs, " +
                 std::to_string(step.carried_count()) + " carried");
    int sample = 0;
    for (const sc::VecX& lambda : force_samples(step.nc(), scale, 11 + static_cast<std::uint64_t>(round))) {
      const sc::VecX MD = step.MD_times(lambda);
      const sc::ContactEvaluation measured = step.measure(MD);
      const double full = measured.min_distance();
      EXPECT_EQ(step.min_distance_at(MD), full) << "sample " << sample;
      EXPECT_EQ(step.min_distance_at(MD), full) << "sample " << sample << ", called again";
      // separated_at answers min d >= target, whatever its witnesses from earlier calls: at
      // the minimum itself, just above and below it, and at targets every pair or none meets.
      for (const double target : {full, std::nextafter(full, 1e300), std::nextafter(full, -1e300), full - 1.0,
                                  full + 1.0, full + 1e-3 * kDHat})
        EXPECT_EQ(step.separated_at(MD, target), full >= target) << "sample " << sample << ", target " << target;
      expect_same_evaluation(step.evaluate(lambda), measured);  // in the last one's storage
      ++sample;
    }
    expect_trial_measurements_fresh(step, s);
    // Pairs the trial step did not flag, as the guarantee loop adds them: all pairs within 0.5.
    const std::vector<sc::Pose> trial = sc::advance_all(s.poses, s.U, step.dofs_per_body(), kDt);
    const std::vector<sc::ContactPair> near =
        sc::find_contact_pairs(std::span<const S>(s.shapes), std::span<const sc::Pose>(trial), 0.5, s.box);
    if (round == 0) {
      ASSERT_GT(step.add_pairs(near), 0u);
    }
  }
}

template <sc::Shape S>
void expect_result_minimum_is_independent(const Scene<S>& s, const sc::ContactStepOptions& options) {
  sc::FreeDrainingMobility m = mobility_for(s);
  const sc::ContactStepResult r = sc::solve_contact_step(s.problem(), m, options);
  EXPECT_GT(r.flagged_pairs, 0u);
  const sc::MinimumDistance fresh =
      sc::minimum_pair_distance(std::span<const S>(s.shapes), std::span<const sc::Pose>(r.poses), s.box);
  EXPECT_EQ(r.min_distance_ratio, fresh.distance / kDHat) << r.message;
}

sc::ContactStepOptions with_directions(sc::ContactDirections d) {
  sc::ContactStepOptions o;
  o.directions = d;
  return o;
}

}  // namespace

TEST(ContactStepMeasure, MinDistanceAtIsTheFullMeasurementForSpheres) {
  expect_min_distance_at_is_measure(spheres(2000, false, 5), {}, 50.0);
  expect_min_distance_at_is_measure(spheres(300, true, 6), {}, 50.0);
}

TEST(ContactStepMeasure, MinDistanceAtIsTheFullMeasurementForCarriedRods) {
  const Scene<sc::Spherocylinder> s = rods(3);
  {
    sc::FreeDrainingMobility m = mobility_for(s);
    const sc::ContactStep<sc::Spherocylinder, sc::FreeDrainingMobility> step(s.problem(), m, {});
    ASSERT_GT(step.carried_count(), 0u) << "the scene must carry pairs that pass through each other";
  }
  expect_min_distance_at_is_measure(s, {}, 20.0);
  expect_min_distance_at_is_measure(s, with_directions(sc::ContactDirections::overlap_ends), 20.0);
}

TEST(ContactStepMeasure, ResultMinimumIsTheSmallestDistanceOverAllPairs) {
  expect_result_minimum_is_independent(spheres(2000, false, 7), {});
  expect_result_minimum_is_independent(spheres(300, true, 8), {});
  const Scene<sc::Spherocylinder> r = rods(4);
  expect_result_minimum_is_independent(r, {});
  expect_result_minimum_is_independent(r, with_directions(sc::ContactDirections::overlap_ends));
}

TEST(MinimumPairDistance, AnAtMostBoundGivesTheSameMinimum) {
  const Scene<sc::Sphere> s = spheres(2000, false, 9);
  const sc::Sphere unit{1.0};
  const std::span<const sc::Pose> q(s.poses);
  const sc::MinimumDistance plain = sc::minimum_pair_distance(unit, q);
  for (const double at_most : {plain.distance, 2.0 * plain.distance, 0.5, 100.0, 0.0}) {
    SCOPED_TRACE("at_most " + std::to_string(at_most));
    const sc::MinimumDistance bounded = sc::minimum_pair_distance(unit, q, std::nullopt, nullptr, at_most);
    EXPECT_EQ(bounded.distance, plain.distance);
    EXPECT_EQ(bounded.i, plain.i);
    EXPECT_EQ(bounded.j, plain.j);
  }
  // Overlapping bodies: a negative bound still finds the deepest pair.
  std::vector<sc::Pose> overlapping(s.poses);
  overlapping[1].x = overlapping[0].x + sc::Vec3(1.5, 0.0, 0.0);
  const sc::MinimumDistance deep = sc::minimum_pair_distance(unit, std::span<const sc::Pose>(overlapping));
  ASSERT_LT(deep.distance, 0.0);
  const std::span<const sc::Pose> both(overlapping);
  EXPECT_EQ(sc::minimum_pair_distance(unit, both, std::nullopt, nullptr, -0.25).distance, deep.distance);
  // Periodic: the same.
  const Scene<sc::Sphere> p = spheres(300, true, 10);
  const sc::MinimumDistance periodic = sc::minimum_pair_distance(unit, std::span<const sc::Pose>(p.poses), p.box);
  const std::span<const sc::Pose> in_box(p.poses);
  EXPECT_EQ(sc::minimum_pair_distance(unit, in_box, p.box, nullptr, periodic.distance).distance, periodic.distance);
  EXPECT_THROW(sc::minimum_pair_distance(unit, q, std::nullopt, nullptr, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
}

}  // namespace contact_step_measure_tests
