#pragma once
// Exact mobility of two equal rigid spheres in unbounded Stokes flow (Jeffrey & Onishi,
// J. Fluid Mech. 139, 261, 1984; Kim & Karrila, Microhydrodynamics, 1991, ch. 11), by the
// twin-multipole series in u = 2a/r summed to high order. A reference to judge approximate
// models such as RPY, and a model of its own for a pair of spheres.
//
// The ten mobility functions of s = r/a, with e the unit vector from a sphere towards the
// other (Kim & Karrila's normalisation for equal spheres; 1 = self, 2 = the other sphere):
//   u_1     = 1/(6 pi eta a)   [(x11a ee + y11a (I - ee)) f_1 + (x12a ee + y12a (I - ee)) f_2]
//             + 1/(4 pi eta a^2) [-y11b tau_1 x e + y12b tau_2 x e]
//   omega_1 = 1/(4 pi eta a^2) [ y11b f_1 x e + y12b f_2 x e]
//             + 1/(8 pi eta a^3) [(x11c ee + y11c (I - ee)) tau_1 + (x12c ee + y12c (I - ee)) tau_2]
// and the same for sphere 2 with its own e. Far apart: x11a = y11a = x11c = y11c = 1, the
// rest 0; RPY agrees with all ten to O(s^-3).
//
// Method. Jeffrey & Onishi expand each sphere's disturbance in Lamb's solution (coefficients
// P, V, Q of the pressure, potential and rotlet harmonics of degree n) and reflect it off the
// other sphere; the coefficient of a1^p a2^q / r^(p+q) obeys a recurrence (their Sec. 3 for
// X^A, eq. 4.6-4.11 for Y^A and Y^B, 7.3-7.5 for Y^C; as corrected by Townsend,
// arXiv:1802.08226). For
// equal spheres only the total order k = p + q matters, which collapses the recurrence to
// P_n(k), and odd k belongs to the other sphere. The recurrences are for the resistance
// problem (velocities given); for the mobility problem the degree-1 force and torque
// coefficients of both spheres are given instead, so P_1(k) = Q_1(k) = 0 for k > 0 and the
// value the recurrence would have given them is the velocity's series coefficient (checked:
// the resulting series reproduce Kim & Karrila's far-field coefficients 15/4, 17/16, 75/4
// and published tables). X^C (rotation about the line of centres) decouples: its swirl
// u_phi = -d h / d rho is carried by axisymmetric harmonics h, reflected with the Legendre
// addition theorem (derived here, no recurrence from the papers).
//
// Convergence: the series converge for s > 2 like (2/s)^k. With kTwinMultipoleOrder = 400
// terms (about 0.2 s to build, once) the truncation error is about 1e-11 at s = 2.1 (gap 0.1a),
// 2e-7 at s = 2.05 and below 1e-16 for s >= 2.2; rounding adds about 1e-16 (checked against
// long double and 1000 terms). Closer to contact the functions need the lubrication forms
// (not done here): two_sphere_mobility_functions reports its truncation estimate and refuses
// s where it exceeds kTwinMultipoleTolerance = 1e-6 (s below about 2.04).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/mobility/rpy_rotation_kernel.hpp"

namespace stokescontact {

struct TwoSphereMobilityFunctions {
  double x11a = 1, x12a = 0, y11a = 1, y12a = 0;  // translation, units 1/(6 pi eta a)
  double y11b = 0, y12b = 0;                      // rotation-translation, units 1/(4 pi eta a^2)
  double x11c = 1, x12c = 0, y11c = 1, y12c = 0;  // rotation, units 1/(8 pi eta a^3)
  double truncation_error = 0;                    // estimated size of the neglected tail
};

inline constexpr int kTwinMultipoleOrder = 400;
inline constexpr double kTwinMultipoleTolerance = 1e-6;  // largest tail estimate returned

namespace detail {

// B(i, j) = C(i + j, i) / 2^(i + j), by Pascal's rule: the binomials of the recurrences,
// scaled with the 2^-k of the coefficients so nothing overflows.
class ScaledBinomials {
 public:
  explicit ScaledBinomials(int n) : n_(n + 1), b_(static_cast<std::size_t>(n_ * n_), 0.0) {
    for (int i = 0; i < n_; ++i)
      for (int j = 0; j < n_; ++j)
        at(i, j) = (i == 0 || j == 0) ? std::ldexp(1.0, -(i + j)) : 0.5 * (at(i - 1, j) + at(i, j - 1));
  }
  double operator()(int i, int j) const { return b_[static_cast<std::size_t>(i * n_ + j)]; }

