#pragma once
// Broad phase: every body pair whose bounding balls come within a cutoff, found with a cell
// list in O(N) for bounded density; open space or an orthorhombic periodic box.
#include <algorithm>
#include <array>
#include <cmath>
#include <compare>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/parallel_for.hpp"
#include "stokescontact/core/types.hpp"
#include "stokescontact/geometry/periodic_box.hpp"

namespace stokescontact {

// A candidate pair, i < j.
struct BodyPair {
  Eigen::Index i = 0;
  Eigen::Index j = 0;
  friend auto operator<=>(const BodyPair&, const BodyPair&) = default;
};

namespace detail {
// floor for |v| < 2^62, inline (std::floor is a library call without SSE4.1).
inline std::int64_t floor_to_int(double v) {
  const auto i = static_cast<std::int64_t>(v);
  return i - (static_cast<double>(i) > v);
}

// The candidate test on raw positions (open) or positions wrapped into the box (periodic).
template <bool Periodic>
inline bool within_reach(const double* xi, const double* xj, double ri, double rj,
                         double cutoff, const double* length) {
  double d[3];
  for (int k = 0; k < 3; ++k) {
    d[k] = xi[k] - xj[k];
    if constexpr (Periodic) {
      if (d[k] > 0.5 * length[k]) d[k] -= length[k];
      else if (d[k] < -0.5 * length[k]) d[k] += length[k];
    }
  }
  const double reach = (ri + rj) + cutoff;
  return d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= reach * reach;
}
}  // namespace detail

// The candidate predicate: |x_i - x_j| (minimum image when periodic) <= r_i + r_j + cutoff.
// CellList evaluates exactly this, bit for bit, so brute force over it is a reference.
inline bool is_candidate_pair(const Vec3& xi, const Vec3& xj, double ri, double rj,
                              double cutoff, const std::optional<PeriodicBox>& box = {}) {
  if (!box) return detail::within_reach<false>(xi.data(), xj.data(), ri, rj, cutoff, nullptr);
  const Vec3 wi = wrap_into_box(xi, *box), wj = wrap_into_box(xj, *box);
  return detail::within_reach<true>(wi.data(), wj.data(), ri, rj, cutoff, box->lengths.data());
}

// Cell list over body centres and bounding radii. Cells are at least the largest interaction
// range 2 max(r) + cutoff wide, and the grid holds at most 4N + 64 buckets: a side with more
// cells folds onto itself (cell index mod buckets, neighbours taken cyclically), so far
// outliers cost no memory and only add a few rejected checks. Each pair of neighbouring
// buckets is visited once, so each body pair is tested once. Buffers persist across calls.
//
// Kept candidates (a Verlet list): after keep_candidates(skin), a query over all bodies that
// cannot answer from kept candidates collects its pairs at cutoff + skin, keeps them with its
// positions x0 and radii r0 as the reference, and answers with those within its own cutoff.
// A later query (x, r, cutoff c) with as many bodies in the same space answers from the kept
// pairs, filtered by the same predicate, when no pair can be missing: a pair within reach at
// x has |x0_i - x0_j| <= |x_i - x_j| + delta_i + delta_j <= r0_i + r0_j + c + g_i + g_j, with
// delta_k = |x_k - x0_k - s| for any common shift s (the mean displacement: a shift changes
// no distance, also on the torus) and g_k = delta_k + r_k - r0_k; so c + g_(1) + g_(2) (the
// two largest) within the reference cutoff C = cutoff + skin, less a rounding allowance,
// means every such pair was kept. The answer is then the cell list's own, pair for pair.
// The bound is about the numbers given, not about which body they describe: it holds for
// any query, whatever its bodies (a subset, reordered), and a query that fails it collects
// afresh. O(N + kept pairs) instead of a bucket sort and the buckets' checks.
class CellList {
 public:
  // Keep candidates within `skin` beyond each full query's cutoff for later queries (see
  // above); 0 stops keeping them. Drops the kept reference.
  void keep_candidates(double skin) {
    require_non_negative(skin, "skin");
    skin_ = skin;
    forget_candidates();
  }
  void forget_candidates() {
    kept_.clear();
    kept_count_ = -1;
  }
  // Whether the last query answered from kept candidates; queries of this object so far (of
  // two bodies or more), and how many of them the kept candidates answered.
  bool last_query_reused() const { return reused_; }
  std::int64_t queries() const { return queries_; }
  std::int64_t reused_queries() const { return reused_queries_; }

