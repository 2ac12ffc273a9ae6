// Far roots of the linearised contact step (eq. 13) on two crossing rods, and the guard that
// refuses them: ContactStepOptions::max_correction_turn (contact/contact_step.hpp).
//
// Two rods (L = 4, R = 0.5, free draining) crossing at a small angle, a gap of ~2 d_hat,
// pressed into each other by +-f across their axes with random torques: the trial step
// overlaps deeply. Eq. 13 is linear in the rotation, so the end gap of the pair can reach
// d_hat again far along the force: the default solver and the LCP sequence both find such a
// root, lambda 1700-3000 (7-10x the push) with a correction that turns a rod by 1.1-1.7 rad and
// leaves the pair 13-31 d_hat apart, or overlapping (the LCP sequence), instead of at d_hat.
// Before the guard the default solver reported those steps converged. The cases were drawn at
// random (theta in [0.02, 0.62] rad, offset along the lower rod in [-2, 2], gap in [1, 3]
// d_hat, f in [100, 500], torques uniform in +-f/2): 350 of 3000 draws gave the default
// solver a converged step turning a rod by more than 0.3 rad; these two are among the clearest
// (the second case of this file's first version, theta 0.251, converges at a near root since
// the working-set LCP starts from BBPGD).
// These far roots are those of the model at Q* (the default solver's in formed and
// matrix-free modes): the tests pin them with DefectCorrectionOptions::jacobian_at_iterate
// off. With the Jacobian at the iterate (blocks mode's default) the default solver converges
// at the near root of the second case itself, and the guard still refuses the first.
#include <gtest/gtest.h>

#include <array>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/mobility/free_draining.hpp"

namespace crossing_rods_tests {

namespace sc = stokescontact;

namespace {

const sc::Spherocylinder kRod{4.0, 0.5};
constexpr double kDt = 0.01;
constexpr double kDHat = 0.01;

struct Crossing {
  double theta;  // angle between the axes, radians
  double shift;  // the upper rod's centre along the lower rod's axis
  double gap;
  double push;                    // +-push across the axes
  std::array<double, 6> torques;  // of the lower, then the upper rod
};

const std::array<Crossing, 2> kCrossings{{
    {0.15862556832129365, -0.040571916508695738, 0.018759502886215411, 432.31320527038827,
     {-48.841442189236169, 45.348015336454012, 206.47794548828202, -171.54293815880769, 203.60249147153934,
      -171.75908546108772}},
    {0.087755492150681763, 1.0807844525445391, 0.024066728486121805, 188.80778361765263,
     {41.12123587137247, -43.838492127817176, 12.973027593196255, 23.794488762808164, -40.280091991139003,
      -42.228236537594341}},
}};

// The lower rod along x at the origin, the upper one turned by theta about y, above it.
std::vector<sc::Pose> poses(const Crossing& c) {
  const sc::Quat along_x(Eigen::AngleAxisd(0.5 * std::numbers::pi, sc::Vec3::UnitY()));
  return {{sc::Vec3::Zero(), along_x},
          {sc::Vec3(c.shift, 2.0 * kRod.radius + c.gap, 0.0),
           sc::Quat(Eigen::AngleAxisd(c.theta, sc::Vec3::UnitY())) * along_x}};
}

sc::VecX forces(const Crossing& c) {
  sc::VecX F = sc::VecX::Zero(12);
  F(1) = c.push;
  F(7) = -c.push;
  for (int k = 0; k < 3; ++k) {
    F(3 + k) = c.torques[static_cast<std::size_t>(k)];
    F(9 + k) = c.torques[static_cast<std::size_t>(3 + k)];
  }
  return F;
}

// One crossing's contact step: the poses, the free-draining mobility set there, U = M F.
struct CrossingStep {
  std::vector<sc::Pose> q;
  sc::FreeDrainingMobility mobility{sc::spherocylinder_mobility(kRod, 1.0), 2, 6};
  sc::VecX U;
  std::vector<sc::Spherocylinder> shapes{kRod};

