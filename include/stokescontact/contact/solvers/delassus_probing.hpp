#pragma once
// A local approximation of the Delassus matrix A = dt D^T M D (the LCP matrix of Broms eq. 26 with
// d^P) on a working set of contacts, from a few mobility applications ("probing").
//
// Column c of A costs one application, M D e_c. But M D e_c is a force dipole's response: its
// effect on a contact k at distance r decays like r^-2 (in the far field of Stokes flow), so
// contacts at least `radius` apart can share one probe: apply M D to the sum of their
// indicators, and read column c's entries at the contacts near c. The contacts are coloured
// greedily so that members of one colour are >= radius apart; row k of a probe is attributed
// to the member nearest k when that member lies within radius / 2 (at most one can), and is
// taken as 0 otherwise. The entries lost are the far field between contacts >= radius / 2
// apart; the contact solver (defect_correction.hpp) corrects for them with exact velocities.
// With radius = infinity every probe has one member and A is exact (formed mode).
//
// Contacts sit at the midpoint of their closest points at Q*; distances between contacts use
// the minimum image in a periodic box.
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <span>
#include <vector>

#include "stokescontact/contact/contact_step.hpp"

namespace stokescontact {

class DelassusProbing {
 public:
  // radius > 0 (may be infinite); the contacts are the step's flagged pairs.
  template <Shape S, MobilityOperator M>
  DelassusProbing(const ContactStep<S, M>& step, double radius) : radius_(radius), box_(step.problem().box) {
    if (!(radius > 0.0)) fail_argument("probe radius", "must be > 0, got " + std::to_string(radius));
    for (const ContactPair& p : step.pairs())
      positions_.push_back(p.points.point_a + 0.5 * p.points.distance * p.points.normal);
  }

  // The working set: indices into step.pairs(), in the order they were added.
  const std::vector<Eigen::Index>& members() const { return members_; }
  // A on the working set (members() x members()), symmetric.
  const MatX& matrix() const { return A_; }
  int probes() const { return static_cast<int>(probes_.size()); }

  // Row k of A on the working set, for any flagged pair k (member or not), read from the probes.
  VecX row(Eigen::Index k) const {
    VecX out = VecX::Zero(static_cast<Eigen::Index>(members_.size()));
    for (const Probe& probe : probes_)
      if (const std::optional<std::size_t> c = nearest_member(probe, k))
        out(static_cast<Eigen::Index>(*c)) = probe.response(k);
    return out;
  }

  // Adds contacts (indices into step.pairs(), not yet members) and probes them: one call of
  // step.MD_times per new colour.
  template <Shape S, MobilityOperator M>
  void add(ContactStep<S, M>& step, std::span<const Eigen::Index> contacts) {
    if (contacts.empty()) return;
    const std::size_t first_new = members_.size();
    members_.insert(members_.end(), contacts.begin(), contacts.end());
    const std::size_t first_probe = probes_.size();
    colour(first_new, first_probe);
    for (std::size_t c = first_probe; c < probes_.size(); ++c) {
      VecX indicator = VecX::Zero(step.nc());
      for (std::size_t m : probes_[c].members) indicator(members_[m]) = 1.0;
      probes_[c].response = step.problem().dt * (step.D().transpose() * step.MD_times(indicator));
    }
    assemble();
  }

 private:
  struct Probe {
    std::vector<std::size_t> members;  // positions in members_
    VecX response;                     // dt D^T M D (sum of the members' indicators), all Nc rows
  };

  // Between the contacts at members_[a] and members_[b].
  double distance(std::size_t a, std::size_t b) const { return contact_distance(members_[a], members_[b]); }

  // Between flagged pairs k and l.
  double contact_distance(Eigen::Index k, Eigen::Index l) const {
    Vec3 r = positions_[static_cast<std::size_t>(l)] - positions_[static_cast<std::size_t>(k)];
    if (box_)
      for (int k = 0; k < 3; ++k) r[k] -= box_->lengths[k] * std::round(r[k] / box_->lengths[k]);
    return r.norm();
  }

  // Greedy colouring of the new members into new probes, members of one probe >= radius apart.
  void colour(std::size_t first_new, std::size_t first_probe) {
    for (std::size_t m = first_new; m < members_.size(); ++m) {
      bool placed = false;
      for (std::size_t c = first_probe; c < probes_.size() && !placed; ++c) {
        bool far = true;
        for (std::size_t other : probes_[c].members) far = far && distance(m, other) >= radius_;
        if (far) {
          probes_[c].members.push_back(m);
          placed = true;
        }
      }
      if (!placed) probes_.push_back({{m}, VecX()});
    }
  }

  // A from every probe's rows, then symmetrised (the true A is): the mean where both (r, c)
  // and (c, r) were read, the one read otherwise.
  void assemble() {
    const auto n = static_cast<Eigen::Index>(members_.size());
    constexpr double unread = std::numeric_limits<double>::quiet_NaN();
    MatX read = MatX::Constant(n, n, unread);
    for (const Probe& probe : probes_)
      for (Eigen::Index r = 0; r < n; ++r) {
        const std::optional<std::size_t> c = nearest_member(probe, members_[static_cast<std::size_t>(r)]);
        if (c) read(r, static_cast<Eigen::Index>(*c)) = probe.response(members_[static_cast<std::size_t>(r)]);
      }
    A_.resize(n, n);
    for (Eigen::Index r = 0; r < n; ++r)
      for (Eigen::Index c = 0; c < n; ++c) {
        const double rc = read(r, c), cr = read(c, r);
        A_(r, c) = std::isnan(rc) ? (std::isnan(cr) ? 0.0 : cr) : (std::isnan(cr) ? rc : 0.5 * (rc + cr));
      }
  }

  // The member of `probe` within radius / 2 of flagged pair k, if any (at most one is).
  std::optional<std::size_t> nearest_member(const Probe& probe, Eigen::Index k) const {
    for (std::size_t m : probe.members)
      if (2.0 * contact_distance(k, members_[m]) < radius_) return m;
    return std::nullopt;
  }

  double radius_;
  std::optional<PeriodicBox> box_;
  std::vector<Eigen::Index> members_;
  std::vector<Vec3> positions_;  // of every flagged pair
  std::vector<Probe> probes_;
  MatX A_;
};

}  // namespace stokescontact