  // All candidate pairs (i < j), lexicographically sorted; valid until the next call.
  const std::vector<BodyPair>& find_pairs(const Mat3X& positions, const VecX& radii, double cutoff,
                                          const std::optional<PeriodicBox>& box = {}) {
    return query(positions, radii, cutoff, box, nullptr);
  }

  // The candidate pairs of find_pairs that have a marked body (marked[i] != 0, one entry per
  // body), sorted as find_pairs sorts them: the same pairs, bit for bit the same test, from the
  // marked bodies' neighbourhoods only. O(N) to sort the bodies into buckets, then O(marked).
  const std::vector<BodyPair>& find_pairs_of(const Mat3X& positions, const VecX& radii, double cutoff,
                                             const std::optional<PeriodicBox>& box, std::span<const char> marked) {
    if (static_cast<Eigen::Index>(marked.size()) != positions.cols())
      fail_argument("marked", "has " + std::to_string(marked.size()) + " entries for " +
                                  std::to_string(positions.cols()) + " bodies");
    return query(positions, radii, cutoff, box, &marked);
  }

  // Equal bodies of bounding radius `radius`.
  const std::vector<BodyPair>& find_pairs(const Mat3X& positions, double radius, double cutoff,
                                          const std::optional<PeriodicBox>& box = {}) {
    require_non_negative(radius, "radius");
    equal_radii_.setConstant(positions.cols(), radius);
    return find_pairs(positions, equal_radii_, cutoff, box);
  }

  // Predicate evaluations in the last query; stays O(N) for bounded density.
  std::int64_t pair_checks() const { return pair_checks_; }
  // Buckets per side of the last grid (0 when N < 2).
  const std::array<std::int64_t, 3>& buckets_per_side() const { return n_; }

 private:
  // find_pairs (marked: none) or find_pairs_of.
  const std::vector<BodyPair>& query(const Mat3X& positions, const VecX& radii, double cutoff,
                                     const std::optional<PeriodicBox>& box, const std::span<const char>* marked) {
    double range = validate(positions, radii, cutoff, box);
    for (std::vector<BodyPair>& found : found_) found.clear();  // kept with their capacity
    pairs_.clear();
    pair_checks_ = 0;
    reused_ = false;
    if (positions.cols() < 2) {
      n_ = {0, 0, 0};
      return pairs_;
    }
    ++queries_;
    if (covered_by_kept(positions, radii, cutoff, box)) {
      filter_kept(positions, radii, cutoff, box, marked);
      reused_ = true;
      ++reused_queries_;
      return pairs_;
    }
    n_ = {0, 0, 0};
    // A full query keeps a new reference, if its reach fits the box.
    const double kept_cutoff = cutoff + skin_;
    const bool keep = skin_ > 0.0 && !marked && (!box || range + skin_ <= 0.5 * box->lengths.minCoeff());
    if (keep) range += skin_;
    build(positions, radii, range, box);
    const double collect_cutoff = keep ? kept_cutoff : cutoff;
    const Vec3 length = box ? box->lengths : Vec3::Zero();
    if (marked) {
      if (box) collect_marked<true>(collect_cutoff, length, *marked);
      else collect_marked<false>(collect_cutoff, length, *marked);
    } else {
      if (box) collect<true>(collect_cutoff, length);
      else collect<false>(collect_cutoff, length);
    }
    sort_pairs(positions.cols());
    if (keep) {
      kept_.swap(pairs_);
      kept_x_ = positions;
      kept_r_ = radii;
      kept_cutoff_ = kept_cutoff;
      kept_box_ = box;
      kept_count_ = positions.cols();
      filter_kept(positions, radii, cutoff, box, nullptr);
    }
    return pairs_;
  }