 private:
  double& at(int i, int j) { return b_[static_cast<std::size_t>(i * n_ + j)]; }
  int n_;
  std::vector<double> b_;
};

// Coefficients c_n(k) 2^-k of the harmonics of degree n = 1..K at total order k = 0..K.
class HarmonicTable {
 public:
  explicit HarmonicTable(int order) : k_(order + 1), c_(static_cast<std::size_t>((order + 2) * k_), 0.0) {}
  double operator()(int n, int k) const { return k < 0 ? 0.0 : c_[static_cast<std::size_t>(n * k_ + k)]; }
  double& at(int n, int k) { return c_[static_cast<std::size_t>(n * k_ + k)]; }

 private:
  int k_;
  std::vector<double> c_;
};

// Jeffrey & Onishi's X^A recurrence for the force problem along the line of centres
// (P_1 = 1 at k = 0, force-free otherwise). Returns the would-be P_1(k) 2^-k: x11a = 1 -
// sum over even k, x12a = sum over odd k, of coefficient (2/s)^k.
inline std::vector<double> axisymmetric_translation_series(int K, const ScaledBinomials& B) {
  HarmonicTable P(K), V(K);
  P.at(1, 0) = V.at(1, 0) = 1.0;
  std::vector<double> velocity(static_cast<std::size_t>(K + 1), 0.0);
  for (int k = 1; k <= K; ++k)
    for (int n = 1; n <= k; ++n) {
      double p = 0.0, pv = 0.0;
      for (int s = 1; s <= k - n + 1; ++s) {
        const int j = k - s - n + 1;  // P_s(j) reflected from the other sphere; j - 2 for the rest
        const double a = n * (2.0 * n + 1) * (2.0 * n * s - n - s + 2) / (2.0 * (n + 1) * (2.0 * s - 1) * (n + s));
        const double b = n * (2.0 * n - 1) / (2.0 * (n + 1));
        const double c = n * (4.0 * n * n - 1) / (2.0 * (n + 1) * (2.0 * s + 1));
        p += B(n, s) * (2.0 * a * P(s, j) - 0.5 * b * P(s, j - 2) - 0.5 * c * V(s, j - 2));
        pv += 0.5 * B(n, s) * P(s, j - 2);
      }
      if (n == 1) {  // force given: P_1 stays 0, the velocity takes its value
        velocity[static_cast<std::size_t>(k)] = p;
        p = 0.0;
      }
      P.at(n, k) = p;
      V.at(n, k) = p - 2.0 * n / ((n + 1.0) * (2.0 * n + 3)) * pv;
    }
  return velocity;
}

// Jeffrey & Onishi's Y^A/Y^B/Y^C recurrence for the force (P_1 = 1) or torque (Q_1 = 1)
// problem across the line of centres. Returns the would-be P_1(k) and Q_1(k) times 2^-k.
struct AsymmetricSeries {
  std::vector<double> translation, rotation;
};

inline AsymmetricSeries asymmetric_series(int K, const ScaledBinomials& B, bool force) {
  HarmonicTable P(K), V(K), Q(K);
  if (force)
    P.at(1, 0) = V.at(1, 0) = 1.0;
  else
    Q.at(1, 0) = 1.0;
  AsymmetricSeries out{std::vector<double>(static_cast<std::size_t>(K + 1), 0.0),
                       std::vector<double>(static_cast<std::size_t>(K + 1), 0.0)};
  for (int k = 1; k <= K; ++k)
    for (int n = 1; n <= k; ++n) {
      double p = 0.0, q = 0.0, pv = 0.0;
      for (int s = 1; s <= k - n + 1; ++s) {
        const int j = k - s - n + 1;
        const double binomial = B(n + 1, s - 1);  // C(n + s, n + 1) 2^-(n + s)
        const double a = (2.0 * n + 1) / (2.0 * (n + 1)) * (3.0 * (n + s) - (n * s + 1.0) * (2.0 * n * s - s - n + 2)) /
                         (s * (n + s) * (2.0 * s - 1));
        const double b = n * (2.0 * n - 1) / (2.0 * (n + 1));
        const double c = n * (4.0 * n * n - 1) / (2.0 * (n + 1) * (2.0 * s + 1));
        const double d = 2.0 * (4.0 * n * n - 1) / (3.0 * (n + 1));
        p += binomial * (2.0 * a * P(s, j) + 0.5 * b * P(s, j - 2) + 0.5 * c * V(s, j - 2) - d * Q(s, j - 1));
        q += binomial * (0.5 * s / (n + 1.0) * Q(s, j - 2) - 1.5 / (n * s * (n + 1.0)) * P(s, j - 1));
        pv += 0.5 * binomial * P(s, j - 2);
      }
      if (n == 1) {  // force and torque given: the velocities take the values
        out.translation[static_cast<std::size_t>(k)] = p;
        out.rotation[static_cast<std::size_t>(k)] = q;
        p = q = 0.0;
      }
      P.at(n, k) = p;
      Q.at(n, k) = q;
      V.at(n, k) = p + 2.0 * n / ((n + 1.0) * (2.0 * n + 3)) * pv;
    }
  return out;
}

// Rotation about the line of centres, torque on sphere 1 (radius 1, sphere 2 at z = s). The
// swirl u_phi = -dh/drho of an axisymmetric harmonic h; about a sphere,
//   h = sum_m A_m r^m P_m + c_m r^(-m-1) P_m  gives  u_phi = sum_l sin(theta) P_l'(cos theta)
//   (A_(l+1) r^l + c_(l-1) r^(-l-1)),
// so a rigid rotation is l = 1 (Omega = A_2 + c_0, c_0 = torque / (8 pi eta)) and no-slip
// sets c_m = -A_(m+2) for m >= 1. The other sphere's r'^(-m-1) P_m(cos theta') is, near
// this one, sum_j (-1)^m C(m+j, m) r^j P_j / s^(m+j+1) (other sphere at +s; at -s the sign is
// (-1)^j). Returns Omega_1(k) 2^-k and Omega_2(k) 2^-k: x11c and x12c in powers of 2/s.
struct AxisymmetricRotationSeries {
  std::vector<double> self, other;
};

inline AxisymmetricRotationSeries axisymmetric_rotation_series(int K, const ScaledBinomials& B) {
  HarmonicTable c1(K), c2(K);  // c_m(k) 2^-k of spheres 1 and 2 (index m + 1)
  c1.at(1, 0) = 1.0;           // the rotlet of the torque on sphere 1
  AxisymmetricRotationSeries out{std::vector<double>(static_cast<std::size_t>(K + 1), 0.0),
                                 std::vector<double>(static_cast<std::size_t>(K + 1), 0.0)};
  out.self[0] = 1.0;
  // The regular coefficient A_j(k) of sphere `to` from the other's c: sign (-1)^m seen from
  // sphere 1 (other at +s), (-1)^j from sphere 2; C(m+j, m) 2^-(m+j+1) = B(m, j) / 2.
  auto regular = [&](const HarmonicTable& from, bool to_first, int j, int k) {
    double sum = 0.0;
    for (int m = 0; m + j + 1 <= k; ++m) {
      const int power = to_first ? m : j;
      sum += (power % 2 == 0 ? 0.5 : -0.5) * B(m, j) * from(m + 1, k - m - j - 1);
    }
    return sum;
  };
  for (int k = 1; k <= K; ++k) {
    out.self[static_cast<std::size_t>(k)] = regular(c2, true, 2, k);
    out.other[static_cast<std::size_t>(k)] = regular(c1, false, 2, k);
    for (int m = 1; m + 3 <= k; ++m) {
      c1.at(m + 1, k) = -regular(c2, true, m + 2, k);
      c2.at(m + 1, k) = -regular(c1, false, m + 2, k);
    }
  }
  return out;
}

// The coefficients of the ten functions (and of y^b from the torque problem, which
// reciprocity makes equal to y^b from the force problem) in powers of 2/s.
struct TwinMultipoleSeries {
  int order = 0;
  std::vector<double> x11a, x12a, y11a, y12a, y11b, y12b, x11c, x12c, y11c, y12c;
  std::vector<double> y11b_from_torque, y12b_from_torque;

