#pragma once
// Collision stress of rigid bodies of any shape (Yan, Zhang & Shelley 2019, Sec. II and IV).
//
// Symbols, paper -> code. Everything is in the world frame, per unit time (the paper's
// impulse J = F_C dt, and sigma^12 = (s^1 + s^2) / dt, eq. 9, so dt drops out):
//   r_M             CollisionBody::centre: the body's centre of mass, Pose::x (every shape's
//                   body origin is its centre of mass, geometry/mass_tensors.hpp, eq. 5)
//   N, G_M          CollisionBody::mass: R N R^T and R G_M R^T, R = pose.rotation(), the
//                   body-frame tensors of geometry/mass_tensors.hpp (eq. 4, 6) rotated
//   Q = G_M^-1      applied as a solve with R G_M R^T (eq. 7)
//   x_C             point - centre: the lever arm of the force (world frame, not the body frame)
//   J / dt          the force on that body; a pair's bodies get +F and -F (eq. 10: J = M dU)
//   Delta Omega/dt  omega = Q (x_C x F) (eq. 11)
//   s / dt          body_collision_stress = r_M F^T + s^G/dt (eq. 12, 14)
//   s^G / dt        geometric_stress: s^G_ij = eps_jkl N_il omega_k, i.e. N [omega]_x^T
//                   (eq. 13, 15; [a]_x b = a x b), the integral of rho x (omega x x)^T dV
//   sigma^12        collision_stress: the sum of both bodies' s / dt (eq. 9, 16)
// Sign convention. The paper's F_C (eq. 16) is the force on particle 2, pointing from 1 to 2
// for a repulsion; its first term (r^2_M - r^1_M) F_C^T is positive on the diagonal for a
// push, i.e. sigma is compressive-positive (a pressure, not the Cauchy stress). Here the
// force is given as the force F_1 on body 1 (body 2 gets -F_1), so the virial term is
//     (r^1_M - r^2_M) F_1^T   (= (r^2_M - r^1_M) F_C^T with F_C = -F_1).
// Departure from the printed eq. 16: each body's geometric term carries the force that body
// receives (eq. 13-15 applied to body 1 with J = -F_C dt), so body 1's term has the opposite
// sign of body 2's; eq. 16 prints both with +F_C. Only this sign gives the thin-rod result
// eq. 23 ((r^2 + x^2_C - r^1 - x^1_C) F_C^T) and a symmetric stress for a force along the
// line through its two points of action (Sec. IV: "exactly symmetric"): the antisymmetric
// part of sigma has the axial vector (p_1 - p_2) x F_1, p_b the world points of action
// (eps_mij s^G_ij = G_M omega = x_C x F for each body). For two equal spheres with a
// frictional force at the contact point this gives the symmetric part of eq. 20's virial
// term, not eq. 20 itself.
// Trace (eq. 17-18): tr s^G = eps_jkl N_jl omega_k = 0 (N symmetric), so the pressure
// tr(sigma) / 3 is the virial term's, (r^1_M - r^2_M) . F_1 / 3, whatever the shapes.
// Homogeneous density rho: N and G_M both scale with rho, omega with 1/rho, so s^G and sigma
// do not depend on it (after eq. 16); `density` is accepted to say so and is checked > 0.
//
// The contact step's collisions (contact/contact_step.hpp). Its lambda is a force magnitude
// (Q(lambda) = Q_t + dt Psi (U + M D lambda), so M D lambda is a velocity and D lambda a force
// and torque per body), the force Yan's stress takes. Each pair k acts through column k of D
// (ContactStepResult::columns, built at the trial configuration Q* = Q_t + dt Psi U, not at
// Q_t): body i gets force -lambda_k f_k and torque lambda_k tau_i, body j (its image, centre
// x_j + image_shift) force +lambda_k f_k and torque lambda_k tau_j. The geometric term needs
// only each body's torque about its centre (omega = Q tau), so a column is enough, whether it
// holds one point pair (d^P, a carried contact, a line contact) or the weighted sum over many
// surface-node pairs (d^S): eq. 16 is linear in the forces (after eq. 16), and summing it over
// a column's node pairs with their weights is the column's stress. With 3 dofs per body
// (spheres) D carries no torques and neither does the stress. contact_step_stress recomputes
// Q* from the problem exactly as the contact step does (advance_all of Q_t with U over dt).
//
// System stress (Sec. IV, eq. 51-52), for N bodies in a box of volume V at temperature kT:
//     Sigma = n kT I + (1 / V) sum_collisions sigma^col,   n = N / V,
//     Pi = tr(Sigma) / 3,   Z = Pi / (n kT) = 1 + sum tr(sigma^col) / (3 N kT).
// Eq. 51 prints 1/N in front of the sum, which has units of energy against n kT I's energy
// per volume; the virial theorem (P V = N kT + (1/3) sum r . F) fixes it as 1/V. Eq. 52's
// Pi^col = sum tr(sigma^col) / (3N) is then a per-body collision pressure (an energy):
// collision_pressure_per_body, with Z = 1 + Pi^col / kT.
// A time average over steps of length dt weights each contact sub-step of length h by h / dt
// (TimeStepper::add_contact_observer reports every sub-step with its problem.dt = h).
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "stokescontact/contact/contact_matrix.hpp"
#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/core/rigid_motion.hpp"
#include "stokescontact/geometry/mass_tensors.hpp"