  // Whether the kept reference holds every pair of this query (the bound above).
  bool covered_by_kept(const Mat3X& x, const VecX& r, double cutoff, const std::optional<PeriodicBox>& box) const {
    if (kept_count_ != x.cols() || box.has_value() != kept_box_.has_value()) return false;
    if (box && box->lengths != kept_box_->lengths) return false;
    const Vec3 shift = (x - kept_x_).rowwise().mean();
    double g1 = -std::numeric_limits<double>::infinity(), g2 = g1, scale = kept_cutoff_ + cutoff;
    for (Eigen::Index k = 0; k < x.cols(); ++k) {
      const double g = (x.col(k) - kept_x_.col(k) - shift).norm() + (r[k] - kept_r_[k]);
      if (g > g2) {
        g2 = std::min(g, g1);
        g1 = std::max(g, g1);
      }
      scale = std::max({scale, x.col(k).cwiseAbs().maxCoeff(), kept_x_.col(k).cwiseAbs().maxCoeff(), r[k], kept_r_[k]});
    }
    if (box) scale = std::max(scale, box->lengths.maxCoeff());
    // Rounding: coordinates, their differences and the squared test err by a few ulps of scale.
    return cutoff + g1 + g2 <= kept_cutoff_ - 1e-12 * scale;
  }

  // The kept pairs that pass this query's test (and have a marked body, if marked), in the
  // kept (sorted) order, in chunks (collect_in_chunks) joined in order.
  void filter_kept(const Mat3X& x, const VecX& r, double cutoff, const std::optional<PeriodicBox>& box,
                   const std::span<const char>* marked) {
    const Mat3X* p = &x;
    if (box) {
      wrapped_.resize(3, x.cols());
      parallel_for(x.cols(), [&](std::ptrdiff_t i) { wrapped_.col(i) = wrap_into_box(x.col(i), *box); });
      p = &wrapped_;
    }
    const Vec3 length = box ? box->lengths : Vec3::Zero();
    const auto n = static_cast<std::int64_t>(kept_.size());
    for (std::vector<BodyPair>& found : found_) found.clear();
    collect_in_chunks(n, [&](std::int64_t first, std::int64_t last, std::vector<BodyPair>& found, std::int64_t& checks) {
      for (std::int64_t k = first; k < last; ++k) {
        const BodyPair q = kept_[static_cast<std::size_t>(k)];
        if (marked && !(*marked)[static_cast<std::size_t>(q.i)] && !(*marked)[static_cast<std::size_t>(q.j)]) continue;
        ++checks;
        const bool in = box ? detail::within_reach<true>(p->col(q.i).data(), p->col(q.j).data(), r[q.i], r[q.j],
                                                         cutoff, length.data())
                            : detail::within_reach<false>(p->col(q.i).data(), p->col(q.j).data(), r[q.i], r[q.j],
                                                          cutoff, nullptr);
        if (in) found.push_back(q);
      }
    });
    std::size_t total = 0;
    for (const std::vector<BodyPair>& found : found_) total += found.size();
    pairs_.clear();
    pairs_.reserve(total);
    for (const std::vector<BodyPair>& found : found_) pairs_.insert(pairs_.end(), found.begin(), found.end());
  }

  static double validate(const Mat3X& x, const VecX& radii, double cutoff,
                         const std::optional<PeriodicBox>& box) {
    for (Eigen::Index i = 0; i < x.cols(); ++i)  // name the body, not the whole matrix
      if (!x.col(i).allFinite()) fail_argument("positions", "column " + std::to_string(i) + " must be finite");
    if (radii.size() != x.cols()) fail_argument("radii", "size must equal the number of positions");
    for (Eigen::Index i = 0; i < radii.size(); ++i)
      if (!(std::isfinite(radii[i]) && radii[i] >= 0.0))
        fail_argument("radii", "entry " + std::to_string(i) + " must be finite and >= 0, got " +
                                   std::to_string(radii[i]));
    require_non_negative(cutoff, "cutoff");
    const double rho_max = radii.size() > 0 ? radii.maxCoeff() : 0.0;
    const double range = (rho_max + rho_max) + cutoff;  // same rounding order as within_reach
    if (box) {
      for (int k = 0; k < 3; ++k) require_positive(box->lengths[k], "PeriodicBox.lengths");
      if (range > 0.5 * box->lengths.minCoeff())  // else the minimum image is ambiguous
        fail_argument("PeriodicBox.lengths", "must be >= 2 (2 max radius + cutoff) = " +
                                                 std::to_string(2.0 * range));
    }
    return range;
  }

