#pragma once
// The Rotne-Prager-Yamakawa direct sum U = M F over all pairs of n equal blobs (or spheres),
// matrix-free, O(n^2): the one production RPY sum, behind RpyMobility (3 or 6 dofs per
// sphere) and the rigid multiblob blob product (3 dofs per blob, blob_rpy.hpp).
//
// Blob units: positions in blob radii a; forces f, torques tau / a; velocities u, angular
// velocities omega a; M in units of mu0 = 1 / (6 pi eta a). With r = x_i - x_j, the pair
// blocks of rpy_kernel.hpp and rpy_rotation_kernel.hpp (Wajnryb et al., J. Fluid Mech. 731,
// R3, 2013, overlap branches included; r = 0 gives the self mobility) become
//   u_i     += tt_f f_j + tt_h (r . f_j) r + rt (tau_j x r)
//   omega_i += rt (f_j x r) + rr_f tau_j + rr_h (r . tau_j) r
// with the coefficients of rpy_pair_terms below.
//
// How it runs: blobs in blocks of at most kRpyBlock, each stored as a structure of arrays.
// A tile couples two blocks; each pair of an off-diagonal tile (I < J) is evaluated once and
// acts both ways (the (j, i) block of M is the (i, j) block transposed), which halves the
// pair work. OpenMP threads share out the block rows I: row I sums its own tiles in order into
// block I and writes each tile's part for block J to a buffer of its own; the buffers are
// then added to block J in order of I. Every blob thus sums its sources in one order,
// whatever the thread count, with one barrier per panel of rows. The tile loop is branch-free
// arithmetic the compiler vectorises; on x86 it is compiled for the baseline instruction
// set, for AVX2 + FMA and for AVX-512, and the widest the CPU supports runs (the choice
// changes results only by rounding). Users need no special flags for the speed.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/types.hpp"

// Runtime instruction-set dispatch: GCC and Clang on x86-64.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define STOKESCONTACT_RPY_DISPATCH 1
#else
#define STOKESCONTACT_RPY_DISPATCH 0
#endif