namespace stokescontact {

// A body as the collision stress sees it: centre of mass and world-frame mass tensors.
struct CollisionBody {
  Vec3 centre = Vec3::Zero();  // r_M
  MassTensors mass;            // R N R^T, R G_M R^T
};

// Body-frame mass tensors rotated to the world frame: R N R^T, R G_M R^T.
inline MassTensors world_mass_tensors(const MassTensors& body, const Pose& pose) {
  validate(pose);
  const Mat3 R = pose.rotation();
  return {R * body.N * R.transpose(), R * body.G_M * R.transpose()};
}

template <Shape S>
CollisionBody collision_body(const S& shape, const Pose& pose, double density = 1.0) {
  return {pose.x, world_mass_tensors(mass_tensors(shape, density), pose)};
}

// Eq. 13, 15 per unit time: s^G / dt = N [Q tau]_x^T, tau = x_C x F the torque about the
// centre of mass, Q = G_M^-1 (eq. 7, 11). Traceless (eq. 17).
inline Mat3 geometric_stress(const MassTensors& world, const Vec3& torque) {
  const Vec3 omega = world.G_M.llt().solve(torque);  // G_M symmetric positive definite
  Mat3 omega_cross;
  omega_cross << 0.0, -omega.z(), omega.y(), omega.z(), 0.0, -omega.x(), -omega.y(), omega.x(), 0.0;
  return world.N * omega_cross.transpose();
}

// Eq. 12, 14 per unit time: one body's s / dt = r_M F^T + s^G / dt, for the force F on it and
// its torque tau about the centre of mass.
inline Mat3 body_collision_stress(const CollisionBody& body, const Vec3& force, const Vec3& torque) {
  return body.centre * force.transpose() + geometric_stress(body.mass, torque);
}

// The virial term of eq. 16 (and eq. 19): (r^1_M - r^2_M) F_1^T, F_1 the force on body 1.
inline Mat3 virial_stress(const Vec3& centre1, const Vec3& centre2, const Vec3& force1) {
  return (centre1 - centre2) * force1.transpose();
}

// Eq. 16: force F_1 on body 1 at world point p_1, -F_1 on body 2 at world point p_2.
inline Mat3 collision_stress(const CollisionBody& body1, const Vec3& point1, const CollisionBody& body2,
                             const Vec3& point2, const Vec3& force1) {
  require_finite(point1, "point1");
  require_finite(point2, "point2");
  require_finite(force1, "force1");
  return body_collision_stress(body1, force1, (point1 - body1.centre).cross(force1)) +
         body_collision_stress(body2, -force1, (point2 - body2.centre).cross(Vec3(-force1)));
}

// Eq. 16 from shapes and poses; `density` is the homogeneous density of both bodies.
template <Shape S1, Shape S2>
Mat3 collision_stress(const S1& shape1, const Pose& pose1, const Vec3& point1, const S2& shape2, const Pose& pose2,
                      const Vec3& point2, const Vec3& force1, double density = 1.0) {
  return collision_stress(collision_body(shape1, pose1, density), point1, collision_body(shape2, pose2, density),
                          point2, force1);
}

// Eq. 17-18: the collision pressure tr(sigma) / 3 (the virial term's: s^G is traceless).
inline double collision_pressure(const Mat3& sigma) { return sigma.trace() / 3.0; }

namespace detail {

// World-frame collision bodies of a configuration; one mass-tensor evaluation for a shared shape.
template <Shape S>
std::vector<CollisionBody> collision_bodies(std::span<const S> shapes, std::span<const Pose> poses, double density) {
  validate_scene(shapes, poses);
  require_positive(density, "density");
  std::vector<CollisionBody> bodies;
  bodies.reserve(poses.size());
  std::vector<MassTensors> body_frame;
  for (const S& s : shapes) body_frame.push_back(mass_tensors(s, density));
  for (std::size_t k = 0; k < poses.size(); ++k)
    bodies.push_back({poses[k].x, world_mass_tensors(body_frame.size() == 1 ? body_frame[0] : body_frame[k], poses[k])});
  return bodies;
}

}  // namespace detail

// Eq. 16 for every contact of a contact step: pair k's stress from lambda_k and column k of D
// (see the top of this file). `poses`: the configuration D was built at (Q*); `pairs` give
// each column's image shift; dofs_per_body 3 drops the torques as D does.
template <Shape S>
std::vector<Mat3> contact_pair_stresses(std::span<const S> shapes, std::span<const Pose> poses,
                                        std::span<const ContactColumn> columns, std::span<const ContactPair> pairs,
                                        const VecX& lambda, int dofs_per_body, double density = 1.0) {
  if (dofs_per_body != 3 && dofs_per_body != 6)
    fail_argument("dofs_per_body", "must be 3 or 6, got " + std::to_string(dofs_per_body));
  if (columns.size() != pairs.size())
    fail_argument("columns", "has " + std::to_string(columns.size()) + " columns for " +
                                 std::to_string(pairs.size()) + " pairs");
  require_finite(lambda, static_cast<Eigen::Index>(columns.size()), "lambda");
  const std::vector<CollisionBody> bodies = detail::collision_bodies(shapes, poses, density);
  std::vector<Mat3> out;
  out.reserve(columns.size());
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const ContactColumn& c = columns[k];
    const std::string field = "columns[" + std::to_string(k) + "]";
    detail::require_pair_indices(c.i, c.j, poses.size(), field);
    if (c.i != pairs[k].i || c.j != pairs[k].j)
      fail_argument(field, "joins bodies (" + std::to_string(c.i) + ", " + std::to_string(c.j) +
                               "), its pair (" + std::to_string(pairs[k].i) + ", " + std::to_string(pairs[k].j) + ")");
    const double l = lambda(static_cast<Eigen::Index>(k));
    if (l == 0.0) {
      out.push_back(Mat3::Zero());
      continue;
    }
    CollisionBody body_j = bodies[static_cast<std::size_t>(c.j)];
    body_j.centre += pairs[k].image_shift;  // the image the column's lever arms are taken from
    const CollisionBody& body_i = bodies[static_cast<std::size_t>(c.i)];
    const Vec3 force_j = l * c.force_j;
    const Vec3 torque_i = dofs_per_body == 6 ? Vec3(l * c.torque_i) : Vec3::Zero();
    const Vec3 torque_j = dofs_per_body == 6 ? Vec3(l * c.torque_j) : Vec3::Zero();
    out.push_back(body_collision_stress(body_i, -force_j, torque_i) + body_collision_stress(body_j, force_j, torque_j));
  }
  return out;
}