  // Buckets per side: the natural cell counts, cut (smallest side first) to at most
  // `budget` buckets in all.
  static std::array<std::int64_t, 3> fit_buckets(const std::array<std::int64_t, 3>& cells,
                                                 double budget) {
    std::array<int, 3> order = {0, 1, 2};
    std::sort(order.begin(), order.end(), [&](int a, int b) { return cells[a] < cells[b]; });
    std::array<std::int64_t, 3> n{};
    for (int r = 0; r < 3; ++r) {
      const double share = std::floor(std::pow(budget, 1.0 / (3 - r)) + 1e-9);
      n[order[r]] = std::clamp(static_cast<std::int64_t>(share), std::int64_t{1}, cells[order[r]]);
      budget /= static_cast<double>(n[order[r]]);
    }
    return n;
  }

  // Open space: cell c = K M + f with K = floor(x / H) for a power of two H (exact) and
  // f = floor((x - K H) M / H), whose rounding (~1e-14 cells) does not grow with |x|; the
  // cells H / M are then at least the range whatever the coordinates. K is clamped far out,
  // where ulp(x) > H keeps distinct coordinates out of reach anyway.
  void set_open_grid(double range) {
    const double padded = std::max(range * (1 + 1e-12), 0x1p-900);  // the pad absorbs rounding
    single_cell_ = !(padded <= 0x1p900);  // a reach near overflow: one cell holds everything
    if (single_cell_) return;
    int e = 0;
    std::frexp(64.0 * padded, &e);
    coarse_ = std::ldexp(1.0, e);  // H in (64, 128] ranges, so H / M is within 1.6% of the range
    inv_coarse_ = std::ldexp(1.0, -e);
    fine_ = static_cast<std::int64_t>(std::floor(coarse_ / padded));
    fine_scale_ = static_cast<double>(fine_) * inv_coarse_;  // M / H, exact
  }

  // (K, f) of an open-space coordinate; c = K M + f with f in [-1, M].
  std::pair<std::int64_t, std::int64_t> open_cell(double x) const {
    const double t = x * inv_coarse_;  // exact: a power of two
    if (!(std::abs(t) < 0x1p62)) return {x < 0 ? -(std::int64_t{1} << 62) : std::int64_t{1} << 62, 0};
    const std::int64_t key = detail::floor_to_int(t);
    return {key, detail::floor_to_int((x - static_cast<double>(key) * coarse_) * fine_scale_)};
  }

  // Bucket along side k: cell index mod n_[k] (a shift when the side is not folded).
  std::int64_t side_bucket(int k, double x) const {
    const std::int64_t n = n_[k];
    const bool folded = n < cells_[k];
    if (periodic_) {  // w * scale may round up to cells
      const std::int64_t c = std::clamp(detail::floor_to_int(x * scale_[k]), std::int64_t{0}, cells_[k] - 1);
      return folded ? c % n : c;
    }
    if (single_cell_) return 0;
    const auto [key, f] = open_cell(x);
    if (!folded) return (key - low_[k].first) * fine_ + (f - low_[k].second) + 2;  // c >= c(low) - 1
    const std::int64_t key_mod = (key % n + n) % n;
    return (key_mod * fine_ + f + n) % n;  // f >= -1: the sum is positive
  }

