#pragma once
// Forward Euler with contact correction (Broms & Tornberg Sec. 2, 3.2.3). One step from Q_t:
//   1. U = U_bg(Q_t) + M(Q_t) F_ext(t, Q_t)             (eq. 3): one mobility application,
//      skipped when F_ext = 0; with Brownian motion (options.brownian, kT > 0) also
//      + sqrt(2 kT / dt) M^(1/2) W + kT div_q M       (Yan et al. eq. 29, U_known = U^B;
//      Delong et al. 2015; docs/brownian.md), W ~ N(0, I) fresh each step from the stream of
//      options.brownian->seed: mobility/brownian_velocity.hpp (exact square root or Lanczos)
//      and mobility/thermal_drift.hpp (exact divergence or one RFD sample), their
//      applications counted;
//   2. a contact step from Q_t with U by the chosen solver (a ContactSolver value, the default
//      solver unless told otherwise; or a custom callable): the trial step Q* = Q_t + dt Psi U
//      (eq. 16), then lambda >= 0 and Q_{t+dt} = Q_t + dt Psi (U + M D lambda)  (eq. 13);
//   3. Q_{t+dt} = the solver's poses, centres wrapped back into [0, L)^3 in a periodic box
//      (positions only: the contact code measures pairs by minimum image);
//   4. the step's StepDiagnostics and Q_{t+dt} go to every step observer (JSON lines through
//      io/diagnostics_json.hpp, trajectories, statistics: whatever the caller attaches).
// Contact observers (add_contact_observer) get each contact step's problem and result, e.g.
// for the collision stress (dynamics/collision_stress.hpp): once per committed contact
// sub-step, in time order (problem.dt is the sub-step's length, problem.poses its start),
// after the step has committed and before the step observers. Attempts that failed and were
// sub-stepped are never reported; the results are kept only while contact observers exist.
// A background flow with a periodic box is refused: u = E x is not periodic, and
// Lees-Edwards boundary conditions are not implemented.
//
// Sub-stepping: a contact step that reports failed_separation (a pair below d_hat at the end,
// or overlapping inside the step, that the solver could not hold) is retried as two steps of
// dt/2, each from its own start with its own U (steps 1-2), recursively up to
// max_substep_halvings times (2^k sub-steps of dt/2^k). The step is committed only when every
// sub-step succeeded; its diagnostics add up their work (substeps says how many).
// A Brownian interval keeps its Gaussian W when halved (a Brownian bridge): with Z ~ N(0, I)
// drawn afresh, the halves get W_1 = (W + Z) / sqrt 2 and W_2 = (W - Z) / sqrt 2, independent
// N(0, I) whose displacements sqrt(2 kT dt/2) B (W_1 + W_2) add up to the failed attempt's
// sqrt(2 kT dt) B W when B is constant. A failure therefore never redraws the noise, which
// would bias the trajectory away from the configurations where steps fail (dense contacts).
// Failures are not hidden: a step that still fails makes step() throw std::runtime_error with
// the solver's message, and the state stays at Q_t. Bad input throws std::invalid_argument
// naming the field before anything changes.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/contact/solvers/contact_solver.hpp"
#include "stokescontact/dynamics/background_flow.hpp"
#include "stokescontact/dynamics/step_diagnostics.hpp"
#include "stokescontact/mobility/brownian_velocity.hpp"
#include "stokescontact/mobility/thermal_drift.hpp"

namespace stokescontact {

// Thermal fluctuations of the bodies (see the top): temperature, the seed of the Gaussian
// stream (core/gaussian_stream.hpp: the same seed gives the same trajectory), and the
// fallbacks' settings for models without an exact square root or divergence.
struct BrownianOptions {
  double kT = 0.0;         // >= 0; 0: no fluctuations, nothing drawn
  std::uint64_t seed = 0;
  LanczosOptions lanczos;  // M^(1/2) W when the model has no apply_sqrt
  RfdOptions rfd;          // kT div_q M when the model has no divergence()

