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
// With radius = infinity every probe has one member and A is exact (formed mode). In blocks
// mode (a block-diagonal model, ContactStep::sparse_MD) there are no probes: the columns of A
// are read exactly from M D, dt D^T (M D) e_c, at no application.
//
// Everything is sparse, so a working set of 1e5 contacts costs O(its size) in time and memory:
// the rows read (R, flagged pairs x working set) are kept only within radius / 2 of their
// column, found with a cell list, and exact zeros (free-draining bodies that share nothing)
// are not kept. A on the working set is R's member rows, symmetrised (reads are symmetric:
// r is read in c's probe exactly when c is in r's).
//
// Contacts sit at the midpoint of their closest points at Q*; distances between contacts use
// the minimum image in a periodic box.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Sparse>

#include "stokescontact/contact/contact_step.hpp"
#include "stokescontact/core/sparse_columns.hpp"
#include "stokescontact/geometry/broad_phase.hpp"

namespace stokescontact {

class DelassusProbing {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double>;

  // radius > 0 (may be infinite); the contacts are the step's flagged pairs.
  template <Shape S, MobilityOperator M>
  DelassusProbing(const ContactStep<S, M>& step, double radius)
      : radius_(radius), box_(step.problem().box), nc_(step.nc()) {
    if (!(radius > 0.0)) fail_argument("probe radius", "must be > 0, got " + std::to_string(radius));
    read_.resize(nc_, 0);
    positions_.resize(3, nc_);
    for (Eigen::Index k = 0; k < nc_; ++k) {
      const ContactPair& p = step.pairs()[static_cast<std::size_t>(k)];
      positions_.col(k) = p.points.point_a + 0.5 * p.points.distance * p.points.normal;
    }
    if (std::isfinite(radius)) {  // the rows each contact reads: the flagged pairs within radius / 2
      std::vector<std::vector<Eigen::Index>> near(static_cast<std::size_t>(nc_));
      for (const BodyPair& p : pairs_within(positions_, 0.5 * radius))
        if (2.0 * contact_distance(p.i, p.j) < radius_) {
          near[static_cast<std::size_t>(p.i)].push_back(p.j);
          near[static_cast<std::size_t>(p.j)].push_back(p.i);
        }
      near_start_.assign(1, 0);
      for (Eigen::Index k = 0; k < nc_; ++k) {
        near_.push_back(k);  // itself first
        near_.insert(near_.end(), near[static_cast<std::size_t>(k)].begin(), near[static_cast<std::size_t>(k)].end());
        near_start_.push_back(static_cast<Eigen::Index>(near_.size()));
      }
    }
  }

  // The working set: indices into step.pairs(), in the order they were added.
  const std::vector<Eigen::Index>& members() const { return members_; }
  // A on the working set (members() x members()), symmetric and sparse.
  const SparseMatrix& matrix() const { return A_; }
  int probes() const { return probes_; }

  // Row k of A on the working set, for any flagged pair k (member or not), read from the probes.
  VecX row(Eigen::Index k) const { return VecX(read_.row(k).transpose()); }

  // The read rows times a change of lambda on the working set: the model's change of every
  // flagged pair's distance (zero where nothing was read).
  VecX rows_times(const VecX& change_W) const { return read_ * change_W; }

  // Adds contacts (indices into step.pairs(), not yet members) and probes them: one call of
  // step.MD_times per new colour.
  template <Shape S, MobilityOperator M>
  void add(ContactStep<S, M>& step, std::span<const Eigen::Index> contacts) {
    if (contacts.empty()) return;
    const auto first_new = static_cast<Eigen::Index>(members_.size());
    members_.insert(members_.end(), contacts.begin(), contacts.end());
    if (const SparseMatrix* MD = step.sparse_MD()) {
      read_exact_columns(step.problem().dt, step.D(), *MD, first_new);
      assemble();
      return;
    }
    const std::vector<std::vector<Eigen::Index>> colours = colour(first_new);
    for (const std::vector<Eigen::Index>& members : colours) {
      VecX indicator = VecX::Zero(step.nc());
      for (Eigen::Index m : members) indicator(members_[static_cast<std::size_t>(m)]) = 1.0;
      const VecX response = step.A_times(indicator);
      for (Eigen::Index m : members) read_rows(m, response);
    }
    probes_ += static_cast<int>(colours.size());
    assemble();
  }

 private:
  // The columns of A = dt D^T (M D) for the members from first_new on, exact (blocks mode).
  void read_exact_columns(double dt, const SparseMatrix& D, const SparseMatrix& MD, Eigen::Index first_new) {
    const auto count = static_cast<Eigen::Index>(members_.size()) - first_new;
    const SparseMatrix MD_new = select_columns(MD, std::span<const Eigen::Index>(members_).subspan(static_cast<std::size_t>(first_new)));
    const SparseMatrix columns = dt * SparseMatrix(D.transpose() * MD_new);
    for (Eigen::Index m = 0; m < count; ++m)
      for (SparseMatrix::InnerIterator it(columns, m); it; ++it)
        if (it.value() != 0.0) read_triplets_.emplace_back(static_cast<int>(it.row()), static_cast<int>(first_new + m), it.value());
  }

