#pragma once
// The contact matrix D (Broms & Tornberg eq. 18-23; Yan et al. eq. 31-32), sparse,
// (dofs_per_body N) x Nc: column k maps the magnitude lambda_k of contact k, between bodies
// i < j, to the forces and torques on them, F_c = D lambda (Broms eq. 6). Rows follow the
// mobility layout: body b owns rows [b d, (b + 1) d), (force, torque) for d = 6, the force
// alone for d = 3 (the translation-only variant, for spheres, whose contact forces pass
// through their centres: the torques are dropped).
//
// Sign convention. n is the unit normal from body i towards body j, s_i and s_j the lever
// arms from each body's centre (body j: the centre of the image used) to its contact point.
// A contact at one point pair contributes
//     body i: force -n, torque s_i x (-n);     body j: force +n, torque s_j x n,
// which is the gradient of the pair distance d with respect to the bodies' rigid motions:
//     D^T U = dd/dt   for U = (u_1, omega_1, ..., u_N, omega_N)   (Yan eq. 38: grad Phi = D^T),
// so lambda >= 0 pushes the bodies apart, and each column obeys Newton's third law (forces
// sum to zero; torques about any point sum to (p_j - p_i) x n = d n x n = 0). This is Broms
// eq. 18, D = -grad B = -b'(d) grad d with b' < 0, normalised as in Broms eq. 20. (Broms eq. 21 and 23
// as printed write the torques as n x s, the opposite sign of s x f; we keep s x f, which the
// finite-difference test of D^T U against dd/dt confirms.)
//
// d^P (Broms eq. 20-21): one point pair per contact, the closest points; the force has unit norm.
// Line contacts of LineContactRods put that point pair where geometry/line_contact.hpp spreads
// the force of a near-parallel pair (ContactPair::force_points) instead.
// d^S (Broms eq. 22-23): the sum over the contact's node pairs l of w_l (gradient of d_l), with
// weights w_l = -b'(d_l) of a barrier with threshold d_try (b0 by default: w_l = 1/d_l as in
// the paper, regularised by eps_reg / eps_cap so overlapping node pairs get finite weights),
// divided by the norm of the net force |sum_l w_l n_l| as Broms eq. 20 does: lambda is then the
// magnitude of the net contact force in both variants, independent of the number of nodes
// and of the barrier's scale. Where the node forces nearly cancel (a body squeezed from
// opposite sides) that norm is floored at min_net_force_fraction * sum_l w_l, so the column
// stays bounded (its force is then shorter than 1).
#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Sparse>

#include "stokescontact/core/parallel_for.hpp"

#include "stokescontact/contact/barrier.hpp"
#include "stokescontact/contact/contact_pairs.hpp"
#include "stokescontact/contact/surface_contacts.hpp"