  explicit TwinMultipoleSeries(int K) : order(K) {
    const ScaledBinomials B(K + 2);
    const std::vector<double> xa = axisymmetric_translation_series(K, B);
    const AsymmetricSeries f = asymmetric_series(K, B, true), t = asymmetric_series(K, B, false);
    const AxisymmetricRotationSeries xc = axisymmetric_rotation_series(K, B);
    // Parity splits self (even) from other (odd), except for the pseudo-vector coupling b.
    auto split = [K](const std::vector<double>& c, int parity, double factor, double constant) {
      std::vector<double> out(static_cast<std::size_t>(K + 1), 0.0);
      for (int k = 1; k <= K; ++k)
        if (k % 2 == parity) out[static_cast<std::size_t>(k)] = factor * c[static_cast<std::size_t>(k)];
      out[0] = constant;
      return out;
    };
    x11a = split(xa, 0, -1.0, 1.0);
    x12a = split(xa, 1, 1.0, 0.0);
    y11a = split(f.translation, 0, -1.0, 1.0);
    y12a = split(f.translation, 1, 1.0, 0.0);
    // Force units 6 pi eta a, angular velocity units 1/(8 pi eta a^3): 2/3 to 1/(4 pi eta a^2).
    y11b = split(f.rotation, 1, -2.0 / 3.0, 0.0);
    y12b = split(f.rotation, 0, 2.0 / 3.0, 0.0);
    y11b_from_torque = split(t.translation, 1, -0.5, 0.0);
    y12b_from_torque = split(t.translation, 0, 0.5, 0.0);
    y11c = split(t.rotation, 0, -1.0, 1.0);
    y12c = split(t.rotation, 1, -1.0, 0.0);
    x11c = xc.self;
    x12c = xc.other;
  }

