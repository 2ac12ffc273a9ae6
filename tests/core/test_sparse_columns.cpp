// select_columns (core/sparse_columns.hpp) against the dense matrix's columns, with repeated
// and out-of-order columns, an explicit zero kept, no columns, and a bad index refused.
#include <gtest/gtest.h>

#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/core/sparse_columns.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace sparse_columns_tests {

namespace sc = stokescontact;

TEST(SelectColumns, GivesTheListedColumnsInTheirOrder) {
  sc::MatX dense = test_support::random_matrix(9, 3);
  for (Eigen::Index i = 0; i < dense.rows(); ++i)
    for (Eigen::Index j = 0; j < dense.cols(); ++j)
      if ((i + 2 * j) % 3 != 0) dense(i, j) = 0.0;  // a sparse pattern
  dense.col(4).setZero();                           // an empty column
  Eigen::SparseMatrix<double> A = dense.sparseView();
  A.coeffRef(8, 2) = 0.0;  // an explicit zero, kept as stored
  A.makeCompressed();
  const std::vector<Eigen::Index> which{7, 2, 4, 2, 0};
  const Eigen::SparseMatrix<double> S = sc::select_columns(A, which);
  ASSERT_EQ(S.rows(), 9);
  ASSERT_EQ(S.cols(), 5);
  EXPECT_TRUE(S.isCompressed());
  for (std::size_t c = 0; c < which.size(); ++c) {
    EXPECT_EQ(sc::MatX(S).col(static_cast<Eigen::Index>(c)), sc::MatX(A).col(which[c])) << "column " << c;
    EXPECT_EQ(S.col(static_cast<Eigen::Index>(c)).nonZeros(), A.col(which[c]).nonZeros()) << "column " << c;
  }
  EXPECT_EQ(sc::select_columns(A, {}).cols(), 0);
  test_support::expect_rejects([&] { sc::select_columns(A, std::vector<Eigen::Index>{1, 9}); }, "which");
}

}  // namespace sparse_columns_tests