  void validate() const {
    require_non_negative(kT, "brownian.kT");
    lanczos.validate();
    rfd.validate();
  }
};

struct TimeStepperOptions {
  double dt = 0.0;                   // > 0
  double d_hat = 0.0;                // > 0
  double d_try = 0.0;                // 0: per step by d_try_rule (ContactStepProblem.d_try)
  double d_try_multiplier = 1.0;     // >= 1
  DTryRule d_try_rule = DTryRule::relative;  // when d_try = 0 (ContactStepProblem.d_try_rule)
  int max_substep_halvings = 4;      // in [0, 30]; 0: a failed step throws at once
  std::optional<PeriodicBox> box;    // none for open space
  std::optional<LinearBackgroundFlow> background_flow;  // none: fluid at rest
  std::optional<BrownianOptions> brownian;               // none: no thermal fluctuations
  ContactStepOptions contact_step;   // given to the contact solver at every step

  void validate() const {
    require_positive(dt, "dt");
    require_positive(d_hat, "d_hat");
    require_non_negative(d_try, "d_try");
    if (d_try > 0.0 && !(d_try >= d_hat))
      fail_argument("d_try", "must be 0 (eq. 30/31) or >= d_hat = " + std::to_string(d_hat) + ", got " +
                                 std::to_string(d_try));
    require_finite(d_try_multiplier, "d_try_multiplier");
    if (!(d_try_multiplier >= 1.0))
      fail_argument("d_try_multiplier", "must be >= 1, got " + std::to_string(d_try_multiplier));
    if (max_substep_halvings < 0 || max_substep_halvings > 30)
      fail_argument("max_substep_halvings", "must lie in [0, 30], got " + std::to_string(max_substep_halvings));
    if (box) {
      for (int k = 0; k < 3; ++k) require_positive(box->lengths[k], "box.lengths");
      if (background_flow && !background_flow->is_zero())
        fail_argument("background_flow",
                      "is not allowed with a periodic box (u = E x is not periodic; no Lees-Edwards conditions)");
    }
    if (brownian) brownian->validate();
    contact_step.validate();
  }
};

// External forces (and torques) per body, stacked as the mobility's rows, at time t and poses Q_t.
using ExternalForceField = std::function<VecX(double, std::span<const Pose>)>;

// Called after every committed step with its diagnostics and Q_{t+dt} (centres wrapped into
// the box); the span is valid during the call only.
using StepObserver = std::function<void(const StepDiagnostics&, std::span<const Pose>)>;

// Called for every contact sub-step of a committed step with its problem (spans valid during
// the call only) and result.
template <Shape S>
using ContactObserver = std::function<void(const ContactStepProblem<S>&, const ContactStepResult&)>;

template <Shape S, MobilityOperator M>
class TimeStepper {
 public:
  // Anything else that solves a contact step: it gets each step's problem, the mobility and
  // options.contact_step, e.g. to count or log around one of the library's solvers.
  using CustomContactSolver =
      std::function<ContactStepResult(const ContactStepProblem<S>&, M&, const ContactStepOptions&)>;

  // `shapes`: one per body or one shared; `mobility` is referenced and must outlive the
  // stepper. Q_0 must be contact free (every d^P >= 0). Centres are wrapped into the box.
  // The contact solver: the default one (defect correction with its default options) ...
  TimeStepper(std::vector<S> shapes, std::vector<Pose> poses, M& mobility, TimeStepperOptions options,
              double t0 = 0.0)
      : TimeStepper(std::move(shapes), std::move(poses), mobility, ContactSolver{}, std::move(options), t0) {}

  // ... one of the library's by value, e.g. contact_solver_from_name("lcp-newton") ...
  TimeStepper(std::vector<S> shapes, std::vector<Pose> poses, M& mobility, ContactSolver contact_solver,
              TimeStepperOptions options, double t0 = 0.0)
      : shapes_(std::move(shapes)), poses_(std::move(poses)), mobility_(mobility), solver_(std::move(contact_solver)),
        options_(std::move(options)), time_(t0), start_time_(t0), noise_(brownian_seed(options_)) {
    validate_and_wrap();
  }

  // ... or a custom callable.
  TimeStepper(std::vector<S> shapes, std::vector<Pose> poses, M& mobility, CustomContactSolver contact_solver,
              TimeStepperOptions options, double t0 = 0.0)
      : shapes_(std::move(shapes)), poses_(std::move(poses)), mobility_(mobility), solver_(std::move(contact_solver)),
        options_(std::move(options)), time_(t0), start_time_(t0), noise_(brownian_seed(options_)) {
    validate_and_wrap();
  }

