// LcpSequenceOptions::forcing (lcp_sequence.hpp): inexact LCPs from the second of a round on.
// The stopping rule it gives each LCP, and on dense Brownian rods (several LCPs per step): the
// same guarantee as every LCP solved to 1e-8, for fewer applications of A, and nearby poses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/contact/solvers/lcp_sequence.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/scenes/periodic_placement.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace lcp_sequence_forcing_tests {

namespace sc = stokescontact;

namespace {

TEST(LcpSequenceForcing, LoosensOnlyLaterLcpsOfARoundAndNeverPastTheCap) {
  sc::LcpSequenceOptions o;  // forcing 0.01, lcp.tolerance 1e-8
  const sc::VecX b = sc::VecX::Constant(3, -0.5);  // ||b||_inf = 0.5
  EXPECT_EQ(sc::detail::inexact_lcp_options(o, 1, 0.1, b).tolerance, 1e-8);  // the first LCP: exact
  EXPECT_DOUBLE_EQ(sc::detail::inexact_lcp_options(o, 2, 0.1, b).tolerance, 0.01 * 0.1 / 0.5);
  EXPECT_EQ(sc::detail::inexact_lcp_options(o, 2, 1e-9, b).tolerance, 1e-8);    // never below lcp.tolerance
  EXPECT_EQ(sc::detail::inexact_lcp_options(o, 2, -0.01, b).tolerance, 1e-8);   // separated: exact
  EXPECT_EQ(sc::detail::inexact_lcp_options(o, 2, 1e3, b).tolerance, sc::LcpSequenceOptions::kForcingCap);
  EXPECT_EQ(sc::detail::inexact_lcp_options(o, 2, 0.1, sc::VecX::Zero(3)).tolerance, 1e-8);
  sc::LcpSequenceOptions polish = o;
  polish.tol = 1e-6;  // aiming at complementarity: every LCP exact
  EXPECT_EQ(sc::detail::inexact_lcp_options(polish, 5, 0.1, b).tolerance, 1e-8);
  sc::LcpSequenceOptions off = o;
  off.forcing = 0.0;
  EXPECT_EQ(sc::detail::inexact_lcp_options(off, 5, 0.1, b).tolerance, 1e-8);
  for (const double bad : {-0.1, 1.0}) {
    sc::LcpSequenceOptions wrong;
    wrong.forcing = bad;
    test_support::expect_rejects([&] { wrong.validate(); }, "LcpSequenceOptions.forcing");
  }
}

// 300 Brownian rods L / D = 5 from the aligned start at hard-core packing 0.40 (the
// isotropic-nematic runs of brownian_rods, docs/results.md), dt D_R = 5e-4, margin 0.3: each
// step takes several LCPs (the rods turn, the linear model is re-measured). Forcing 0.01
// against every LCP to 1e-8, same start and noise: every step converged and separated
// either way, fewer applications of A in all, and the rods end close.
TEST(LcpSequenceForcing, DenseBrownianRodsKeepTheGuaranteeForFewerApplications) {
  const sc::Spherocylinder rod{5.0, 0.5};
  constexpr std::size_t kRods = 300;
  const double side = 14.94;  // 300 rods of volume 4.45 (diameter 1): packing 0.40
  const std::vector<sc::Pose> start = sc::periodic_aligned_columns(rod, kRods, side, 0.01, 2);
  const sc::Mat6 body = sc::spherocylinder_mobility(rod, 1.0);
  sc::TimeStepperOptions options;
  options.dt = 5e-4 / body(3, 3);  // dt D_R = 5e-4, D_R = kT / zeta_r
  options.d_hat = 0.01;
  options.box = sc::PeriodicBox{sc::Vec3::Constant(side)};
  options.brownian.emplace();
  options.brownian->kT = 1.0;
  options.contact_step.cost = sc::MobilityCost::matrix_free;  // every product with A counted
  options.contact_step.separation_margin = 0.3;
  options.contact_step.directions = sc::ContactDirections::overlap_ends;
  options.contact_step.overlap_ends_angle = 0.3;
  struct Run {
    int lcps = 0;
    std::size_t applications = 0;
    std::vector<sc::Pose> poses;
  };
  std::vector<Run> runs;
  for (const double forcing : {0.0, 0.01}) {
    SCOPED_TRACE("forcing " + std::to_string(forcing));
    sc::LcpSequenceOptions sequence;
    sequence.inner = sc::InnerLcpSolver::apgd;
    sequence.forcing = forcing;
    sc::FreeDrainingMobility mobility(body, kRods, 6);
    sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility> stepper({rod}, start, mobility, sequence, options);
    Run run;
    for (int k = 0; k < 6; ++k) {
      const sc::StepDiagnostics d = stepper.step();
      ASSERT_EQ(d.status, sc::ContactStepStatus::converged) << d.message;
      EXPECT_GE(d.min_distance_ratio, 0.7);
      run.lcps += d.iterations;
      run.applications += d.mobility_applications;
    }
    EXPECT_GE(run.lcps, 3 * 6);  // several LCPs per step: the forcing has LCPs to loosen
    run.poses = stepper.poses();
    runs.push_back(std::move(run));
  }
  EXPECT_LT(runs[1].applications, runs[0].applications);
  double moved_apart = 0.0;
  for (std::size_t i = 0; i < kRods; ++i) moved_apart = std::max(moved_apart, (runs[1].poses[i].x - runs[0].poses[i].x).norm());
  EXPECT_LT(moved_apart, 1e-3);
  std::printf("6 steps: %d LCPs, %zu applications with every LCP to 1e-8; %d LCPs, %zu with forcing 0.01; "
              "centres at most %.2e apart\n",
              runs[0].lcps, runs[0].applications, runs[1].lcps, runs[1].applications, moved_apart);
}

}  // namespace

}  // namespace lcp_sequence_forcing_tests