namespace detail {

// Q*, the dofs and checks shared by the contact-step overloads.
template <Shape S>
std::vector<Pose> contact_step_trial(const ContactStepProblem<S>& problem, const ContactStepResult& result,
                                     int& dofs) {
  const auto n = problem.poses.size();
  if (n == 0 || problem.U.size() % static_cast<Eigen::Index>(n) != 0)
    fail_argument("problem.U", "has size " + std::to_string(problem.U.size()) + " for " + std::to_string(n) +
                                   " bodies");
  dofs = static_cast<int>(problem.U.size() / static_cast<Eigen::Index>(n));
  if (static_cast<Eigen::Index>(result.columns.size()) != result.lambda.size())
    fail_argument("result.columns", "has " + std::to_string(result.columns.size()) + " columns for " +
                                        std::to_string(result.lambda.size()) +
                                        " contact magnitudes (a result not from run_contact_step?)");
  return advance_all(problem.poses, problem.U, dofs, problem.dt);  // Q*, as ContactStep builds it
}

}  // namespace detail

// Per-pair stresses of one contact step (eq. 16), from its problem and result.
template <Shape S>
std::vector<Mat3> contact_step_pair_stresses(const ContactStepProblem<S>& problem, const ContactStepResult& result,
                                             double density = 1.0) {
  int dofs = 6;
  const std::vector<Pose> trial = detail::contact_step_trial(problem, result, dofs);
  return contact_pair_stresses(problem.shapes, std::span<const Pose>(trial), std::span<const ContactColumn>(result.columns),
                               std::span<const ContactPair>(result.pairs), result.lambda, dofs, density);
}

