#pragma once
// Running mean of a correlated series with its error bar by block averaging (Flyvbjerg &
// Petersen, J. Chem. Phys. 91, 461 (1989)), on line, in O(dim log n) memory.
//
// Level 0 holds the samples x_1, x_2, ...; level l + 1 the averages of neighbouring pairs of
// level l (an unpaired last block waits for its partner; at the end it is left out, as the
// paper drops it). With n_l blocks at level l and their sample variance v_l (Welford's
// update, 1/(n_l - 1)), the standard error of the mean estimated there is
//     se_l = sqrt(v_l / n_l),   with its own error  se_l / sqrt(2 (n_l - 1)).
// For correlated samples se_l grows with l until the blocks (2^l samples) are much longer
// than the correlation time, then stays on a plateau, the error bar sought, while its noise
// grows as the blocks get fewer.
//
// The plateau level, per component (correlation times differ between components):
//   the smallest l with at least min_blocks blocks and (2^l)^3 > 2 n (se_l / se_0)^4,
// the criterion of Lee et al. (Phys. Rev. E 83, 066706, 2011; used by pyblock): with
// (se_l / se_0)^2 ~ 2 tau_int it picks blocks of about (4 n tau_int^2)^(1/3) samples, long
// against tau_int and short enough to leave many blocks. If no level with min_blocks blocks
// meets it, the series is too short to resolve its correlations: the last level with
// min_blocks blocks is reported (or level 0 when none has) and `converged` is false.
// The mean is the plain mean of all samples. min_blocks defaults to 32.
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

// One level of the blocking transformation.
struct BlockLevel {
  std::size_t block_size = 1;  // samples per block, 2^l
  std::size_t blocks = 0;      // n_l
  VecX std_error;              // se_l per component (0 with fewer than 2 blocks)
  VecX std_error_error;        // se_l / sqrt(2 (n_l - 1))
};

struct BlockAverageResult {
  std::size_t samples = 0;
  VecX mean;                    // of all samples
  VecX std_error;               // the plateau's se, per component
  VecX std_error_error;         // its error
  std::vector<std::size_t> level;  // the plateau level per component
  std::vector<bool> converged;     // per component: the plateau criterion was met
  std::vector<BlockLevel> levels;  // every level with at least 2 blocks

  bool all_converged() const {
    for (bool c : converged)
      if (!c) return false;
    return true;
  }
};

// Samples of a fixed dimension (set by the first sample, or by the constructor).
class BlockAverage {
 public:
  explicit BlockAverage(std::size_t min_blocks = 32) : min_blocks_(min_blocks) {
    if (min_blocks < 2) fail_argument("min_blocks", "must be >= 2, got " + std::to_string(min_blocks));
  }

  void add(const VecX& x) {
    if (x.size() == 0) fail_argument("sample", "must have at least one component");
    if (samples_ == 0) dim_ = x.size();
    if (x.size() != dim_)
      fail_argument("sample", "has " + std::to_string(x.size()) + " components, expected " + std::to_string(dim_));
    require_finite(x, "sample");
    ++samples_;
    push(0, x);
  }
  void add(double x) { add(VecX::Constant(1, x)); }
  // A 3x3 tensor, component (r, c) at index 3 c + r (column major, as Eigen stores it).
  void add_tensor(const Mat3& x) { add(VecX(Eigen::Map<const VecX>(x.data(), 9))); }

  std::size_t samples() const { return samples_; }
  Eigen::Index dimension() const { return dim_; }

  // Throws std::invalid_argument naming "samples" with fewer than 2 samples.
  BlockAverageResult result() const {
    if (samples_ < 2)
      fail_argument("samples", "block averaging needs at least 2 samples, got " + std::to_string(samples_));
    BlockAverageResult r;
    r.samples = samples_;
    r.mean = levels_[0].mean;
    for (std::size_t l = 0; l < levels_.size() && levels_[l].count >= 2; ++l) {
      const Level& s = levels_[l];
      const double n = static_cast<double>(s.count);
      BlockLevel b;
      b.block_size = std::size_t{1} << l;
      b.blocks = s.count;
      b.std_error = (s.m2 / (n - 1.0) / n).cwiseSqrt();
      b.std_error_error = b.std_error / std::sqrt(2.0 * (n - 1.0));
      r.levels.push_back(std::move(b));
    }
    const VecX& se0 = r.levels[0].std_error;
    const double n = static_cast<double>(samples_);
    r.std_error.resize(dim_);
    r.std_error_error.resize(dim_);
    for (Eigen::Index c = 0; c < dim_; ++c) {
      std::size_t pick = 0;
      bool found = false;
      for (std::size_t l = 0; l < r.levels.size() && r.levels[l].blocks >= min_blocks_; ++l) {
        pick = l;
        const double b = static_cast<double>(r.levels[l].block_size);
        const double ratio = se0(c) > 0.0 ? r.levels[l].std_error(c) / se0(c) : 1.0;
        if (b * b * b > 2.0 * n * ratio * ratio * ratio * ratio) {
          found = true;
          break;
        }
      }
      r.level.push_back(pick);
      r.converged.push_back(found);
      r.std_error(c) = r.levels[pick].std_error(c);
      r.std_error_error(c) = r.levels[pick].std_error_error(c);
    }
    return r;
  }

 private:
  struct Level {
    std::size_t count = 0;
    VecX mean;
    VecX m2;  // sum of squared deviations from the mean
    VecX pending;
    bool has_pending = false;
  };

  void push(std::size_t l, const VecX& x) {
    if (levels_.size() == l) levels_.push_back({0, VecX::Zero(dim_), VecX::Zero(dim_), VecX(), false});
    Level& s = levels_[l];
    ++s.count;
    const VecX delta = x - s.mean;
    s.mean += delta / static_cast<double>(s.count);
    s.m2 += delta.cwiseProduct(x - s.mean);
    if (!s.has_pending) {
      s.pending = x;
      s.has_pending = true;
      return;
    }
    s.has_pending = false;
    const VecX pair = 0.5 * (s.pending + x);
    push(l + 1, pair);  // s is not used after this: levels_ may reallocate
  }

  std::size_t min_blocks_ = 32;
  std::size_t samples_ = 0;
  Eigen::Index dim_ = 0;
  std::vector<Level> levels_;
};

}  // namespace stokescontact