  void build(const Mat3X& x, const VecX& radii, double range, const std::optional<PeriodicBox>& box) {
    const Eigen::Index count = x.cols();
    periodic_ = box.has_value();
    if (box) {
      wrapped_.resize(3, count);
      for (Eigen::Index i = 0; i < count; ++i) wrapped_.col(i) = wrap_into_box(x.col(i), *box);
    } else {
      set_open_grid(range);
    }
    const Mat3X& p = box ? wrapped_ : x;
    for (int k = 0; k < 3; ++k) {
      if (box) {  // w in [0, L) rounds by ~1e-16 L: the pad 4e-15 L keeps pairs in adjacent cells
        const double length = box->lengths[k];
        cells_[k] = static_cast<std::int64_t>(std::floor(length / (range * (1 + 1e-12) + 4e-15 * length)));
      } else if (single_cell_) {
        cells_[k] = 1;
      } else {  // occupied span; +4 as (K, f) order may miss c by 1 at each end and an
                // unfolded side must keep empty buckets between its ends. (K, f) is
                // non-decreasing in x (lexicographically: K = floor(x / H), and within one K
                // f = floor((x - K H) M / H), each step a rounded monotone map), so the span's
                // ends are the cells of the least and the greatest coordinate.
        const auto lo = open_cell(p.row(k).minCoeff()), hi = open_cell(p.row(k).maxCoeff());
        const double span = static_cast<double>(hi.first - lo.first) * static_cast<double>(fine_) +
                            static_cast<double>(hi.second - lo.second) + 1.0;
        cells_[k] = static_cast<std::int64_t>(std::min(span + 4.0, 0x1p62));
        low_[k] = lo;
      }
    }
    n_ = fit_buckets(cells_, 4.0 * static_cast<double>(count) + 64.0);
    if (box) {
      for (int k = 0; k < 3; ++k) {  // a multiple of n, so the seam folds onto buckets n-1 | 0
        cells_[k] = n_[k] * (cells_[k] / n_[k]);
        scale_[k] = static_cast<double>(cells_[k]) / box->lengths[k];
      }
    }

    // Counting sort of the bodies by bucket.
    const std::int64_t buckets = n_[0] * n_[1] * n_[2];
    bucket_.resize(static_cast<std::size_t>(count));
    start_.assign(static_cast<std::size_t>(buckets + 1), 0);
    parallel_for(count, [&](std::ptrdiff_t i) {
      bucket_[static_cast<std::size_t>(i)] =
          side_bucket(0, p(0, i)) + n_[0] * (side_bucket(1, p(1, i)) + n_[1] * side_bucket(2, p(2, i)));
    });
    for (const std::int64_t b : bucket_) ++start_[static_cast<std::size_t>(b + 1)];
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    id_.resize(static_cast<std::size_t>(count));
    pos_.resize(3, count);
    rad_.resize(count);
    for (Eigen::Index i = 0; i < count; ++i) {
      const Eigen::Index slot = start_[static_cast<std::size_t>(bucket_[static_cast<std::size_t>(i)])]++;
      id_[static_cast<std::size_t>(slot)] = i;
      pos_.col(slot) = p.col(i);
      rad_[slot] = radii[i];
    }
    std::rotate(start_.rbegin(), start_.rbegin() + 1, start_.rend());  // back to bucket starts
    start_[0] = 0;
  }

  // Distinct buckets within one of b, cyclically, along a side of n (fewer than 3 if n < 3).
  static int neighbours(std::int64_t b, std::int64_t n, std::int64_t out[3]) {
    const std::int64_t candidates[3] = {b == 0 ? n - 1 : b - 1, b, b + 1 == n ? 0 : b + 1};
    int m = 0;
    for (const std::int64_t c : candidates)
      if (std::find(out, out + m, c) == out + m) out[m++] = c;
    return m;
  }

  // `part(first, last, found, checks)` over the items [0, count) in chunks, each chunk's pairs
  // in its own buffer of found_ (their order does not matter: sort_pairs sorts them all) and
  // its checks added up after; the chunks run on OpenMP threads (parallel_for) from
  // kParallelForMinCount bodies on, so the pairs and their order are those of one thread.
  template <class Part>
  void collect_in_chunks(std::int64_t count, Part&& part) {
    const std::int64_t chunks = pos_.cols() >= kParallelForMinCount ? std::clamp<std::int64_t>(count, 1, 64) : 1;
    if (found_.size() < static_cast<std::size_t>(chunks)) found_.resize(static_cast<std::size_t>(chunks));
    chunk_checks_.assign(static_cast<std::size_t>(chunks), 0);
    parallel_for(
        chunks,
        [&](std::ptrdiff_t c) {
          std::vector<BodyPair>& found = found_[static_cast<std::size_t>(c)];
          found.clear();
          part(count * c / chunks, count * (c + 1) / chunks, found, chunk_checks_[static_cast<std::size_t>(c)]);
        },
        2);
    for (const std::int64_t checks : chunk_checks_) pair_checks_ += checks;
  }