// Their sum: the collision stress of one contact step, sum over its pairs of eq. 16.
template <Shape S>
Mat3 contact_step_stress(const ContactStepProblem<S>& problem, const ContactStepResult& result,
                         double density = 1.0) {
  Mat3 sum = Mat3::Zero();
  for (const Mat3& s : contact_step_pair_stresses(problem, result, density)) sum += s;
  return sum;
}

// Eq. 51 (normalised per volume, see the top of this file): Sigma = n kT I + sum / V.
inline Mat3 system_stress(const Mat3& collision_stress_sum, std::size_t bodies, double volume, double kT) {
  require_finite(collision_stress_sum, "collision_stress_sum");
  require_positive(volume, "volume");
  require_non_negative(kT, "kT");
  if (bodies == 0) fail_argument("bodies", "must be >= 1");
  const double n = static_cast<double>(bodies) / volume;
  return n * kT * Mat3::Identity() + collision_stress_sum / volume;
}

// Eq. 52: Pi = tr(Sigma) / 3.
inline double system_pressure(const Mat3& sigma) { return sigma.trace() / 3.0; }

// Eq. 52: Pi^col = sum tr(sigma^col) / (3N), the paper's per-body collision pressure.
inline double collision_pressure_per_body(const Mat3& collision_stress_sum, std::size_t bodies) {
  if (bodies == 0) fail_argument("bodies", "must be >= 1");
  return collision_stress_sum.trace() / (3.0 * static_cast<double>(bodies));
}

// Z = Pi / (n kT), the compressibility factor (1 for an ideal gas).
inline double compressibility_factor(double pressure, double number_density, double kT) {
  require_finite(pressure, "pressure");
  require_positive(number_density, "number_density");
  require_positive(kT, "kT");
  return pressure / (number_density * kT);
}

}  // namespace stokescontact