  explicit CrossingStep(const Crossing& c) : q(poses(c)) {
    mobility.set_configuration(q);
    U = mobility.apply(forces(c));
  }
  sc::ContactStepProblem<sc::Spherocylinder> problem() const { return {shapes, q, U, kDt, kDHat, 0.0, 1.0, {}}; }
};

// The default solver with the model at Q* and its secants, as in formed and matrix-free mode.
sc::DefectCorrectionOptions model_at_trial() {
  sc::DefectCorrectionOptions o;
  o.jacobian_at_iterate = false;
  return o;
}

sc::DefectCorrectionOptions model_at_trial_without_fallback() {
  sc::DefectCorrectionOptions o = model_at_trial();
  o.far_root_fallback = false;
  o.lcp_sequence_fallback = false;
  return o;
}

}  // namespace

// The far root is found, and reported as failed separation naming the option; the same step
// with the guard lifted is the old "converged" answer, which the test shows is a far root.
TEST(CrossingRods, FarRootIsNotReportedConverged) {
  const sc::DefectCorrectionOptions without_fallback = model_at_trial_without_fallback();
  for (const Crossing& c : kCrossings) {
    SCOPED_TRACE("theta " + std::to_string(c.theta));
    CrossingStep setup(c);
    sc::FreeDrainingMobility& mobility = setup.mobility;
    const auto problem = setup.problem();

    for (const sc::ContactSolver& solver : {sc::ContactSolver{without_fallback}, sc::contact_solver_from_name("lcp-newton")}) {
      SCOPED_TRACE(sc::contact_solver_name(solver));
      const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, {}, solver);
      EXPECT_EQ(r.status, sc::ContactStepStatus::failed_separation) << r.message;
      EXPECT_GT(r.max_correction_turn, 1.0);
      EXPECT_GT(r.lambda_max, 5.0 * c.push);
      EXPECT_NE(r.message.find("ContactStepOptions.max_correction_turn"), std::string::npos) << r.message;
      EXPECT_TRUE(r.fallback.empty()) << r.fallback;
    }

    // Without the guard the default solver calls it converged: every end gap holds, but the
    // pair ends more than 10 d_hat apart, pushed by 7-10x the force that pressed it.
    sc::ContactStepOptions unguarded;
    unguarded.max_correction_turn = 1e9;
    const sc::ContactStepResult far = sc::solve_contact_step(problem, mobility, unguarded, sc::ContactSolver{model_at_trial()});
    EXPECT_EQ(far.status, sc::ContactStepStatus::converged) << far.message;
    EXPECT_GT(far.min_distance_ratio, 10.0);
    EXPECT_GT(far.max_correction_turn, 1.0);
    EXPECT_TRUE(far.fallback.empty()) << far.fallback;
  }
}

#if STOKESCONTACT_HAS_NLOPT
// eq. 15 on the working set finds the near root (a turn of 0.19-0.28 rad, lambda 1.5-2.1 f), and
// the default solver falls back to it: the same answer, at the cost of both solves.
TEST(CrossingRods, DefaultSolverFallsBackToTheNearRoot) {
  for (const Crossing& c : kCrossings) {
    SCOPED_TRACE("theta " + std::to_string(c.theta));
    CrossingStep setup(c);
    sc::FreeDrainingMobility& mobility = setup.mobility;
    const auto problem = setup.problem();

    const sc::ContactStepResult near =
        sc::solve_contact_step(problem, mobility, {}, sc::contact_solver_from_name("barrier-working-set"));
    EXPECT_EQ(near.status, sc::ContactStepStatus::converged) << near.message;
    EXPECT_LT(near.max_correction_turn, 0.5);
    EXPECT_LT(near.lambda_max, 3.0 * c.push);
    EXPECT_GE(near.min_distance_ratio, 1.0 - 1e-3);

    const sc::ContactStepResult r = sc::solve_contact_step(problem, mobility, {}, sc::ContactSolver{model_at_trial()});
    EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    EXPECT_EQ(r.fallback, "barrier-working-set");
    EXPECT_NE(r.message.find("barrier-working-set"), std::string::npos) << r.message;
    EXPECT_EQ(r.lambda, near.lambda);
    EXPECT_GE(r.iterations, near.iterations + 1);
    EXPECT_LT(r.max_correction_turn, 0.5);
    // The wall time and its phases count both solves.
    EXPECT_NEAR(r.phase_times.total(), r.wall_time_s, 1e-12);

    // In time: one contact step, no sub-step, and the diagnostics count the fallback.
    sc::TimeStepperOptions o;
    o.dt = kDt;
    o.d_hat = kDHat;
    sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility> stepper({kRod}, setup.q, mobility,
                                                                        sc::ContactSolver{model_at_trial()}, o);
    stepper.set_external_forces(forces(c));
    const sc::StepDiagnostics d = stepper.step();
    EXPECT_EQ(d.status, sc::ContactStepStatus::converged) << d.message;
    EXPECT_EQ(d.substeps, 1u);
    EXPECT_EQ(d.fallbacks, 1u);
  }
}

