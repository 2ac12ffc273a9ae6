#pragma once
// Rotne-Prager-Yamakawa mobility between N equal spheres of radius a (Broms & Tornberg
// Sec. 1.1, the particle-level model of their Fig. 4 runs; Yan et al. Sec. III.A): the pair
// blocks of rpy_kernel.hpp (translation) and rpy_rotation_kernel.hpp (rotation), with the
// overlapping branches of Wajnryb et al. (2013), so M stays SPD when spheres overlap.
//
// dofs_per_body 3: translation only (u from f), what a sphere scene pushed through the centres
// needs. dofs_per_body 6: (u, omega) from (f, tau), all four couplings.
//
// apply is the O(N^2) direct sum, matrix-free: targets in blocks that stay in L1, every source
// streamed past them, the loop over the targets of a block written so that the compiler
// vectorises it (structure of arrays, no branches, no library calls), blocks shared among
// OpenMP threads. Each target sums its sources in the same order whatever the thread count.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/mobility/mobility_operator.hpp"
#include "stokescontact/mobility/rpy_kernel.hpp"
#include "stokescontact/mobility/rpy_rotation_kernel.hpp"

namespace stokescontact {

namespace detail {

// 1/sqrt(x) for normal x > 0: four Newton steps y <- y (3/2 - x y^2 / 2) from the bit-level
// estimate (Lomont's constant, relative error < 3.5e-3; each step squares it), a few ulp in
// the end. Plain arithmetic: GCC does not vectorise std::sqrt under the default -fmath-errno.
inline double inverse_sqrt(double x) {
  double y = std::bit_cast<double>(std::uint64_t{0x5fe6eb50c7b537a9} - (std::bit_cast<std::uint64_t>(x) >> 1));
  const double half_x = 0.5 * x;
  y *= 1.5 - half_x * y * y;
  y *= 1.5 - half_x * y * y;
  y *= 1.5 - half_x * y * y;
  y *= 1.5 - half_x * y * y;
  return y;
}

// The pair coefficients of rpy_kernel.hpp and rpy_rotation_kernel.hpp for r = |x_i - x_j|,
// written per r vector and without branches: both branches are evaluated and blended with a
// 0/1 mask (GCC will not if-convert floating-point branches under -ftrapping-math).
//   u_i += mu_t  [tt_f f + tt_h (r . f) r] + mu_rt rt (tau x r)
//   omega_i += mu_rt rt (f x r) + mu_r [rr_f tau + rr_h (r . tau) r]
struct RpyPairTerms {
  double tt_f, tt_h, rt, rr_f, rr_h;
};

template <bool Rotation>
inline RpyPairTerms rpy_pair_terms(double r2, double a, double inv_a) {
  // r2 = 0 (the self pair) is lifted to 1e-300: every term stays finite and multiplies r = 0.
  const double inv_r = inverse_sqrt(r2 + 1e-300);
  const double r = r2 * inv_r, inv_r2 = inv_r * inv_r;
  const double far = 0.5 + 0.5 * std::copysign(1.0, r - 2.0 * a);  // 1 for r >= 2a, else 0
  const double near = 1.0 - far;
  const double s = far * a * inv_r;  // a / r on the far branch, 0 on the near one
  const double s3 = s * s * s, t = r * inv_a;
  RpyPairTerms c{};
  c.tt_f = 0.75 * s + 0.5 * s3 + near * (1.0 - 9.0 / 32.0 * t);
  c.tt_h = (0.75 * s - 1.5 * s3) * inv_r2 + near * (3.0 / 32.0) * inv_a * inv_r;
  if constexpr (Rotation) {
    c.rt = s * s * inv_r + near * inv_a * (0.5 - 3.0 / 16.0 * t);
    c.rr_f = -0.5 * s3 + near * (1.0 - 27.0 / 32.0 * t + 5.0 / 64.0 * t * t * t);
    c.rr_h = 1.5 * s3 * inv_r2 + near * (9.0 / 32.0 * inv_a * inv_r - 3.0 / 64.0 * r * inv_a * inv_a * inv_a);
  }
  return c;
}

// Per-sphere data as separate arrays (structure of arrays), so target loops load packets.
struct SphereArrays {
  std::array<VecX, 3> x;    // centres
  std::array<VecX, 3> f;    // forces
  std::array<VecX, 3> tau;  // torques (6 dofs only)
};

inline constexpr Eigen::Index kRpyTargetBlock = 256;  // 256 targets x 6-12 doubles: L1-resident

// u (units mu_t) and omega (units mu_r) of targets [i0, i1) from all sources.
template <bool Rotation>
void rpy_target_block(const SphereArrays& s, double a, Eigen::Index i0, Eigen::Index i1,
                      std::array<VecX, 3>& u, std::array<VecX, 3>& omega) {
  constexpr Eigen::Index B = kRpyTargetBlock;
  std::array<std::array<double, B>, 3> ub{}, wb{};
  const double inv_a = 1.0 / a;
  const double* x = s.x[0].data();
  const double* y = s.x[1].data();
  const double* z = s.x[2].data();
  const Eigen::Index m = i1 - i0, n = s.x[0].size();
  for (Eigen::Index j = 0; j < n; ++j) {
    const double xj = s.x[0][j], yj = s.x[1][j], zj = s.x[2][j];
    const double fx = s.f[0][j], fy = s.f[1][j], fz = s.f[2][j];
    double tx = 0.0, ty = 0.0, tz = 0.0;  // torque on source j (6 dofs)
    if constexpr (Rotation) {
      tx = s.tau[0][j];
      ty = s.tau[1][j];
      tz = s.tau[2][j];
    }
    // The rotation-translation coupling in the accumulators' units: the torque for u
    // (mu_rt / mu_t = 3 / (4a)), the force for omega (mu_rt / mu_r = a).
    const double tux = 0.75 * inv_a * tx, tuy = 0.75 * inv_a * ty, tuz = 0.75 * inv_a * tz;
    const double gx = a * fx, gy = a * fy, gz = a * fz;
    for (Eigen::Index k = 0; k < m; ++k) {
      const double rx = x[i0 + k] - xj, ry = y[i0 + k] - yj, rz = z[i0 + k] - zj;
      const RpyPairTerms c = rpy_pair_terms<Rotation>(rx * rx + ry * ry + rz * rz, a, inv_a);
      const double rf = c.tt_h * (rx * fx + ry * fy + rz * fz);
      ub[0][k] += c.tt_f * fx + rf * rx;
      ub[1][k] += c.tt_f * fy + rf * ry;
      ub[2][k] += c.tt_f * fz + rf * rz;
      if constexpr (Rotation) {
        ub[0][k] += c.rt * (tuy * rz - tuz * ry);  // tau x r
        ub[1][k] += c.rt * (tuz * rx - tux * rz);
        ub[2][k] += c.rt * (tux * ry - tuy * rx);
        const double rtau = c.rr_h * (rx * tx + ry * ty + rz * tz);
        wb[0][k] += c.rr_f * tx + rtau * rx + c.rt * (gy * rz - gz * ry);  // + f x r
        wb[1][k] += c.rr_f * ty + rtau * ry + c.rt * (gz * rx - gx * rz);
        wb[2][k] += c.rr_f * tz + rtau * rz + c.rt * (gx * ry - gy * rx);
      }
    }
  }
  for (std::size_t d = 0; d < 3; ++d) {
    u[d].segment(i0, m) = Eigen::Map<const VecX>(ub[d].data(), m);
    if constexpr (Rotation) omega[d].segment(i0, m) = Eigen::Map<const VecX>(wb[d].data(), m);
  }
}

// The direct sum over all targets: u in units of mu_t, omega in units of mu_r.
template <bool Rotation>
void rpy_direct_sum(const SphereArrays& s, double a, std::array<VecX, 3>& u, std::array<VecX, 3>& omega) {
  const Eigen::Index n = s.x[0].size();
  const Eigen::Index blocks = (n + kRpyTargetBlock - 1) / kRpyTargetBlock;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 1) if (blocks > 1)
#endif
  for (Eigen::Index b = 0; b < blocks; ++b)
    rpy_target_block<Rotation>(s, a, b * kRpyTargetBlock, std::min(n, (b + 1) * kRpyTargetBlock), u, omega);
}

}  // namespace detail