  // Each unordered pair of neighbouring buckets once, from the lower index (rows of x-adjacent
  // buckets compared first), so each body pair is tested once even on sides of 1 or 2 buckets.
  // Bodies are in bucket order, x fastest: an inner run bx-1..bx+1 of a row is one range.
  // Rows (by, bz) in chunks (collect_in_chunks).
  template <bool Periodic>
  void collect(double cutoff, const Vec3& length) {
    collect_in_chunks(n_[1] * n_[2], [&](std::int64_t first_row, std::int64_t last_row, std::vector<BodyPair>& found,
                                         std::int64_t& checks) {
      auto cross = [&](Eigen::Index begin, Eigen::Index end, Eigen::Index other, Eigen::Index other_end) {
        checks += (end - begin) * (other_end - other);
        for (Eigen::Index a = begin; a < end; ++a)
          for (Eigen::Index c = std::max(other, a + 1); c < other_end; ++c)
            if (detail::within_reach<Periodic>(pos_.col(a).data(), pos_.col(c).data(), rad_[a], rad_[c], cutoff,
                                               length.data())) {
              const Eigen::Index i = id_[static_cast<std::size_t>(a)], j = id_[static_cast<std::size_t>(c)];
              found.push_back(i < j ? BodyPair{i, j} : BodyPair{j, i});
            }
      };
      auto at = [&](std::int64_t bucket) { return start_[static_cast<std::size_t>(bucket)]; };
      const std::int64_t sx = n_[0];
      std::int64_t nx[3], ny[3], nz[3];
      for (std::int64_t row = first_row; row < last_row; ++row) {
        const std::int64_t by = row % n_[1], bz = row / n_[1];
        const int mz = neighbours(bz, n_[2], nz);
        const int my = neighbours(by, n_[1], ny);
        for (std::int64_t bx = 0; bx < sx; ++bx) {
          const std::int64_t b = bx + sx * row;
          const Eigen::Index begin = at(b), end = at(b + 1);
          if (begin == end) continue;
          const int mx = neighbours(bx, sx, nx);
          const bool inner = bx >= 1 && bx + 1 < sx;
          cross(begin, end, begin, end);  // within the bucket: c > a
          checks -= (end - begin) * (end - begin + 1) / 2;  // counted pairs c > a only
          for (int z = 0; z < mz; ++z)
            for (int y = 0; y < my; ++y) {
              const std::int64_t other = ny[y] + n_[1] * nz[z];
              if (other < row) continue;
              if (other == row || !inner) {
                for (int x = 0; x < mx; ++x)
                  if (other > row || nx[x] > bx) cross(begin, end, at(nx[x] + sx * other), at(nx[x] + sx * other + 1));
              } else {
                cross(begin, end, at(bx - 1 + sx * other), at(bx + 2 + sx * other));
              }
            }
        }
      }
    });
  }

  // find_pairs_of's search: each marked body against every body of the (up to 27) buckets
  // around its own, a pair of two marked bodies from the lower index only. within_reach is
  // symmetric bit for bit (d and -d square alike, the minimum image flips with the sign), so
  // a pair passes here exactly when collect passes it. Bodies in bucket order (neighbouring
  // marked bodies read the same buckets: at 1e5 spheres in the packing's order, body order
  // read them scattered over memory), in chunks (collect_in_chunks).
  template <bool Periodic>
  void collect_marked(double cutoff, const Vec3& length, std::span<const char> marked) {
    const auto is_marked = [&](Eigen::Index k) { return marked[static_cast<std::size_t>(k)] != 0; };
    const auto part = [&](std::int64_t first, std::int64_t last, std::vector<BodyPair>& found, std::int64_t& checks) {
      const std::int64_t sx = n_[0], sy = n_[1];
      std::int64_t nx[3], ny[3], nz[3];
      for (Eigen::Index a = first; a < last; ++a) {  // slots: the bodies in bucket order
        const Eigen::Index i = id_[static_cast<std::size_t>(a)];
        if (!is_marked(i)) continue;
        const std::int64_t b = bucket_[static_cast<std::size_t>(i)];
        const int mx = neighbours(b % sx, sx, nx);
        const int my = neighbours((b / sx) % sy, sy, ny);
        const int mz = neighbours(b / (sx * sy), n_[2], nz);
        for (int z = 0; z < mz; ++z)
          for (int y = 0; y < my; ++y)
            for (int x = 0; x < mx; ++x) {
              const std::int64_t other = nx[x] + sx * (ny[y] + sy * nz[z]);
              const Eigen::Index end = start_[static_cast<std::size_t>(other + 1)];
              for (Eigen::Index c = start_[static_cast<std::size_t>(other)]; c < end; ++c) {
                const Eigen::Index j = id_[static_cast<std::size_t>(c)];
                if (j == i || (is_marked(j) && j < i)) continue;
                ++checks;
                if (detail::within_reach<Periodic>(pos_.col(a).data(), pos_.col(c).data(), rad_[a], rad_[c], cutoff,
                                                   length.data()))
                  found.push_back(i < j ? BodyPair{i, j} : BodyPair{j, i});
              }
            }
      }
    };
    collect_in_chunks(static_cast<std::int64_t>(marked.size()), part);
  }