namespace stokescontact {

// The instruction sets the tile loop is compiled for; results agree to rounding.
enum class RpyInstructionSet { baseline, avx2_fma, avx512 };

inline const char* rpy_instruction_set_name(RpyInstructionSet isa) {
  switch (isa) {
    case RpyInstructionSet::avx2_fma:
      return "avx2_fma";
    case RpyInstructionSet::avx512:
      return "avx512";
    default:
      return "baseline";
  }
}

// Whether this CPU runs `isa` (baseline always).
inline bool rpy_instruction_set_supported(RpyInstructionSet isa) {
#if STOKESCONTACT_RPY_DISPATCH
  __builtin_cpu_init();
  switch (isa) {
    case RpyInstructionSet::avx2_fma:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case RpyInstructionSet::avx512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("fma");
    default:
      return true;
  }
#else
  return isa == RpyInstructionSet::baseline;
#endif
}

// The widest supported instruction set, detected once.
inline RpyInstructionSet rpy_best_instruction_set() {
  static const RpyInstructionSet best = [] {
    for (const auto isa : {RpyInstructionSet::avx512, RpyInstructionSet::avx2_fma})
      if (rpy_instruction_set_supported(isa)) return isa;
    return RpyInstructionSet::baseline;
  }();
  return best;
}

namespace detail {

// 1/sqrt(x) for normal x > 0: four Newton steps y <- y (3/2 - x y^2 / 2) from the bit-level
// estimate (Lomont's constant, relative error < 3.5e-2; each step about squares it), a few
// ulp in the end. Plain arithmetic: GCC does not vectorise std::sqrt under -fmath-errno.
[[gnu::always_inline]] inline double inverse_sqrt(double x) {
  double y = std::bit_cast<double>(std::uint64_t{0x5fe6eb50c7b537a9} - (std::bit_cast<std::uint64_t>(x) >> 1));
  const double half_x = 0.5 * x;
  y *= 1.5 - half_x * y * y;
  y *= 1.5 - half_x * y * y;
  y *= 1.5 - half_x * y * y;
  y *= 1.5 - half_x * y * y;
  return y;
}

// mask ? a : b bit by bit, mask all ones or all zeros: GCC if-converts a floating-point ?:
// in a loop only where the vector unit has masks (AVX-512); this vectorises everywhere.
[[gnu::always_inline]] inline double select(std::uint64_t mask, double a, double b) {
  return std::bit_cast<double>((std::bit_cast<std::uint64_t>(a) & mask) | (std::bit_cast<std::uint64_t>(b) & ~mask));
}

// The pair coefficients in blob units for r2 = |x_i - x_j|^2 (the equations at the top):
// rpy_translation_coefficients (f, g) and rpy_rotation_coefficients (w, f_r, g_r) at t = r
// as tt_f = f, tt_h = g / r^2, rt = (3/4) w / r, rr_f = (3/4) f_r, rr_h = (3/4) g_r / r^2
// (mu_rt / mu0 = 3 / (4a), mu_r / mu0 = 3 / (4a^2)). Both branches are evaluated and one is
// selected, without branching: far for r > 2, near for r <= 2. r2 is lifted by 1e-60, so
// r = 0 (the self term) gives finite terms that multiply r = 0, and 1/r^5 <= 1e150 stays
// finite in both branches; the lift changes r2 by less than rounding for r > 1e-22.
struct RpyPairTerms {
  double tt_f, tt_h, rt, rr_f, rr_h;
};

template <bool Rotation>
[[gnu::always_inline]] inline RpyPairTerms rpy_pair_terms(double r2) {
  const double s = inverse_sqrt(r2 + 1e-60), s2 = s * s, s3 = s2 * s, r = r2 * s;  // s = 1/r
  const std::uint64_t far = std::uint64_t{0} - (std::bit_cast<std::uint64_t>(4.0 - r2) >> 63);  // r > 2
  RpyPairTerms c{};
  c.tt_f = select(far, s * (0.75 + 0.5 * s2), 1.0 - 9.0 / 32.0 * r);
  c.tt_h = select(far, s3 * (0.75 - 1.5 * s2), 3.0 / 32.0 * s);
  if constexpr (Rotation) {
    c.rt = select(far, 0.75 * s3, 0.375 - 9.0 / 64.0 * r);
    c.rr_f = select(far, -0.375 * s3, 0.75 - 81.0 / 128.0 * r + 15.0 / 256.0 * r2 * r);
    c.rr_h = select(far, 1.125 * s3 * s2, 27.0 / 128.0 * s - 9.0 / 256.0 * r);
  }
  return c;
}

// Block storage. A block holds at most kRpyBlock blobs, padded to a multiple of kRpyLanes
// (the widest vector) with copies of the last blob that carry no force: their terms are
// finite, so they add exactly 0. Sources: x, y, z, f (3), tau (3, 6 dofs), each component
// kRpySourceStride long, the block's blobs stored twice in a row so that a tile walks the
// pairs (k, k + o) without wrapping. Accumulators: u (3), omega (3, 6 dofs), each kRpyBlock
// long. A 3-dof tile touches 27 KB, within a 32 KB L1 cache.
inline constexpr Eigen::Index kRpyBlock = 128;
inline constexpr Eigen::Index kRpyLanes = 8;
inline constexpr Eigen::Index kRpySourceStride = 2 * kRpyBlock;

// One tile: targets of block I, sources of block J (both of size b). Pair (k, j) with
// j = (k + o) mod b for o in [0, b): every pair once, each target's sources in a fixed order.
// Adds the velocities of block I's blobs to acc_i. Mutual (I < J): the pair also acts on j,
// and out_j receives (is overwritten with) block J's velocities from block I. Not mutual
// (I == J, the diagonal tile): targets only, o = 0 is the self term.
template <bool Rotation, bool Mutual>
[[gnu::always_inline]] inline void rpy_tile(const double* __restrict src_i, const double* __restrict src_j,
                                            double* __restrict acc_i, double* __restrict out_j, Eigen::Index b) {
  constexpr Eigen::Index S = kRpySourceStride, A = kRpyBlock, W = 2 * kRpyBlock;
  constexpr Eigen::Index dofs = Rotation ? 6 : 3;
  alignas(64) double col[Mutual ? dofs * W : 1];  // out_j over doubled indices, folded at the end
  if constexpr (Mutual) std::fill(col, col + dofs * W, 0.0);
  for (Eigen::Index o = 0; o < b; ++o) {
    const double* __restrict sj = src_j + o;
    double* __restrict cj = col + o;
    for (Eigen::Index k = 0; k < b; ++k) {
      const double rx = src_i[k] - sj[k], ry = src_i[S + k] - sj[S + k], rz = src_i[2 * S + k] - sj[2 * S + k];
      const RpyPairTerms c = rpy_pair_terms<Rotation>(rx * rx + ry * ry + rz * rz);
      const double fjx = sj[3 * S + k], fjy = sj[4 * S + k], fjz = sj[5 * S + k];
      const double hj = c.tt_h * (rx * fjx + ry * fjy + rz * fjz);
      double ux = c.tt_f * fjx + hj * rx, uy = c.tt_f * fjy + hj * ry, uz = c.tt_f * fjz + hj * rz;
      if constexpr (Rotation) {
        const double tjx = sj[6 * S + k], tjy = sj[7 * S + k], tjz = sj[8 * S + k];
        ux += c.rt * (tjy * rz - tjz * ry);  // tau_j x r
        uy += c.rt * (tjz * rx - tjx * rz);
        uz += c.rt * (tjx * ry - tjy * rx);
        const double gj = c.rr_h * (rx * tjx + ry * tjy + rz * tjz);
        acc_i[3 * A + k] += c.rr_f * tjx + gj * rx + c.rt * (fjy * rz - fjz * ry);  // + f_j x r
        acc_i[4 * A + k] += c.rr_f * tjy + gj * ry + c.rt * (fjz * rx - fjx * rz);
        acc_i[5 * A + k] += c.rr_f * tjz + gj * rz + c.rt * (fjx * ry - fjy * rx);
      }
      acc_i[k] += ux;
      acc_i[A + k] += uy;
      acc_i[2 * A + k] += uz;
      if constexpr (Mutual) {
        // Blob j sees -r: the even terms are unchanged, the cross products change sign.
        const double fix = src_i[3 * S + k], fiy = src_i[4 * S + k], fiz = src_i[5 * S + k];
        const double hi = c.tt_h * (rx * fix + ry * fiy + rz * fiz);
        double vx = c.tt_f * fix + hi * rx, vy = c.tt_f * fiy + hi * ry, vz = c.tt_f * fiz + hi * rz;
        if constexpr (Rotation) {
          const double tix = src_i[6 * S + k], tiy = src_i[7 * S + k], tiz = src_i[8 * S + k];
          vx -= c.rt * (tiy * rz - tiz * ry);
          vy -= c.rt * (tiz * rx - tix * rz);
          vz -= c.rt * (tix * ry - tiy * rx);
          const double gi = c.rr_h * (rx * tix + ry * tiy + rz * tiz);
          cj[3 * W + k] += c.rr_f * tix + gi * rx - c.rt * (fiy * rz - fiz * ry);
          cj[4 * W + k] += c.rr_f * tiy + gi * ry - c.rt * (fiz * rx - fix * rz);
          cj[5 * W + k] += c.rr_f * tiz + gi * rz - c.rt * (fix * ry - fiy * rx);
        }
        cj[k] += vx;
        cj[W + k] += vy;
        cj[2 * W + k] += vz;
      }
    }
  }
  if constexpr (Mutual)
    for (Eigen::Index d = 0; d < dofs; ++d)
      for (Eigen::Index k = 0; k < b; ++k) out_j[d * A + k] = col[d * W + k] + col[d * W + b + k];
}

// The tile loop compiled per instruction set.
using RpyTileFunction = void (*)(const double*, const double*, double*, double*, Eigen::Index);

template <bool Rotation, bool Mutual>
void rpy_tile_baseline(const double* src_i, const double* src_j, double* acc_i, double* out_j, Eigen::Index b) {
  rpy_tile<Rotation, Mutual>(src_i, src_j, acc_i, out_j, b);
}

#if STOKESCONTACT_RPY_DISPATCH
template <bool Rotation, bool Mutual>
[[gnu::target("avx2,fma")]] void rpy_tile_avx2(const double* src_i, const double* src_j, double* acc_i,
                                                double* out_j, Eigen::Index b) {
  rpy_tile<Rotation, Mutual>(src_i, src_j, acc_i, out_j, b);
}

template <bool Rotation, bool Mutual>
[[gnu::target("avx512f,avx512dq,fma")]] void rpy_tile_avx512(const double* src_i, const double* src_j,
                                                              double* acc_i, double* out_j, Eigen::Index b) {
  rpy_tile<Rotation, Mutual>(src_i, src_j, acc_i, out_j, b);
}
#endif

template <bool Rotation, bool Mutual>
RpyTileFunction rpy_tile_function(RpyInstructionSet isa) {
#if STOKESCONTACT_RPY_DISPATCH
  if (isa == RpyInstructionSet::avx512) return &rpy_tile_avx512<Rotation, Mutual>;
  if (isa == RpyInstructionSet::avx2_fma) return &rpy_tile_avx2<Rotation, Mutual>;
#endif
  (void)isa;
  return &rpy_tile_baseline<Rotation, Mutual>;
}

// Blocks of n blobs: as few as kRpyBlock allows, of equal size b (a multiple of kRpyLanes).
struct RpyBlocks {
  Eigen::Index count = 0, size = 0;
};

inline RpyBlocks rpy_blocks(Eigen::Index n) {
  const Eigen::Index count = (n + kRpyBlock - 1) / kRpyBlock;
  const Eigen::Index per_block = (n + count - 1) / count;
  return {count, (per_block + kRpyLanes - 1) / kRpyLanes * kRpyLanes};
}

// Fewer blocks (n <= 896, a product of at most ~1 ms on one core) run on one thread: a
// parallel region costs microseconds on idle cores but can wait milliseconds for a thread
// that another process has descheduled.
inline constexpr Eigen::Index kRpyParallelMinBlocks = 8;

// Rows per panel: the column buffers of a panel (rows x blocks x tile outputs) stay within
// kRpyPanelDoubles, so memory stays O(n) for large n; small scenes run as one panel.
inline constexpr Eigen::Index kRpyPanelDoubles = Eigen::Index{1} << 21;  // 16 MB

// Block row I: the diagonal tile, then the tiles (I, J > I) in order of J.
template <bool Rotation>
void rpy_direct_sum_blocks(const Mat3X& x, const VecX& F, VecX& U, RpyInstructionSet isa) {
  constexpr Eigen::Index dofs = Rotation ? 6 : 3, S = kRpySourceStride, A = kRpyBlock;
  constexpr Eigen::Index source_size = (3 + dofs) * S, acc_size = dofs * A;
  const Eigen::Index n = x.cols();
  const RpyBlocks layout = rpy_blocks(n);
  const Eigen::Index blocks = layout.count, b = layout.size;  // not a structured binding: lambdas capture them
  const Eigen::Index panel = std::clamp(kRpyPanelDoubles / (blocks * acc_size), Eigen::Index{1}, blocks);
  std::vector<double> sources(static_cast<std::size_t>(blocks * source_size), 0.0);
  std::vector<double> rows(static_cast<std::size_t>(blocks * acc_size), 0.0);     // row sums
  std::vector<double> columns(static_cast<std::size_t>(blocks * acc_size), 0.0);  // buffers added
  // Only slots (row, J > row) are written, then read; left uninitialised, the others are never touched.
  const std::unique_ptr<double[]> buffers(new double[static_cast<std::size_t>(panel * blocks * acc_size)]);
  for (Eigen::Index blk = 0; blk < blocks; ++blk) {
    double* s = sources.data() + blk * source_size;
    for (Eigen::Index k = 0; k < b; ++k) {
      const Eigen::Index i = std::min(blk * b + k, n - 1);  // padding sits on the last blob, no force
      const bool real = blk * b + k < n;
      for (Eigen::Index d = 0; d < 3; ++d) s[d * S + k] = s[d * S + b + k] = x(d, i);
      for (Eigen::Index d = 0; d < dofs; ++d)
        s[(3 + d) * S + k] = s[(3 + d) * S + b + k] = real ? F[dofs * i + d] : 0.0;
    }
  }
  const RpyTileFunction diagonal = rpy_tile_function<Rotation, false>(isa);
  const RpyTileFunction mutual = rpy_tile_function<Rotation, true>(isa);
  auto source = [&](Eigen::Index blk) { return sources.data() + blk * source_size; };
  auto buffer = [&](Eigen::Index row, Eigen::Index blk) { return buffers.get() + (row * blocks + blk) * acc_size; };
  for (Eigen::Index first = 0; first < blocks; first += panel) {
    const Eigen::Index last = std::min(blocks, first + panel);
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 1) if (blocks >= kRpyParallelMinBlocks)
#endif
    for (Eigen::Index i = first; i < last; ++i) {  // longest rows first
      double* row = rows.data() + i * acc_size;
      diagonal(source(i), source(i), row, nullptr, b);
      for (Eigen::Index j = i + 1; j < blocks; ++j) mutual(source(i), source(j), row, buffer(i - first, j), b);
    }
    // In one thread: O(n) per row, and no second barrier (each is costly on a busy machine).
    for (Eigen::Index j = first + 1; j < blocks; ++j) {
      double* column = columns.data() + j * acc_size;
      for (Eigen::Index i = first; i < std::min(last, j); ++i) {
        const double* in = buffer(i - first, j);
        for (Eigen::Index d = 0; d < dofs; ++d)
          for (Eigen::Index k = 0; k < b; ++k) column[d * A + k] += in[d * A + k];
      }
    }
  }
  U.resize(dofs * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index at = (i / b) * acc_size + i % b;
    for (Eigen::Index d = 0; d < dofs; ++d) U[dofs * i + d] = rows[at + d * A] + columns[at + d * A];
  }
}

}  // namespace detail

