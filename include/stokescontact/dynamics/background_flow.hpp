#pragma once
// A linear background flow u(x) = E x and the rigid-body velocities it gives, the U_bg of
// Broms & Tornberg eq. 3 (their eq. 32 for biaxial compression).
//
// A body is advected by the flow at its centre, u_b = E x_b, and (6 dofs) spins with the
// local fluid rotation, omega_b = (1/2) curl u = (1/2) (E_32 - E_23, E_13 - E_31, E_21 - E_12).
// Not modelled: the coupling of the strain rate (the symmetric part of E) to the rotation of
// elongated bodies (Jeffery orbits) and the stresslet a rigid body exerts back on the flow; a
// rod here is advected and turns with the vorticity only, as a sphere would. Eq. 32 gives the
// rods no angular velocity at all, which agrees: biaxial compression has no vorticity.
//
// Layout as the mobility operators (mobility_operator.hpp): body b owns rows
// [b d, (b + 1) d), (u_b, omega_b) for d = 6, u_b alone for d = 3.
#include <cmath>
#include <cstddef>
#include <span>
#include <string>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

// Whether the constructor insists on div u = trace E = 0 (Stokes flow is incompressible).
enum class Incompressibility { required, not_required };

class LinearBackgroundFlow {
 public:
  // |trace E| <= this times the Frobenius norm of E counts as traceless.
  static constexpr double kTraceTolerance = 1e-12;

  // u(x) = E x. Throws std::invalid_argument naming "E" when E is not finite, or (the default)
  // when |trace E| > kTraceTolerance |E|.
  explicit LinearBackgroundFlow(const Mat3& E, Incompressibility incompressibility = Incompressibility::required)
      : E_(E) {
    require_finite(E.reshaped(), "E");
    if (incompressibility == Incompressibility::required && !(std::abs(E.trace()) <= kTraceTolerance * E.norm()))
      fail_argument("E", "an incompressible flow needs trace E = 0 (relative to |E| = " + std::to_string(E.norm()) +
                             "), got trace " + std::to_string(E.trace()));
  }

  // Simple shear u = rate y e_x: E_12 = rate, vorticity -rate e_z, so omega = -(rate / 2) e_z.
  static LinearBackgroundFlow shear(double rate) {
    require_finite(rate, "rate");
    Mat3 E = Mat3::Zero();
    E(0, 1) = rate;
    return LinearBackgroundFlow(E);
  }

  // Biaxial compression, Broms & Tornberg eq. 32: E = diag(rate, -rate/2, -rate/2). The flow
  // compresses along y and z and extends along x (rate > 0); traceless, no vorticity.
  static LinearBackgroundFlow biaxial_compression(double rate) {
    require_finite(rate, "rate");
    return LinearBackgroundFlow(Vec3(rate, -0.5 * rate, -0.5 * rate).asDiagonal().toDenseMatrix());
  }

  const Mat3& velocity_gradient() const { return E_; }

  // u(x) = E x.
  Vec3 velocity(const Vec3& x) const { return E_ * x; }

  // Half the vorticity, the same everywhere in a linear flow.
  Vec3 angular_velocity() const {
    return 0.5 * Vec3(E_(2, 1) - E_(1, 2), E_(0, 2) - E_(2, 0), E_(1, 0) - E_(0, 1));
  }

  bool is_zero() const { return E_.isZero(0.0); }

  // U_bg for bodies at `poses`, dofs_per_body 3 or 6 (rows as above).
  VecX body_velocities(std::span<const Pose> poses, int dofs_per_body) const {
    if (dofs_per_body != 3 && dofs_per_body != 6)
      fail_argument("dofs_per_body", "must be 3 or 6, got " + std::to_string(dofs_per_body));
    validate(poses);
    VecX U(static_cast<Eigen::Index>(poses.size()) * dofs_per_body);
    const Vec3 omega = angular_velocity();
    for (std::size_t b = 0; b < poses.size(); ++b) {
      const Eigen::Index row = static_cast<Eigen::Index>(b) * dofs_per_body;
      U.segment<3>(row) = velocity(poses[b].x);
      if (dofs_per_body == 6) U.segment<3>(row + 3) = omega;
    }
    return U;
  }

 private:
  Mat3 E_;
};

}  // namespace stokescontact