  // Counting sort by i, then a (short) sort of each i's partners: O(pairs + N).
  void sort_pairs(Eigen::Index count) {
    first_.assign(static_cast<std::size_t>(count + 1), 0);
    std::size_t total = 0;
    for (const std::vector<BodyPair>& found : found_) {
      total += found.size();
      for (const BodyPair& q : found) ++first_[static_cast<std::size_t>(q.i + 1)];
    }
    std::partial_sum(first_.begin(), first_.end(), first_.begin());
    pairs_.resize(total);
    for (const std::vector<BodyPair>& found : found_)
      for (const BodyPair& q : found) pairs_[static_cast<std::size_t>(first_[static_cast<std::size_t>(q.i)]++)] = q;
    auto begin = pairs_.begin();  // first_[i] is now the end of i's run
    for (Eigen::Index i = 0; i < count; ++i) {
      const auto end = pairs_.begin() + first_[static_cast<std::size_t>(i)];
      std::sort(begin, end);
      begin = end;
    }
  }

  // Kept candidates (keep_candidates): the reference's pairs, positions, radii, cutoff and box.
  double skin_ = 0.0;
  std::vector<BodyPair> kept_;
  Mat3X kept_x_;
  VecX kept_r_;
  double kept_cutoff_ = 0.0;
  std::optional<PeriodicBox> kept_box_;
  Eigen::Index kept_count_ = -1;  // bodies of the reference; -1: none kept
  bool reused_ = false;
  std::int64_t queries_ = 0, reused_queries_ = 0;
  // Per chunk of a query, in bucket order; buffers beyond the query's chunks stay empty, and
  // all keep their capacity across queries.
  std::vector<std::vector<BodyPair>> found_;
  std::vector<BodyPair> pairs_;               // sorted
  std::vector<std::int64_t> chunk_checks_;
  std::int64_t pair_checks_ = 0;
  std::array<std::int64_t, 3> n_{}, cells_{};  // buckets and (unfolded) cells per side
  std::array<double, 3> scale_{};              // periodic: cells per unit length
  bool periodic_ = false, single_cell_ = false;
  double coarse_ = 1.0, inv_coarse_ = 1.0;     // open: H, a power of two, and 1 / H
  std::int64_t fine_ = 1;                      // open: M cells per H
  double fine_scale_ = 1.0;                    // open: M / H
  std::array<std::pair<std::int64_t, std::int64_t>, 3> low_{};  // open: least (K, f) per side
  VecX equal_radii_, rad_;                    // rad_: radii in bucket order
  Mat3X wrapped_, pos_;                       // pos_: positions in bucket order
  std::vector<std::int64_t> bucket_, start_;  // bucket of each body; first body of each bucket
  std::vector<Eigen::Index> id_, first_;      // body id in bucket order; pair runs by i
};

// One-shot query; see CellList::find_pairs.
inline std::vector<BodyPair> candidate_pairs(const Mat3X& positions, const VecX& radii, double cutoff,
                                             const std::optional<PeriodicBox>& box = {}) {
  CellList cells;
  return cells.find_pairs(positions, radii, cutoff, box);
}

inline std::vector<BodyPair> candidate_pairs(const Mat3X& positions, double radius, double cutoff,
                                             const std::optional<PeriodicBox>& box = {}) {
  CellList cells;
  return cells.find_pairs(positions, radius, cutoff, box);
}

}  // namespace stokescontact