  // Constant external forces: size bodies * dofs_per_body, finite. Zero by default.
  void set_external_forces(VecX forces) {
    require_finite(forces, size(), "external_forces");
    forces_ = std::move(forces);
    force_field_ = nullptr;
  }

  // Forces depending on (t, Q_t), checked at each step (size, finite) before anything changes.
  void set_external_force_field(ExternalForceField field) {
    if (!field) fail_argument("external_forces", "the force field must be callable");
    force_field_ = std::move(field);
    forces_.reset();
  }

  // Observers run after every committed step, in the order added; not after a step that
  // throws. One that throws stops run() with the step already committed.
  void add_step_observer(StepObserver observer) {
    if (!observer) fail_argument("step_observer", "must be callable");
    observers_.push_back(std::move(observer));
  }

  void clear_step_observers() { observers_.clear(); }

  // Contact observers run after every committed step, once per contact sub-step that step
  // is made of (in time order), before the step observers; in the order added.
  void add_contact_observer(ContactObserver<S> observer) {
    if (!observer) fail_argument("contact_observer", "must be callable");
    contact_observers_.push_back(std::move(observer));
  }

  void clear_contact_observers() { contact_observers_.clear(); }

  // One step; returns its diagnostics (also kept in diagnostics()). Throws std::runtime_error
  // on failed separation.
  StepDiagnostics step() {
    const auto start = std::chrono::steady_clock::now();
    std::vector<Pose> poses = poses_;
    StepDiagnostics d;
    d.substeps = 0;
    d.min_distance_ratio = std::numeric_limits<double>::infinity();
    std::string failure;
    pending_.clear();
    if (!advance_interval(poses, time_, options_.dt, 0, d, failure, draw_brownian_gaussian()))
      throw std::runtime_error("time step " + std::to_string(steps_ + 1) + " from t = " + std::to_string(time_) +
                               ": " + failure);
    // Commit Q_{t+dt}.
    poses_ = std::move(poses);
    wrap_into_box();
    ++steps_;
    time_ = t0_plus_steps();
    d.step = steps_;
    d.time = time_;
    d.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    diagnostics_.push_back(std::move(d));
    std::vector<PendingContactStep> committed = std::move(pending_);
    pending_.clear();
    for (const PendingContactStep& c : committed) {
      const ContactStepProblem<S> problem = make_problem(std::span<const Pose>(c.poses), c.U, c.dt);
      for (const ContactObserver<S>& observer : contact_observers_) observer(problem, c.result);
    }
    for (const StepObserver& observer : observers_) observer(diagnostics_.back(), std::span<const Pose>(poses_));
    return diagnostics_.back();
  }

  // `steps` steps (>= 0); stops at the first throw, the state then at the last good step.
  void run(int steps) {
    if (steps < 0) fail_argument("steps", "must be >= 0, got " + std::to_string(steps));
    for (int k = 0; k < steps; ++k) step();
  }

  // The Gaussian stream in its present state (it starts from options.brownian->seed). A
  // stepper given it by set_noise draws, from its next step on, what this one would: a run
  // continued by another stepper (another dt, a restart from io/checkpoint.hpp) goes on with
  // the same stream instead of drawing the seed's first variates again.
  const GaussianStream& noise() const { return noise_; }
  void set_noise(GaussianStream noise) { noise_ = std::move(noise); }

  const std::vector<Pose>& poses() const { return poses_; }
  const std::vector<S>& shapes() const { return shapes_; }
  double time() const { return time_; }
  long steps_taken() const { return steps_; }
  const std::vector<StepDiagnostics>& diagnostics() const { return diagnostics_; }
  const TimeStepperOptions& options() const { return options_; }
  Eigen::Index size() const { return static_cast<Eigen::Index>(poses_.size()) * dofs_; }

