#pragma once
// A reproducible stream of standard normal variates from a 64-bit seed, for Brownian
// increments and random finite differences.
//
// Bits: std::mt19937_64, whose output sequence the C++ standard fixes for every library.
// Uniforms: the top 53 bits, u = bits * 2^-53 in [0, 1).
// Normals: Marsaglia's polar method (Marsaglia & Bray 1964): (x, y) uniform in the unit disc by
// rejection from the square, then x sqrt(-2 ln s / s), y sqrt(-2 ln s / s) with s = x^2 + y^2.
// The accept/reject test is exact IEEE arithmetic, so every library consumes the same bits for
// the same variates; the values differ at most by std::log's rounding (std::sqrt is correctly
// rounded), i.e. they are bit-identical wherever log is correctly rounded (glibc).
// std::normal_distribution is not used: its algorithm is left to each standard library, so a
// seed would give different trajectories under libstdc++, libc++ and MSVC.
#include <cmath>
#include <cstdint>
#include <ios>
#include <istream>
#include <ostream>
#include <random>

#include "stokescontact/core/types.hpp"

namespace stokescontact {

class GaussianStream {
 public:
  explicit GaussianStream(std::uint64_t seed) : engine_(seed), seed_(seed) {}

  // The next standard normal variate (the pair's second value is kept for the next call).
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double x = 0.0, y = 0.0, s = 0.0;
    do {  // uniform in [-1, 1)^2 until inside the unit disc, origin excluded (ln 0)
      x = 2.0 * uniform() - 1.0;
      y = 2.0 * uniform() - 1.0;
      s = x * x + y * y;
    } while (!(s < 1.0) || s == 0.0);
    const double factor = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = y * factor;
    has_spare_ = true;
    return x * factor;
  }

  // n consecutive variates, entry 0 first.
  VecX vector(Eigen::Index n) {
    VecX w(n);
    for (Eigen::Index i = 0; i < n; ++i) w(i) = (*this)();
    return w;
  }

  // The seed the stream started from (for reports and failure messages).
  std::uint64_t seed() const { return seed_; }

  // Two streams in the same state draw the same variates from here on.
  bool operator==(const GaussianStream&) const = default;

  // The whole state as text: the seed, the kept variate of the last pair, and the engine's
  // state (its standard text form, 312 words and the position in them). A stream read back
  // draws exactly what this one would draw next (io/checkpoint.hpp: a run continued later).
  friend std::ostream& operator<<(std::ostream& out, const GaussianStream& g) {
    const std::ios_base::fmtflags flags = out.flags();
    const std::streamsize precision = out.precision();
    out << std::dec << g.seed_ << ' ' << (g.has_spare_ ? 1 : 0) << ' ';
    out.precision(17);  // round trip of the double
    out << std::defaultfloat << g.spare_ << ' ' << g.engine_;
    out.flags(flags);
    out.precision(precision);
    return out;
  }

  // Reads what operator<< wrote; on malformed text the stream's failbit is set and `g` is
  // left as it was.
  friend std::istream& operator>>(std::istream& in, GaussianStream& g) {
    GaussianStream read(0);
    int has_spare = -1;
    in >> read.seed_ >> has_spare >> read.spare_ >> read.engine_;
    if (!in || (has_spare != 0 && has_spare != 1)) {
      in.setstate(std::ios_base::failbit);
      return in;
    }
    read.has_spare_ = has_spare == 1;
    g = read;
    return in;
  }

 private:
  // Uniform in [0, 1) from the top 53 bits: every double of the form k 2^-53.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

  std::mt19937_64 engine_;
  std::uint64_t seed_ = 0;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace stokescontact