  // Between flagged pairs k and l.
  double contact_distance(Eigen::Index k, Eigen::Index l) const {
    Vec3 r = positions_.col(l) - positions_.col(k);
    if (box_)
      for (int a = 0; a < 3; ++a) r[a] -= box_->lengths[a] * std::round(r[a] / box_->lengths[a]);
    return r.norm();
  }

  // Every pair of points (columns) within `cutoff` (minimum image in the box), a superset:
  // callers test the exact condition. A cell list where the box allows its cells, else all pairs.
  std::vector<BodyPair> pairs_within(const Mat3X& points, double cutoff) const {
    if (box_ && !(box_->lengths.minCoeff() >= cutoff)) {
      std::vector<BodyPair> all;
      for (Eigen::Index i = 0; i < points.cols(); ++i)
        for (Eigen::Index j = i + 1; j < points.cols(); ++j) all.push_back({i, j});
      return all;
    }
    CellList cells;
    return cells.find_pairs(points, 0.0, cutoff, box_);
  }

  // Greedy colouring of the new members (from first_new on) into new probes, members of one
  // probe >= radius apart: each takes the first colour no nearer member holds. Returns the
  // colours' members (positions in members_).
  std::vector<std::vector<Eigen::Index>> colour(Eigen::Index first_new) const {
    const auto count = static_cast<Eigen::Index>(members_.size()) - first_new;
    std::vector<std::vector<Eigen::Index>> colours;
    if (!std::isfinite(radius_)) {  // no two contacts are infinitely far apart
      for (Eigen::Index m = first_new; m < first_new + count; ++m) colours.push_back({m});
      return colours;
    }
    Mat3X points(3, count);
    for (Eigen::Index m = 0; m < count; ++m) points.col(m) = positions_.col(members_[static_cast<std::size_t>(first_new + m)]);
    std::vector<std::vector<Eigen::Index>> earlier(static_cast<std::size_t>(count));  // conflicts, earlier members
    for (const BodyPair& p : pairs_within(points, radius_))
      if (contact_distance(members_[static_cast<std::size_t>(first_new + p.i)],
                           members_[static_cast<std::size_t>(first_new + p.j)]) < radius_)
        earlier[static_cast<std::size_t>(p.j)].push_back(p.i);  // p.i < p.j
    std::vector<std::size_t> colour_of(static_cast<std::size_t>(count));
    std::vector<char> taken;
    for (Eigen::Index m = 0; m < count; ++m) {
      taken.assign(colours.size(), 0);
      for (Eigen::Index other : earlier[static_cast<std::size_t>(m)]) taken[colour_of[static_cast<std::size_t>(other)]] = 1;
      const std::size_t c = static_cast<std::size_t>(std::find(taken.begin(), taken.end(), 0) - taken.begin());
      if (c == colours.size()) colours.emplace_back();
      colours[c].push_back(first_new + m);
      colour_of[static_cast<std::size_t>(m)] = c;
    }
    return colours;
  }

  // The rows of member m's column in its probe's response: every flagged pair within radius /
  // 2 of it (all of them for an infinite radius), exact zeros left out.
  void read_rows(Eigen::Index m, const VecX& response) {
    const auto column = static_cast<int>(m);
    const auto keep = [&](Eigen::Index k) {
      if (response(k) != 0.0) read_triplets_.emplace_back(static_cast<int>(k), column, response(k));
    };
    if (!std::isfinite(radius_)) {
      for (Eigen::Index k = 0; k < nc_; ++k) keep(k);
      return;
    }
    const Eigen::Index contact = members_[static_cast<std::size_t>(m)];
    for (Eigen::Index q = near_start_[static_cast<std::size_t>(contact)];
         q < near_start_[static_cast<std::size_t>(contact) + 1]; ++q)
      keep(near_[static_cast<std::size_t>(q)]);
  }

  // R from the triplets read so far, and A = (R_W + R_W^T) / 2 on the working set (the true A
  // is symmetric; where only one of (r, c), (c, r) is nonzero the other was read as 0).
  void assemble() {
    const auto n = static_cast<Eigen::Index>(members_.size());
    read_.resize(nc_, n);
    read_.setFromTriplets(read_triplets_.begin(), read_triplets_.end());
    std::vector<Eigen::Index> position(static_cast<std::size_t>(nc_), -1);
    for (Eigen::Index r = 0; r < n; ++r) position[static_cast<std::size_t>(members_[static_cast<std::size_t>(r)])] = r;
    std::vector<Eigen::Triplet<double>> half;
    for (const Eigen::Triplet<double>& t : read_triplets_)
      if (const Eigen::Index r = position[static_cast<std::size_t>(t.row())]; r >= 0) {
        half.emplace_back(static_cast<int>(r), t.col(), 0.5 * t.value());
        half.emplace_back(t.col(), static_cast<int>(r), 0.5 * t.value());
      }
    A_.resize(n, n);
    A_.setFromTriplets(half.begin(), half.end());
  }

  double radius_;
  std::optional<PeriodicBox> box_;
  Eigen::Index nc_;
  Mat3X positions_;                       // of every flagged pair
  std::vector<Eigen::Index> near_, near_start_;  // per flagged pair: itself and those within radius / 2
  std::vector<Eigen::Index> members_;
  int probes_ = 0;
  std::vector<Eigen::Triplet<double>> read_triplets_;  // (flagged pair, member position, value)
  SparseMatrix read_;                     // R: flagged pairs x working set
  SparseMatrix A_;
};

}  // namespace stokescontact
