#include <gtest/gtest.h>

#include <random>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "stokescontact/core/sparse_transpose_product.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace sparse_transpose_product_tests {

namespace sc = stokescontact;

// A contact-matrix-like S: `rows` rows, `cols` columns of 12 non-zeros each (two bodies' six
// rows), random values.
Eigen::SparseMatrix<double> contact_like(Eigen::Index rows, Eigen::Index cols, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<Eigen::Index> body(0, rows / 6 - 1);
  std::normal_distribution<double> value(0.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index k = 0; k < cols; ++k) {
    const Eigen::Index i = body(rng);
    Eigen::Index j = body(rng);
    if (j == i) j = (i + 1) % (rows / 6);
    for (const Eigen::Index b : {i, j})
      for (int r = 0; r < 6; ++r) entries.emplace_back(6 * b + r, k, value(rng));
  }
  Eigen::SparseMatrix<double> S(rows, cols);
  S.setFromTriplets(entries.begin(), entries.end());
  return S;
}

// S^T v and c S^T v equal Eigen's products bit for bit (the same sums in the same order) and
// the dense product to roundoff, below the threshold where the columns are shared out over
// threads and above it; an empty S gives an empty result.
TEST(SparseTransposeProduct, EqualsEigensProductBitForBitAndTheDenseProduct) {
  for (const Eigen::Index cols : {Eigen::Index{0}, Eigen::Index{1}, Eigen::Index{2800},
                                  sc::kSparseTransposeParallelColumns + 123}) {
    const Eigen::Index rows = 6 * 4000;
    const Eigen::SparseMatrix<double> S = contact_like(rows, cols, 7);
    const sc::VecX v = sc::VecX::Random(rows);
    const sc::VecX ours = sc::sparse_transpose_times(S, v);
    const sc::VecX eigen = S.transpose() * v;
    ASSERT_EQ(ours.size(), cols);
    EXPECT_TRUE((ours.array() == eigen.array()).all()) << cols << " columns";
    const double c = 0.0137;  // a time step: dt D^T (M D x)
    const sc::VecX scaled = sc::sparse_transpose_times(S, v, c);
    const sc::VecX eigen_scaled = c * (S.transpose() * v);
    EXPECT_TRUE((scaled.array() == eigen_scaled.array()).all()) << cols << " columns, scaled";
    if (cols >= 2800) {  // c applied after the sum rounds otherwise somewhere: the order is tested
      EXPECT_FALSE((scaled.array() == (c * eigen).array()).all());
    }
    if (cols <= 2800) {
      const sc::VecX dense = Eigen::MatrixXd(S).transpose() * v;
      EXPECT_LE((ours - dense).lpNorm<Eigen::Infinity>(), 1e-13 * (1.0 + dense.lpNorm<Eigen::Infinity>()));
    }
    // Into a vector of another size: resized; of the right size: overwritten.
    sc::VecX out = sc::VecX::Constant(3, 5.0);
    sc::sparse_transpose_times(S, v, out);
    EXPECT_TRUE((out.array() == eigen.array()).all());
    sc::sparse_transpose_times(S, v, out);
    EXPECT_TRUE((out.array() == eigen.array()).all());
  }
}

}  // namespace sparse_transpose_product_tests
