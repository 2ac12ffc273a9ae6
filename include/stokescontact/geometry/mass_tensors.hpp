#pragma once
// Mass tensors of a uniform body about its centre of mass, in the body frame (Yan et al.):
//   N   = integral rho x x^T dV                 (eq. 6)
//   G_M = integral rho (|x|^2 I - x x^T) dV     (eq. 4, the moment of inertia tensor)
// scaled by the density rho (default 1: then they are pure volume integrals). Sphere and
// spherocylinder are analytic (Yan A1-A6); the boomerang is a sum of exact pieces
// (cylinders, hemispherical caps) and a Gauss quadrature of the torus section, exact to
// rounding because the integrand is polynomial in the tube radius, a low-degree
// trigonometric polynomial around the tube and an entire function along the bend.
#include <cmath>
#include <numbers>
#include <vector>

#include "stokescontact/geometry/shapes.hpp"

namespace stokescontact {

struct MassTensors {
  Mat3 N = Mat3::Zero();    // eq. 6
  Mat3 G_M = Mat3::Zero();  // eq. 4
};

namespace detail {

// Volume, first moment integral x dV and second moment integral x x^T dV of a body piece.
struct Moments {
  double volume = 0.0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();

  Moments& operator+=(const Moments& o) {
    volume += o.volume;
    first += o.first;
    second += o.second;
    return *this;
  }
};

// Solid cylinder of radius r about a segment.
inline Moments cylinder_moments(const Segment& axis, double r) {
  Moments m;
  const double a = axis.length();
  if (a == 0.0) return m;
  const double pi = std::numbers::pi;
  const Vec3 t = (axis.p1 - axis.p0) / a;
  const Vec3 mid = axis.point(0.5);
  const Mat3 tt = t * t.transpose();
  m.volume = pi * r * r * a;
  m.first = m.volume * mid;
  m.second = m.volume * mid * mid.transpose() + pi * r * r * a * a * a / 12.0 * tt +
             pi * r * r * r * r * a / 4.0 * (Mat3::Identity() - tt);
  return m;
}

// Solid hemisphere of radius r on the flat face centred at `base`, bulging along unit `pole`:
// integral y dV = (pi r^4 / 4) pole, integral y y^T dV = (2 pi r^5 / 15) I about the base.
inline Moments cap_moments(const Vec3& base, const Vec3& pole, double r) {
  const double pi = std::numbers::pi;
  const Vec3 mu = pi * r * r * r * r / 4.0 * pole;
  Moments m;
  m.volume = 2.0 / 3.0 * pi * r * r * r;
  m.first = m.volume * base + mu;
  m.second = m.volume * base * base.transpose() + base * mu.transpose() + mu * base.transpose() +
             2.0 * pi * std::pow(r, 5) / 15.0 * Mat3::Identity();
  return m;
}

// Gauss-Legendre nodes and weights on [0, 1] (Newton on the Legendre recurrence).
inline void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.assign(static_cast<std::size_t>(n), 0.0);
  w.assign(static_cast<std::size_t>(n), 0.0);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double step = p1 / dp;
      z -= step;
      if (std::abs(step) < 1e-16) break;
    }
    const auto k = static_cast<std::size_t>(i);
    x[k] = 0.5 * (1.0 - z);
    w[k] = 1.0 / ((1.0 - z * z) * dp * dp);  // 2 / ((1 - z^2) P'^2), halved for [0, 1]
  }
}