// U = M F in blob units (top of file) for blobs at x (3 x n, in blob radii), F and U stacked
// per blob: (f_i) for dofs_per_blob 3, (f_i, tau_i) for 6. Runs the tile loop compiled for
// `isa` (default: the widest this CPU supports; an unsupported one is refused).
inline VecX rpy_direct_sum(const Mat3X& x, const VecX& F, int dofs_per_blob,
                           RpyInstructionSet isa = rpy_best_instruction_set()) {
  if (dofs_per_blob != 3 && dofs_per_blob != 6)
    fail_argument("dofs_per_blob", "must be 3 or 6, got " + std::to_string(dofs_per_blob));
  if (F.size() != dofs_per_blob * x.cols())
    fail_argument("F", "has size " + std::to_string(F.size()) + ", expected " + std::to_string(dofs_per_blob * x.cols()));
  if (!rpy_instruction_set_supported(isa))
    fail_argument("isa", std::string(rpy_instruction_set_name(isa)) + " is not supported by this CPU");
  VecX U;
  if (x.cols() == 0) return U;
  if (dofs_per_blob == 6)
    detail::rpy_direct_sum_blocks<true>(x, F, U, isa);
  else
    detail::rpy_direct_sum_blocks<false>(x, F, U, isa);
  return U;
}

}  // namespace stokescontact