// The far-root fallback is dense (SLSQP): it runs only on steps of at most
// far_root_fallback_max_pairs flagged pairs. Below the step's pair count it is not tried, and
// the step goes to the LCP sequence alone.
TEST(CrossingRods, FarRootFallbackSkipsStepsWithMorePairsThanItsBound) {
  const Crossing& c = kCrossings[0];
  CrossingStep setup(c);
  const auto problem = setup.problem();
  sc::DefectCorrectionOptions bounded = model_at_trial();
  const sc::ContactStepResult first = sc::solve_contact_step(problem, setup.mobility, {}, bounded);
  ASSERT_EQ(first.fallback, "barrier-working-set");
  bounded.far_root_fallback_max_pairs = first.flagged_pairs - 1;
  const sc::ContactStepResult r = sc::solve_contact_step(problem, setup.mobility, {}, bounded);
  EXPECT_NE(r.fallback, "barrier-working-set");
  EXPECT_EQ(r.message.find("barrier-working-set"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("lcp-newton"), std::string::npos) << r.message;
}

// With the Jacobian at the iterate (the default in blocks mode) the default solver converges
// at the second case's near root by itself, no fallback: the barrier's answer within the
// solvers' tolerances. The first case's iterates still head for a far root: the guard refuses
// it and the fallback gives the near root, as above.
TEST(CrossingRods, JacobianAtTheIterateConvergesAtTheNearRoot) {
  for (std::size_t k = 0; k < kCrossings.size(); ++k) {
    const Crossing& c = kCrossings[k];
    SCOPED_TRACE("theta " + std::to_string(c.theta));
    CrossingStep setup(c);
    const auto problem = setup.problem();
    const sc::ContactStepResult near =
        sc::solve_contact_step(problem, setup.mobility, {}, sc::contact_solver_from_name("barrier-working-set"));
    const sc::ContactStepResult r = sc::solve_contact_step(problem, setup.mobility);
    EXPECT_EQ(r.status, sc::ContactStepStatus::converged) << r.message;
    EXPECT_LT(r.max_correction_turn, 0.5);
    EXPECT_GE(r.min_distance_ratio, 1.0 - 1e-3);
    EXPECT_LT(r.lambda_max, 3.0 * c.push);
    ASSERT_EQ(r.lambda.size(), near.lambda.size());
    EXPECT_LE((r.lambda - near.lambda).lpNorm<Eigen::Infinity>(), 1e-3 * near.lambda_max);
    EXPECT_EQ(r.fallback, k == 1 ? "" : "barrier-working-set") << r.message;
  }
}
#endif

// The time stepper sub-steps the refused step (two halves each) and commits it: every turn
// within the bound, every gap at d_hat.
TEST(CrossingRods, StepperSubStepsTheRefusedStep) {
  for (const Crossing& c : kCrossings) {
    SCOPED_TRACE("theta " + std::to_string(c.theta));
    sc::FreeDrainingMobility mobility(sc::spherocylinder_mobility(kRod, 1.0), 2, 6);
    sc::TimeStepperOptions o;
    o.dt = kDt;
    o.d_hat = kDHat;
    const sc::DefectCorrectionOptions without_fallback = model_at_trial_without_fallback();
    sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility> stepper({kRod}, poses(c), mobility,
                                                                        sc::ContactSolver{without_fallback}, o);
    stepper.set_external_forces(forces(c));
    const sc::StepDiagnostics d = stepper.step();
    EXPECT_EQ(d.status, sc::ContactStepStatus::converged) << d.message;
    EXPECT_GE(d.substeps, 2u);
    EXPECT_LE(d.max_correction_turn, o.contact_step.max_correction_turn);
    EXPECT_GE(d.min_distance_ratio, 1.0 - 1e-3);
  }
}

TEST(CrossingRods, NonPositiveTurnBoundIsRejected) {
  for (const double bad : {0.0, -0.1}) {
    sc::ContactStepOptions o;
    o.max_correction_turn = bad;
    try {
      o.validate();
      ADD_FAILURE() << "accepted max_correction_turn = " << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("ContactStepOptions.max_correction_turn"), std::string::npos) << e.what();
    }
  }
}

}  // namespace crossing_rods_tests
