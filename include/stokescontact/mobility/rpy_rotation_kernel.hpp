#pragma once
// Rotational couplings of the Rotne-Prager-Yamakawa tensor between two equal spheres of
// radius a, overlapping branches included (Wajnryb, Mizerski, Zuk & Szymczak, J. Fluid Mech.
// 731, R3, 2013; the translation block is rpy_kernel.hpp). With r = x_i - x_j, r_hat = r/|r|
// and t = |r| / a:
//   rotation-translation, omega_i from f_j (and, equally, u_i from tau_j):
//     M_rt f = mu_rt w(t) f x r_hat,            mu_rt = 1 / (8 pi eta a^2)
//     t >  2: w = 1 / t^2                       [the point force's vorticity: (1/2) curl u]
//     t <= 2: w = t / 2 - 3 t^2 / 16
//   rotation-rotation, omega_i from tau_j:
//     M_rr = mu_r [f_r I + g_r r_hat r_hat^T],  mu_r = 1 / (8 pi eta a^3)
//     t >  2: f_r = -1 / (2 t^3), g_r = 3 / (2 t^3)   [1/(16 pi eta r^3) (3 r_hat r_hat - I)]
//     t <= 2: f_r = 1 - 27 t / 32 + 5 t^3 / 64, g_r = 9 t / 32 - 3 t^3 / 64
// Values and first derivatives of both branches agree at t = 2; t = 0 gives the self
// mobilities M_rt = 0, M_rr = mu_r I. The pair block of the 6N x 6N matrix is
// [[M_tt, M_rt], [M_rt, M_rr]](r): M_rt is antisymmetric, so block (j, i) = block (i, j)^T.
#include <numbers>

#include "stokescontact/core/types.hpp"

namespace stokescontact {

struct RpyRotationCoefficients {
  double w = 0.0;    // rotation-translation, units mu_rt
  double f_r = 1.0;  // rotation-rotation I part, units mu_r
  double g_r = 0.0;  // rotation-rotation r_hat r_hat part, units mu_r
};

inline RpyRotationCoefficients rpy_rotation_coefficients(double r, double a) {
  const double t = r / a;
  if (t > 2.0) {
    const double t3 = t * t * t;
    return {1.0 / (t * t), -0.5 / t3, 1.5 / t3};
  }
  const double t3 = t * t * t;
  return {t / 2.0 - 3.0 / 16.0 * t * t, 1.0 - 27.0 / 32.0 * t + 5.0 / 64.0 * t3, 9.0 / 32.0 * t - 3.0 / 64.0 * t3};
}

// 1 / (8 pi eta a^2) and 1 / (8 pi eta a^3): the units of the two couplings.
inline double rotation_translation_mobility(double a, double eta) {
  return 1.0 / (8.0 * std::numbers::pi * eta * a * a);
}
inline double rotation_mobility(double a, double eta) { return 1.0 / (8.0 * std::numbers::pi * eta * a * a * a); }

// [v]_x, the matrix of v x (.).
inline Mat3 cross_matrix(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// omega_i = M f_j, r = x_i - x_j (also u_i = M tau_j).
inline Mat3 rpy_rotation_translation(const Vec3& r, double a, double eta) {
  const double d = r.norm();
  if (d == 0.0) return Mat3::Zero();
  // f x r_hat = -[r_hat]_x f.
  return -rotation_translation_mobility(a, eta) * rpy_rotation_coefficients(d, a).w * cross_matrix(r / d);
}

// omega_i = M tau_j, r = x_i - x_j.
inline Mat3 rpy_rotation_rotation(const Vec3& r, double a, double eta) {
  const double d = r.norm();
  const RpyRotationCoefficients c = rpy_rotation_coefficients(d, a);
  Mat3 m = c.f_r * Mat3::Identity();
  if (d > 0.0) m += (c.g_r / (d * d)) * r * r.transpose();
  return rotation_mobility(a, eta) * m;
}

}  // namespace stokescontact