class RpyMobility {
 public:
  // `spheres` spheres of radius parameters.radius; dofs_per_body 3 (translation) or 6.
  RpyMobility(std::size_t spheres, RpyParameters parameters, int dofs_per_body = 3)
      : n_(static_cast<Eigen::Index>(spheres)), parameters_(parameters), dofs_(dofs_per_body) {
    parameters_.validate("RpyParameters");
    if (dofs_ != 3 && dofs_ != 6) fail_argument("dofs_per_body", "must be 3 or 6, got " + std::to_string(dofs_));
    if (n_ == 0) fail_argument("spheres", "needs at least one sphere");
    for (auto* arrays : {&s_.x, &s_.f, &u_})
      for (VecX& v : *arrays) v.resize(n_);
    if (dofs_ == 6)
      for (auto* arrays : {&s_.tau, &omega_})
        for (VecX& v : *arrays) v.resize(n_);
  }

  // New centres (orientations are irrelevant to spheres but must be valid). Validates
  // everything before changing anything.
  void set_configuration(std::span<const Pose> poses) {
    validate(poses, static_cast<std::size_t>(n_));
    for (Eigen::Index i = 0; i < n_; ++i)
      for (std::size_t d = 0; d < 3; ++d) s_.x[d][i] = poses[static_cast<std::size_t>(i)].x[static_cast<Eigen::Index>(d)];
    configured_ = true;
  }