 private:
  // The constructors' checks, before anything else: options, t0, solver, scene, mobility.
  void validate_and_wrap() {
    options_.validate();
    require_finite(time_, "t0");
    if (const ContactSolver* solver = std::get_if<ContactSolver>(&solver_))
      std::visit([](const auto& o) { o.validate(); }, *solver);
    else if (!std::get<CustomContactSolver>(solver_))
      fail_argument("contact_solver", "must be callable");
    validate_scene(std::span<const S>(shapes_), std::span<const Pose>(poses_));
    dofs_ = mobility_.dofs_per_body();
    if (dofs_ != 3 && dofs_ != 6) fail_argument("mobility", "dofs_per_body must be 3 or 6, got " + std::to_string(dofs_));
    if (mobility_.size() != size())
      fail_argument("mobility", "has size " + std::to_string(mobility_.size()) + ", expected " +
                                    std::to_string(size()) + " (bodies * dofs_per_body)");
    if (options_.box) {  // the broad phase's condition (geometry/broad_phase.hpp) with d_try = d_hat
      double largest = 0.0;
      for (const S& s : shapes_) largest = std::max(largest, bounding_radius(s));
      const double needed = 2.0 * (2.0 * largest + options_.d_hat);
      if (!(options_.box->lengths.minCoeff() >= needed))
        fail_argument("box.lengths", "must be >= 2 (2 max bounding radius + d_hat) = " + std::to_string(needed) +
                                         ", got a side of " + std::to_string(options_.box->lengths.minCoeff()) +
                                         ": a body would meet its own image, or two images of another");
    }
    const MinimumDistance closest =
        minimum_pair_distance(std::span<const S>(shapes_), std::span<const Pose>(poses_), options_.box);
    if (closest.distance < 0.0)
      fail_argument("poses", "Q_0 must be contact free; bodies " + std::to_string(closest.i) + " and " +
                                 std::to_string(closest.j) + " overlap, d = " + std::to_string(closest.distance));
    wrap_into_box();
  }

  static std::uint64_t brownian_seed(const TimeStepperOptions& options) {
    return options.brownian ? options.brownian->seed : 0;
  }

  bool brownian() const { return options_.brownian && options_.brownian->kT > 0.0; }

  // The Gaussian W of a whole step (empty without Brownian motion).
  VecX draw_brownian_gaussian() { return brownian() ? noise_.vector(size()) : VecX(); }