// Solid torus section: x = centre + (R_b + rho cos psi) d(t) + rho sin psi a, with
// d(t) = cos t e1 + sin t e2, a = e1 x e2, dV = rho (R_b + rho cos psi) drho dpsi dt.
// Degree in rho <= 4 (4 Gauss nodes exact), trigonometric degree in psi <= 3 (periodic
// trapezoid with 8 nodes exact), and 16 Gauss nodes in t leave an error far below rounding.
inline Moments torus_section_moments(const Arc& bend, double r) {
  constexpr int n_rho = 4, n_psi = 8, n_t = 16;
  std::vector<double> xr, wr, xt, wt;
  gauss_legendre(n_rho, xr, wr);
  gauss_legendre(n_t, xt, wt);
  const double two_pi = 2.0 * std::numbers::pi;
  const Vec3 a = bend.axis();
  Moments m;
  for (std::size_t it = 0; it < xt.size(); ++it) {
    const double t = xt[it] * bend.angle;
    const Vec3 d = std::cos(t) * bend.e1 + std::sin(t) * bend.e2;
    for (int ip = 0; ip < n_psi; ++ip) {
      const double psi = two_pi * ip / n_psi;
      for (std::size_t ir = 0; ir < xr.size(); ++ir) {
        const double rho = xr[ir] * r;
        const double ring = bend.radius + rho * std::cos(psi);
        const double weight = wt[it] * bend.angle * (two_pi / n_psi) * wr[ir] * r * rho * ring;
        const Vec3 x = bend.centre + ring * d + rho * std::sin(psi) * a;
        m.volume += weight;
        m.first += weight * x;
        m.second += weight * x * x.transpose();
      }
    }
  }
  return m;
}

inline Moments moments(const Spherocylinder& s) {
  const Segment axis = centre_curve(s).segments[0];
  Moments m = cylinder_moments(axis, s.radius);
  m += cap_moments(axis.p0, -Vec3::UnitZ(), s.radius);
  m += cap_moments(axis.p1, Vec3::UnitZ(), s.radius);
  return m;
}

// Caps point along the bend's end tangents, which are the arms' directions.
inline Moments moments(const Boomerang& b) {
  const auto c = centre_curve(b);
  const Arc& bend = c.arcs[0];
  Moments m = cylinder_moments(c.segments[0], b.radius);
  m += cylinder_moments(c.segments[1], b.radius);
  m += torus_section_moments(bend, b.radius);
  m += cap_moments(c.segments[0].p0, -bend.tangent(0.0), b.radius);
  m += cap_moments(c.segments[1].p1, bend.tangent(bend.angle), b.radius);
  return m;
}

}  // namespace detail

// Integral x dV in the body frame: zero when the body origin is the centre of mass (eq. 5).
inline Vec3 first_moment(const Sphere& s) {
  validate(s);
  return Vec3::Zero();  // the centre curve is the origin itself
}
inline Vec3 first_moment(const Spherocylinder& s) {
  validate(s);
  return detail::moments(s).first;
}
inline Vec3 first_moment(const Boomerang& b) {
  validate(b);
  return detail::moments(b).first;
}

// Sphere: N = (4 pi / 15) R^5 rho I, G_M = (8 pi / 15) R^5 rho I.
inline MassTensors mass_tensors(const Sphere& s, double density = 1.0) {
  validate(s);
  require_positive(density, "density");
  const double r5 = std::pow(s.radius, 5), pi = std::numbers::pi;
  return {density * 4.0 * pi / 15.0 * r5 * Mat3::Identity(),
          density * 8.0 * pi / 15.0 * r5 * Mat3::Identity()};
}

// Yan A1-A6 with beta = L / (2R), axis along body z.
inline MassTensors mass_tensors(const Spherocylinder& s, double density = 1.0) {
  validate(s);
  require_positive(density, "density");
  const double beta = s.length / (2.0 * s.radius);
  const double c = density * std::numbers::pi * std::pow(s.radius, 5);
  const double b2 = beta * beta, b3 = b2 * beta;
  const double n_perp = c * (15.0 * beta + 8.0) / 30.0;                                 // A3
  const double n_par = c * (10.0 * b3 + 20.0 * b2 + 15.0 * beta + 4.0) / 15.0;          // A4
  const double g_perp = c * (20.0 * b3 + 40.0 * b2 + 45.0 * beta + 16.0) / 30.0;        // A5
  const double g_par = c * (15.0 * beta + 8.0) / 15.0;                                  // A6
  return {Vec3(n_perp, n_perp, n_par).asDiagonal(), Vec3(g_perp, g_perp, g_par).asDiagonal()};
}

inline MassTensors mass_tensors(const Boomerang& b, double density = 1.0) {
  validate(b);
  require_positive(density, "density");
  const Mat3 second = detail::moments(b).second;
  const Mat3 n = density * 0.5 * (second + second.transpose());  // symmetric to the last bit
  return {n, n.trace() * Mat3::Identity() - n};  // |x|^2 I - x x^T, eq. 4 from eq. 6
}

}  // namespace stokescontact