  // sum_k c_k u^k (Horner), and an estimate of the tail beyond k = K: the last two terms
  // continued as a geometric series of ratio u^2.
  static double sum(const std::vector<double>& c, double u, double& tail) {
    double value = 0.0;
    for (std::size_t k = c.size(); k-- > 0;) value = value * u + c[k];
    const std::size_t K = c.size() - 1;
    const double last = std::abs(c[K]) * std::pow(u, static_cast<double>(K)) +
                        std::abs(c[K - 1]) * std::pow(u, static_cast<double>(K - 1));
    tail = std::max(tail, last * u * u / (1.0 - u * u));
    return value;
  }
};

inline const TwinMultipoleSeries& twin_multipole_series() {
  static const TwinMultipoleSeries series(kTwinMultipoleOrder);  // built once, thread-safe
  return series;
}

}  // namespace detail

// The ten functions at s = r / a > 2. Throws std::invalid_argument for s not finite or
// <= 2, std::domain_error where the truncation estimate exceeds kTwinMultipoleTolerance.
inline TwoSphereMobilityFunctions two_sphere_mobility_functions(double r_over_a) {
  require_finite(r_over_a, "r_over_a");
  if (!(r_over_a > 2.0))
    fail_argument("r_over_a", "must be > 2 (spheres apart), got " + std::to_string(r_over_a));
  const detail::TwinMultipoleSeries& c = detail::twin_multipole_series();
  const double u = 2.0 / r_over_a;
  TwoSphereMobilityFunctions m;
  double& tail = m.truncation_error;
  using S = detail::TwinMultipoleSeries;
  m.x11a = S::sum(c.x11a, u, tail);
  m.x12a = S::sum(c.x12a, u, tail);
  m.y11a = S::sum(c.y11a, u, tail);
  m.y12a = S::sum(c.y12a, u, tail);
  m.y11b = S::sum(c.y11b, u, tail);
  m.y12b = S::sum(c.y12b, u, tail);
  m.x11c = S::sum(c.x11c, u, tail);
  m.x12c = S::sum(c.x12c, u, tail);
  m.y11c = S::sum(c.y11c, u, tail);
  m.y12c = S::sum(c.y12c, u, tail);
  if (!(tail <= kTwinMultipoleTolerance))
    throw std::domain_error("two_sphere_mobility_functions: r/a = " + std::to_string(r_over_a) +
                            " is too close to contact for the " + std::to_string(c.order) +
                            "-term series (tail estimate " + std::to_string(tail) + ")");
  return m;
}

using Mat12 = Eigen::Matrix<double, 12, 12>;

// The 12 x 12 mobility of spheres at x1 and x2 (radius a, viscosity eta), rows (u_1, omega_1,
// u_2, omega_2), columns (f_1, tau_1, f_2, tau_2), from the functions m.
inline Mat12 two_sphere_mobility_matrix(const TwoSphereMobilityFunctions& m, const Vec3& x1, const Vec3& x2,
                                        double a, double eta) {
  if (!((x2 - x1).norm() > 0.0)) fail_argument("x2", "must differ from x1");
  const double mu_t = 1.0 / (6.0 * std::numbers::pi * eta * a);
  const double mu_b = 1.0 / (4.0 * std::numbers::pi * eta * a * a);
  const double mu_r = 1.0 / (8.0 * std::numbers::pi * eta * a * a * a);
  const Vec3 e = (x2 - x1).normalized();  // from sphere 1 to sphere 2
  const Mat3 ee = e * e.transpose(), I = Mat3::Identity();
  auto axial = [&](double x, double y) -> Mat3 { return x * ee + y * (I - ee); };
  Mat12 M;
  for (int alpha = 0; alpha < 2; ++alpha) {
    const Mat3 f_cross_e = -cross_matrix(alpha == 0 ? e : Vec3(-e));  // f -> f x e_alpha
    for (int beta = 0; beta < 2; ++beta) {
      const bool self = alpha == beta;
      M.block<3, 3>(6 * alpha, 6 * beta) = mu_t * (self ? axial(m.x11a, m.y11a) : axial(m.x12a, m.y12a));
      M.block<3, 3>(6 * alpha + 3, 6 * beta) = mu_b * (self ? m.y11b : m.y12b) * f_cross_e;
      M.block<3, 3>(6 * alpha + 3, 6 * beta + 3) = mu_r * (self ? axial(m.x11c, m.y11c) : axial(m.x12c, m.y12c));
    }
  }
  for (int alpha = 0; alpha < 2; ++alpha)  // u_alpha from tau_beta: reciprocity
    for (int beta = 0; beta < 2; ++beta)
      M.block<3, 3>(6 * alpha, 6 * beta + 3) = M.block<3, 3>(6 * beta + 3, 6 * alpha).transpose();
  return M;
}

// The exact 12 x 12 mobility of two equal spheres of radius a at x1, x2 (|x2 - x1| > 2a).
inline Mat12 two_sphere_mobility_matrix(const Vec3& x1, const Vec3& x2, double a, double eta) {
  require_finite(x1, "x1");
  require_finite(x2, "x2");
  require_positive(a, "radius");
  require_positive(eta, "viscosity");
  return two_sphere_mobility_matrix(two_sphere_mobility_functions((x2 - x1).norm() / a), x1, x2, a, eta);
}

}  // namespace stokescontact