  // Steps 1-2 over [t, t + h] from `poses`, advanced in place, with the interval's Gaussian W
  // (Brownian motion only); on failed separation, two halves bridged from W (see the top),
  // down to max_substep_halvings. False (with the last message) if that fails too.
  bool advance_interval(std::vector<Pose>& poses, double t, double h, int halvings, StepDiagnostics& d,
                        std::string& failure, const VecX& W) {
    const std::span<const Pose> q_t(poses);
    // Eq. 3: U = U_bg + M F_ext.
    std::optional<VecX> forces;
    if (force_field_) {
      VecX f = force_field_(t, q_t);
      require_finite(f, size(), "external_forces");
      forces = std::move(f);
    } else if (forces_) {
      forces = *forces_;
    }
    VecX U = options_.background_flow ? options_.background_flow->body_velocities(q_t, dofs_) : VecX::Zero(size());
    std::size_t applications = 0;
    if (forces && !forces->isZero(0.0)) {
      mobility_.set_configuration(q_t);
      U += mobility_.apply(*forces);
      applications = 1;
    }
    if (brownian()) {  // + sqrt(2 kT / h) M^(1/2) W + kT div_q M
      const BrownianOptions& b = *options_.brownian;
      mobility_.set_configuration(q_t);
      const MobilitySqrtProduct thermal = brownian_velocity(mobility_, b.kT, h, W, b.lanczos);
      U += thermal.value;
      applications += static_cast<std::size_t>(thermal.lanczos_iterations);
      U += thermal_drift(mobility_, q_t, b.kT, noise_, b.rfd);
      if constexpr (!ExactDivergenceMobility<M>) applications += 2;  // one centred RFD sample
    }
    // Eq. 13/16 through the chosen solver.
    const ContactStepProblem<S> problem = make_problem(q_t, U, h);
    ContactStepResult result = solve(problem);
    d.unconstrained_applications += applications;
    d.mobility_applications += applications + result.mobility_applications;
    d.iterations += result.iterations;
    if (result.status == ContactStepStatus::failed_separation) {
      failure = result.message;
      if (halvings >= options_.max_substep_halvings) return false;
      // Halves: nothing was recorded for this attempt, and each half records its own.
      VecX W1, W2;
      if (brownian()) {  // the bridge: W = (W1 + W2) / sqrt 2
        const VecX Z = noise_.vector(size());
        W1 = (W + Z) / std::sqrt(2.0);
        W2 = (W - Z) / std::sqrt(2.0);
      }
      return advance_interval(poses, t, 0.5 * h, halvings + 1, d, failure, W1) &&
             advance_interval(poses, t + 0.5 * h, 0.5 * h, halvings + 1, d, failure, W2);
    }
    if (result.poses.size() != poses.size())
      throw std::runtime_error("contact solver returned " + std::to_string(result.poses.size()) + " poses for " +
                               std::to_string(poses.size()) + " bodies");
    // Kept for the contact observers until the step commits (a sub-step of a step that fails
    // later is dropped with it: step() clears pending_ first).
    if (!contact_observers_.empty()) pending_.push_back({std::vector<Pose>(q_t.begin(), q_t.end()), U, h, result});
    poses = std::move(result.poses);
    ++d.substeps;
    d.flagged_pairs = std::max(d.flagged_pairs, result.flagged_pairs);
    std::size_t active = 0;
    for (Eigen::Index k = 0; k < result.lambda.size(); ++k) active += result.lambda(k) > 0.0 ? 1 : 0;
    d.active_pairs = std::max(d.active_pairs, active);
    d.carried_pairs = std::max(d.carried_pairs, result.carried_pairs);
    d.min_distance_ratio = std::min(d.min_distance_ratio, result.min_distance_ratio);  // minimum image in a box
    if (result.status == ContactStepStatus::not_converged || d.substeps == 1) d.status = result.status;
    if (!result.message.empty()) d.message = std::move(result.message);
    d.lambda_sum += result.lambda_sum;
    d.lambda_max = std::max(d.lambda_max, result.lambda_max);
    d.max_correction_turn = std::max(d.max_correction_turn, result.max_correction_turn);
    d.fallbacks += result.fallback.empty() ? 0 : 1;
    return true;
  }

  // The contact step of an interval of length h from q_t with velocities U.
  ContactStepProblem<S> make_problem(std::span<const Pose> q_t, const VecX& U, double h) const {
    ContactStepProblem<S> problem{std::span<const S>(shapes_), q_t, U, h, options_.d_hat,
                                  options_.d_try,              options_.d_try_multiplier, options_.box};
    problem.d_try_rule = options_.d_try_rule;
    return problem;
  }

  ContactStepResult solve(const ContactStepProblem<S>& problem) {
    if (const CustomContactSolver* custom = std::get_if<CustomContactSolver>(&solver_))
      return (*custom)(problem, mobility_, options_.contact_step);
    return solve_contact_step(problem, mobility_, options_.contact_step, std::get<ContactSolver>(solver_));
  }

  // t_n = t_0 + n dt, not a running sum: no drift over many steps.
  double t0_plus_steps() const { return start_time_ + static_cast<double>(steps_) * options_.dt; }

  void wrap_into_box() {
    if (!options_.box) return;
    for (Pose& p : poses_) p.x = stokescontact::wrap_into_box(p.x, *options_.box);
  }

  std::vector<S> shapes_;
  std::vector<Pose> poses_;
  M& mobility_;
  std::variant<ContactSolver, CustomContactSolver> solver_;
  TimeStepperOptions options_;
  double time_ = 0.0;
  double start_time_ = 0.0;
  int dofs_ = 6;
  long steps_ = 0;
  GaussianStream noise_;  // W of each step, bridges and RFD samples, in that order of use
  std::optional<VecX> forces_;
  ExternalForceField force_field_;
  std::vector<StepObserver> observers_;
  // A contact sub-step of the step in progress, for the contact observers.
  struct PendingContactStep {
    std::vector<Pose> poses;  // its Q_t
    VecX U;
    double dt = 0.0;
    ContactStepResult result;
  };
  std::vector<ContactObserver<S>> contact_observers_;
  std::vector<PendingContactStep> pending_;
  std::vector<StepDiagnostics> diagnostics_;
};

}  // namespace stokescontact