  // U = M F, one application; F stacked per sphere (f_i[, tau_i]).
  VecX apply(const VecX& F) {
    require_configured();
    require_finite(F, size(), "F");
    counter_.count();
    for (Eigen::Index i = 0; i < n_; ++i)
      for (Eigen::Index d = 0; d < 3; ++d) {
        s_.f[static_cast<std::size_t>(d)][i] = F[dofs_ * i + d];
        if (dofs_ == 6) s_.tau[static_cast<std::size_t>(d)][i] = F[dofs_ * i + 3 + d];
      }
    const double a = parameters_.radius, eta = parameters_.viscosity;
    if (dofs_ == 6)
      detail::rpy_direct_sum<true>(s_, a, u_, omega_);
    else
      detail::rpy_direct_sum<false>(s_, a, u_, omega_);
    const double mu_t = stokes_mobility(a, eta), mu_r = rotation_mobility(a, eta);
    VecX U(size());
    for (Eigen::Index i = 0; i < n_; ++i)
      for (Eigen::Index d = 0; d < 3; ++d) {
        U[dofs_ * i + d] = mu_t * u_[static_cast<std::size_t>(d)][i];
        if (dofs_ == 6) U[dofs_ * i + 3 + d] = mu_r * omega_[static_cast<std::size_t>(d)][i];
      }
    return U;
  }

  // The dense matrix from the pair blocks, formed directly (0 applications).
  MatX dense_matrix() const {
    require_configured();
    MatX m(size(), size());
    const double a = parameters_.radius, eta = parameters_.viscosity;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 16)
#endif
    for (Eigen::Index i = 0; i < n_; ++i)
      for (Eigen::Index j = 0; j < n_; ++j) {
        const Vec3 r = centre(i) - centre(j);
        auto block = m.block(dofs_ * i, dofs_ * j, dofs_, dofs_);
        block.topLeftCorner<3, 3>() = rpy_translation(r, a, eta);
        if (dofs_ == 6) {
          const Mat3 rt = rpy_rotation_translation(r, a, eta);
          block.topRightCorner<3, 3>() = rt;
          block.bottomLeftCorner<3, 3>() = rt;
          block.bottomRightCorner<3, 3>() = rpy_rotation_rotation(r, a, eta);
        }
      }
    return m;
  }

  Eigen::Index size() const { return dofs_ * n_; }
  int dofs_per_body() const { return dofs_; }
  std::size_t applications() const { return counter_.applications(); }
  void reset_applications() { counter_.reset_applications(); }
  const RpyParameters& parameters() const { return parameters_; }

 private:
  Vec3 centre(Eigen::Index i) const { return {s_.x[0][i], s_.x[1][i], s_.x[2][i]}; }

  void require_configured() const {
    if (!configured_) throw std::logic_error("RpyMobility: call set_configuration before apply");
  }

  Eigen::Index n_ = 0;
  RpyParameters parameters_;
  int dofs_ = 3;
  detail::SphereArrays s_;
  std::array<VecX, 3> u_, omega_;  // sums of the last apply, units mu_t and mu_r
  bool configured_ = false;
  ApplicationCounter counter_;
};

}  // namespace stokescontact