namespace stokescontact {

// Degrees of freedom per body that a scene of shape S needs: spheres never carry torques.
template <Shape S>
inline constexpr int contact_dofs_per_body = std::is_same_v<S, Sphere> ? 3 : 6;

// One column of D: body i receives -force_j and torque_i, body j force_j and torque_j.
struct ContactColumn {
  Eigen::Index i = 0;
  Eigen::Index j = 0;
  Vec3 force_j = Vec3::Zero();
  Vec3 torque_i = Vec3::Zero();
  Vec3 torque_j = Vec3::Zero();
};

// How the node pairs of a surface contact are weighted (Broms eq. 23).
struct SurfaceWeights {
  BarrierFunction function = BarrierFunction::b0;  // w_l = -b'(d_l), threshold d_try
  double eps_reg = 0.0;                            // shift of the weight barrier (Broms Remark 4)
  double cap_fraction = 1e-2;                      // its cap at cap_fraction (d_try + eps_reg)
  double min_net_force_fraction = 1e-3;            // floor of the normalisation, in (0, 1]
};

namespace detail {

// Adds w times the gradient of a point-pair distance with normal n and lever arms s_i, s_j.
inline void add_distance_gradient(ContactColumn& c, const Vec3& n, const Vec3& s_i, const Vec3& s_j, double w) {
  c.force_j += w * n;
  c.torque_i -= w * s_i.cross(n);
  c.torque_j += w * s_j.cross(n);
}

inline void require_pair_indices(Eigen::Index i, Eigen::Index j, std::size_t bodies, const std::string& field) {
  const auto n = static_cast<Eigen::Index>(bodies);
  if (!(0 <= i && i < n && 0 <= j && j < n && i != j))
    fail_argument(field, "bodies (" + std::to_string(i) + ", " + std::to_string(j) +
                             ") must be distinct indices into poses, N = " + std::to_string(n));
}

// The centres of a pair's bodies (body j: its image), checked.
inline std::pair<Vec3, Vec3> pair_centres(Eigen::Index i, Eigen::Index j, const Vec3& image_shift,
                                          std::span<const Pose> poses, const std::string& field) {
  require_pair_indices(i, j, poses.size(), field);
  // (the names are built only on failure: this runs for every column of D)
  if (!image_shift.allFinite()) require_finite(image_shift, field + ".image_shift");
  const Pose& pi = poses[static_cast<std::size_t>(i)];
  const Pose& pj = poses[static_cast<std::size_t>(j)];
  if (!is_valid(pi)) validate(pi, "poses[" + std::to_string(i) + "]");
  if (!is_valid(pj)) validate(pj, "poses[" + std::to_string(j) + "]");
  return {pi.x, pj.x + image_shift};
}

inline bool valid_point_pair(const Vec3& point_i, const Vec3& point_j, const Vec3& normal) {
  return point_i.allFinite() && point_j.allFinite() && normal.allFinite() && std::abs(normal.norm() - 1.0) <= 1e-10;
}

[[noreturn]] inline void fail_point_pair(const std::string& field) {
  fail_argument(field, "points must be finite and the normal a unit vector");
}

inline ContactColumn particle_contact_column(const ContactPair& pair, std::span<const Pose> poses,
                                             const std::string& field) {
  const auto [x_i, x_j] = pair_centres(pair.i, pair.j, pair.image_shift, poses, field);
  const ClosestPoints& cp = pair.force_points ? *pair.force_points : pair.points;  // a line contact's, if any
  if (!valid_point_pair(cp.point_a, cp.point_b, cp.normal)) fail_point_pair(field + ".points");
  ContactColumn c{pair.i, pair.j};
  add_distance_gradient(c, cp.normal, cp.point_a - x_i, cp.point_b - x_j, 1.0);
  return c;
}

inline ContactColumn surface_contact_column(const SurfaceContact& contact, std::span<const Pose> poses,
                                            const BarrierParameters& weight_barrier, const SurfaceWeights& weights,
                                            const std::string& field) {
  const auto [x_i, x_j] = pair_centres(contact.i, contact.j, contact.image_shift, poses, field);
  ContactColumn c{contact.i, contact.j};
  double weight_sum = 0.0;
  for (std::size_t l = 0; l < contact.distances.pairs.size(); ++l) {
    const SurfacePair& p = contact.distances.pairs[l];
    if (!valid_point_pair(p.point_a, p.point_b, p.normal))
      fail_point_pair(field + ".distances.pairs[" + std::to_string(l) + "]");
    const double w = -barrier(weights.function, p.distance, weight_barrier).first;
    if (w == 0.0) continue;  // at d_try exactly
    weight_sum += w;
    add_distance_gradient(c, p.normal, p.point_a - x_i, p.point_b - x_j, w);
  }
  if (weight_sum == 0.0)  // every node pair sits at d_try: fall back to the closest points
    return particle_contact_column({contact.i, contact.j, contact.image_shift, contact.distances.particle, std::nullopt, std::nullopt}, poses,
                                   field + ".distances.particle");
  const double scale = 1.0 / std::max(c.force_j.norm(), weights.min_net_force_fraction * weight_sum);
  c.force_j *= scale;
  c.torque_i *= scale;
  c.torque_j *= scale;
  return c;
}

// The barrier whose slopes weight the node pairs, threshold d_try.
inline BarrierParameters surface_weight_barrier(double d_try, const SurfaceWeights& weights) {
  require_positive(d_try, "d_try");
  if (!(weights.min_net_force_fraction > 0.0 && weights.min_net_force_fraction <= 1.0))
    fail_argument("SurfaceWeights.min_net_force_fraction",
                  "must lie in (0, 1], got " + std::to_string(weights.min_net_force_fraction));
  return barrier_parameters(d_try, weights.eps_reg, weights.cap_fraction);
}

}  // namespace detail

// D with columns[d.cols()..] appended: d holds the columns before them already (a contact
// step only ever appends pairs), which are copied, not computed again. (dofs_per_body N) x
// columns.size(), dofs_per_body = 3 or 6; each column holds both bodies' dofs_per_body rows,
// ascending (the lower body's first), as setFromTriplets would order the same entries.
inline void append_contact_columns(Eigen::SparseMatrix<double>& d, std::span<const ContactColumn> columns,
                                   std::size_t bodies, int dofs_per_body) {
  if (dofs_per_body != 3 && dofs_per_body != 6)
    fail_argument("dofs_per_body", "must be 3 or 6, got " + std::to_string(dofs_per_body));
  const Eigen::Index per_body = dofs_per_body, per_column = 2 * per_body;
  const auto rows = static_cast<Eigen::Index>(bodies) * per_body;
  const auto nc = static_cast<Eigen::Index>(columns.size()), first = d.cols();
  if (first > nc || (first > 0 && d.rows() != rows) || !d.isCompressed() || d.nonZeros() != first * per_column)
    fail_argument("d", "must hold the first columns of the contact matrix, compressed (" + std::to_string(d.rows()) +
                           " x " + std::to_string(d.cols()) + " for " + std::to_string(nc) + " columns of " +
                           std::to_string(rows) + " rows)");
  Eigen::SparseMatrix<double> out(rows, nc);
  out.resizeNonZeros(nc * per_column);
  int* const outer = out.outerIndexPtr();
  int* const inner = out.innerIndexPtr();
  double* const value = out.valuePtr();
  std::copy_n(d.innerIndexPtr(), first * per_column, inner);
  std::copy_n(d.valuePtr(), first * per_column, value);
  for (Eigen::Index k = 0; k <= nc; ++k) outer[k] = static_cast<int>(k * per_column);
  const auto n = static_cast<Eigen::Index>(bodies);
  for (Eigen::Index k = first; k < nc; ++k) {
    const ContactColumn& c = columns[static_cast<std::size_t>(k)];
    if (!(0 <= c.i && c.i < n && 0 <= c.j && c.j < n && c.i != c.j))
      detail::require_pair_indices(c.i, c.j, bodies, "columns[" + std::to_string(k) + "]");
    // Body b's entries: -force_j, torque_i (body i) or force_j, torque_j (body j).
    const auto body_entries = [&](Eigen::Index b, Eigen::Index at) {
      const bool is_i = b == c.i;
      for (Eigen::Index r = 0; r < per_body; ++r) {
        inner[at + r] = static_cast<int>(b * per_body + r);
        value[at + r] = r < 3 ? (is_i ? -c.force_j[r] : c.force_j[r]) : (is_i ? c.torque_i[r - 3] : c.torque_j[r - 3]);
      }
    };
    body_entries(std::min(c.i, c.j), k * per_column);
    body_entries(std::max(c.i, c.j), k * per_column + per_body);
  }
  d = std::move(out);
}

// D from its columns: (dofs_per_body N) x columns.size(), dofs_per_body = 3 or 6.
inline Eigen::SparseMatrix<double> assemble_contact_matrix(std::span<const ContactColumn> columns,
                                                           std::size_t bodies, int dofs_per_body) {
  Eigen::SparseMatrix<double> d;
  append_contact_columns(d, columns, bodies, dofs_per_body);
  return d;
}

// M D for a block-diagonal M (one block per body: free draining), with D's columns from
// MD.cols() on appended to MD: column k of M D is nonzero on the rows of D's column k only (its
// two bodies' blocks), so M D has D's pattern and each column is computed alone, O(new
// columns). The same sums in the same order as Eigen's sparse product M * D (D's entries of a
// column in order, each times M's column); M must be block diagonal with blocks of
// D.rows() / bodies rows (std::invalid_argument otherwise).
inline void append_block_diagonal_product(Eigen::SparseMatrix<double>& MD, const Eigen::SparseMatrix<double>& M,
                                          const Eigen::SparseMatrix<double>& D, std::size_t bodies) {
  const Eigen::Index first = MD.cols(), nc = D.cols();
  if (M.rows() != D.rows() || M.cols() != D.rows() || bodies == 0 || D.rows() % static_cast<Eigen::Index>(bodies) != 0)
    fail_argument("M", "is " + std::to_string(M.rows()) + " x " + std::to_string(M.cols()) + " for D of " +
                           std::to_string(D.rows()) + " rows and " + std::to_string(bodies) + " bodies");
  if (first > nc || (first > 0 && MD.rows() != D.rows()) || !MD.isCompressed() || !D.isCompressed() ||
      MD.nonZeros() != D.outerIndexPtr()[first])
    fail_argument("MD", "must hold M D of D's first columns, compressed");
  const Eigen::Index per_body = D.rows() / static_cast<Eigen::Index>(bodies);
  Eigen::SparseMatrix<double> out(D.rows(), nc);
  out.resizeNonZeros(D.nonZeros());
  std::copy_n(D.outerIndexPtr(), nc + 1, out.outerIndexPtr());
  std::copy_n(D.innerIndexPtr(), D.nonZeros(), out.innerIndexPtr());
  std::copy_n(MD.valuePtr(), MD.nonZeros(), out.valuePtr());
  const int* const outer = D.outerIndexPtr();
  const int* const inner = D.innerIndexPtr();
  double* const value = out.valuePtr();
  std::vector<char> outside(static_cast<std::size_t>(nc - first), 0);
  parallel_for(nc - first, [&](std::ptrdiff_t index) {
    const Eigen::Index k = first + index;
    const int begin = outer[k], end = outer[k + 1];
    for (int e = begin; e < end; ++e) value[e] = 0.0;
    for (int e = begin; e < end; ++e) {
      const double y = D.valuePtr()[e];
      for (Eigen::SparseMatrix<double>::InnerIterator m(M, inner[e]); m; ++m) {
        const int* const at = std::find(inner + begin, inner + end, static_cast<int>(m.row()));
        if (at == inner + end || m.row() / per_body != inner[e] / per_body) {
          outside[static_cast<std::size_t>(index)] = 1;
          continue;
        }
        value[at - inner] += m.value() * y;
      }
    }
  });
  if (std::find(outside.begin(), outside.end(), 1) != outside.end())
    fail_argument("M", "is not block diagonal with blocks of " + std::to_string(per_body) + " rows");
  MD = std::move(out);
}

// Broms eq. 20-21: the column of a pair from its closest points.
inline ContactColumn particle_contact_column(const ContactPair& pair, std::span<const Pose> poses) {
  return detail::particle_contact_column(pair, poses, "pair");
}

// Broms eq. 22-23: the weighted, normalised column of a surface contact; d_try > 0 is the
// threshold its node pairs were found with.
inline ContactColumn surface_contact_column(const SurfaceContact& contact, std::span<const Pose> poses, double d_try,
                                            const SurfaceWeights& weights = {}) {
  return detail::surface_contact_column(contact, poses, detail::surface_weight_barrier(d_try, weights), weights,
                                        "contact");
}

// D from closest points (Broms eq. 20-21), one column per pair.
inline Eigen::SparseMatrix<double> contact_matrix(std::span<const ContactPair> pairs, std::span<const Pose> poses,
                                                  int dofs_per_body = 6) {
  std::vector<ContactColumn> columns;
  columns.reserve(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k)
    columns.push_back(detail::particle_contact_column(pairs[k], poses, "pairs[" + std::to_string(k) + "]"));
  return assemble_contact_matrix(columns, poses.size(), dofs_per_body);
}

// D from surface-node distances (Broms eq. 22-23), one column per contact.
inline Eigen::SparseMatrix<double> surface_contact_matrix(std::span<const SurfaceContact> contacts,
                                                          std::span<const Pose> poses, double d_try,
                                                          int dofs_per_body = 6, const SurfaceWeights& weights = {}) {
  const BarrierParameters weight_barrier = detail::surface_weight_barrier(d_try, weights);
  std::vector<ContactColumn> columns;
  columns.reserve(contacts.size());
  for (std::size_t k = 0; k < contacts.size(); ++k)
    columns.push_back(detail::surface_contact_column(contacts[k], poses, weight_barrier, weights,
                                                     "contacts[" + std::to_string(k) + "]"));
  return assemble_contact_matrix(columns, poses.size(), dofs_per_body);
}

}  // namespace stokescontact
