// periodic_random_placement and periodic_aligned_columns: contact free through the minimum
// image (checked against every image by brute force), inside the box, reproducible by seed,
// and clear errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/geometry/closest_points.hpp"
#include "stokescontact/scenes/periodic_placement.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace periodic_placement_tests {

namespace sc = stokescontact;

namespace {

// The smallest gap between any two bodies over all 27 neighbouring images: no minimum image
// used. Images whose centres are more than 2 bounding radii + 1 apart are not measured (their
// gap is > 1, more than every gap these tests compare with).
template <sc::Shape S>
double smallest_gap_over_images(const S& shape, const std::vector<sc::Pose>& poses, const sc::Vec3& lengths) {
  double best = 1e300;
  const double reach = 2.0 * sc::bounding_radius(shape) + 1.0;
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (std::size_t j = i + 1; j < poses.size(); ++j)
      for (int a = -1; a <= 1; ++a)
        for (int b = -1; b <= 1; ++b)
          for (int c = -1; c <= 1; ++c) {
            const sc::Pose image{poses[j].x + lengths.cwiseProduct(sc::Vec3(a, b, c)), poses[j].q};
            if ((image.x - poses[i].x).norm() > reach) continue;
            best = std::min(best, sc::closest_points(shape, poses[i], shape, image).distance);
          }
  return best;
}

template <sc::Shape S>
double smallest_gap_over_images(const S& shape, const std::vector<sc::Pose>& poses, double side) {
  return smallest_gap_over_images(shape, poses, sc::Vec3::Constant(side));
}

// Each pair's smallest gap over the 27 neighbouring images, pairs in order (i < j).
template <sc::Shape S>
std::vector<double> pair_gaps_over_images(const S& shape, const std::vector<sc::Pose>& poses, double side) {
  std::vector<double> gaps;
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (std::size_t j = i + 1; j < poses.size(); ++j)
      gaps.push_back(smallest_gap_over_images(shape, std::vector<sc::Pose>{poses[i], poses[j]}, side));
  return gaps;
}

TEST(PeriodicPlacement, RodsAreContactFreeAcrossTheBoundaryAndInsideTheBox) {
  const sc::Spherocylinder rod{5.0, 0.5};
  const double side = 16.0, gap = 0.05;
  const std::vector<sc::Pose> poses = sc::periodic_random_placement(rod, 60, side, gap, 7);
  ASSERT_EQ(poses.size(), 60u);
  for (const sc::Pose& p : poses) {
    EXPECT_TRUE((p.x.array() >= 0.0).all() && (p.x.array() < side).all());
    EXPECT_NEAR(p.q.norm(), 1.0, 1e-14);
  }
  EXPECT_GT(smallest_gap_over_images(rod, poses, side), gap);
  // The check above is not empty: some pairs come within 1 of each other across a face only.
  const sc::PeriodicBox box{sc::Vec3::Constant(side)};
  int across = 0;
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      const sc::Pose shifted{poses[j].x + sc::minimum_image_shift(poses[i].x, poses[j].x, box), poses[j].q};
      across += shifted.x != poses[j].x && sc::closest_points(rod, poses[i], rod, shifted).distance < 1.0 ? 1 : 0;
    }
  EXPECT_GT(across, 0);
  const std::vector<sc::Pose> again = sc::periodic_random_placement(rod, 60, side, gap, 7);
  for (std::size_t k = 0; k < poses.size(); ++k) EXPECT_EQ(poses[k].x, again[k].x);
  const std::vector<sc::Pose> other = sc::periodic_random_placement(rod, 60, side, gap, 8);
  EXPECT_NE(poses[0].x, other[0].x);
}

TEST(PeriodicPlacement, RejectsABoxTooSmallAndReportsAPackingItCannotFinish) {
  const sc::Spherocylinder rod{5.0, 0.5};
  test_support::expect_rejects([&] { sc::periodic_random_placement(rod, 2, 11.9, 0.0, 1); }, "side");
  test_support::expect_rejects([&] { sc::periodic_random_placement(rod, 2, 20.0, -0.1, 1); }, "min_gap");
  test_support::expect_rejects([&] { sc::periodic_random_placement(rod, 2, 20.0, 0.1, 1, 0); }, "max_attempts");
  // Unit spheres (bounding diameter 2) at 200 in a box of 8: phi 1.6, impossible.
  try {
    sc::periodic_random_placement(sc::Sphere{1.0}, 200, 8.0, 0.0, 1, 1000);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("1000 draws in a row were rejected"), std::string::npos) << e.what();
  }
}

// L / D = 5 rods at packing 0.45 (brownian_rods refuses a random start at 0.3 and above):
// every rod along z, 277 of them in columns with their own z offsets, contact free across
// every face.
TEST(PeriodicPlacement, AlignedColumnsReachADenseContactFreeStart) {
  const sc::Spherocylinder rod{5.0, 0.5};
  const double side = 14.0, gap = 0.01;
  const double volume = std::numbers::pi * (0.25 * rod.length + 1.0 / 6.0);  // diameter 1
  const auto count = static_cast<std::size_t>(0.45 * side * side * side / volume);
  ASSERT_EQ(count, 277u);
  const std::vector<sc::Pose> poses = sc::periodic_aligned_columns(rod, count, side, gap, 3);
  ASSERT_EQ(poses.size(), count);
  for (const sc::Pose& p : poses) {
    EXPECT_TRUE((p.x.array() >= 0.0).all() && (p.x.array() < side).all());
    EXPECT_LT((p.rotation().col(2) - sc::Vec3::UnitZ()).norm(), 1e-15);
  }
  EXPECT_GT(smallest_gap_over_images(rod, poses, side), gap);
  // Not a layered (smectic) start: the rods' z positions spread over the box.
  std::vector<double> z;
  for (const sc::Pose& p : poses) z.push_back(p.x.z());
  std::sort(z.begin(), z.end());
  double largest_hole = z.front() + side - z.back();
  for (std::size_t k = 1; k < z.size(); ++k) largest_hole = std::max(largest_hole, z[k] - z[k - 1]);
  EXPECT_LT(largest_hole, 0.5);
  const std::vector<sc::Pose> again = sc::periodic_aligned_columns(rod, count, side, gap, 3);
  for (std::size_t k = 0; k < poses.size(); ++k) EXPECT_EQ(poses[k].x, again[k].x);
  EXPECT_NE(poses[0].x, sc::periodic_aligned_columns(rod, count, side, gap, 4)[0].x);
}

// Yan et al.'s elongated box (72 D x 15 D x 15 D for 2000 rods), here 1000 rods at packing
// 0.44 in a box 4.8 times as long as wide (12.6 x 12.6 x 60.1), the rods along its long side (z): inside the box,
// contact free through every image, and filling the long side (no hole longer than a rod).
TEST(PeriodicPlacement, AlignedColumnsFillAnElongatedBox) {
  const sc::Spherocylinder rod{5.0, 0.5};
  const double gap = 0.01, volume = std::numbers::pi * (0.25 * rod.length + 1.0 / 6.0);
  const std::size_t count = 1000;
  const double side = std::cbrt(count * volume / (0.44 * 4.8));
  const sc::PeriodicBox box{sc::Vec3(side, side, 4.8 * side)};
  const std::vector<sc::Pose> poses = sc::periodic_aligned_columns(rod, count, box, gap, 5);
  ASSERT_EQ(poses.size(), count);
  std::vector<double> z;
  for (const sc::Pose& p : poses) {
    EXPECT_TRUE((p.x.array() >= 0.0).all() && (p.x.array() < box.lengths.array()).all()) << p.x.transpose();
    EXPECT_LT((p.rotation().col(2) - sc::Vec3::UnitZ()).norm(), 1e-15);
    z.push_back(p.x.z());
  }
  EXPECT_GT(smallest_gap_over_images(rod, poses, box.lengths), gap);
  std::sort(z.begin(), z.end());
  double largest_hole = z.front() + box.lengths.z() - z.back();
  for (std::size_t k = 1; k < z.size(); ++k) largest_hole = std::max(largest_hole, z[k] - z[k - 1]);
  EXPECT_LT(largest_hole, rod.length);
  // The cube is the box of equal sides: the same start.
  const std::vector<sc::Pose> cube = sc::periodic_aligned_columns(rod, 100, 14.0, gap, 3);
  const std::vector<sc::Pose> boxed = sc::periodic_aligned_columns(rod, 100, sc::PeriodicBox{sc::Vec3::Constant(14.0)}, gap, 3);
  for (std::size_t k = 0; k < cube.size(); ++k) EXPECT_EQ(cube[k].x, boxed[k].x);
  test_support::expect_rejects([&] { sc::periodic_aligned_columns(rod, 2, sc::PeriodicBox{sc::Vec3(14.0, 15.0, 60.0)}, gap, 1); },
                               "box.lengths");
  test_support::expect_rejects([&] { sc::periodic_aligned_columns(rod, 2, sc::PeriodicBox{sc::Vec3(14.0, 14.0, 11.9)}, 0.0, 1); },
                               "box.lengths");
}

// rescale_centres: an expansion widens or keeps every pair's gap (brute force over the 27
// images, each pair on its own), however little or much; a compression narrows some.
TEST(PeriodicPlacement, AnExpansionShortensNoGapBetweenRods) {
  const sc::Spherocylinder rod{5.0, 0.5};
  const double side = 13.0;
  const std::vector<sc::Pose> start = sc::periodic_random_placement(rod, 60, side, 0.01, 11);
  const std::vector<double> before = pair_gaps_over_images(rod, start, side);
  ASSERT_LT(*std::min_element(before.begin(), before.end()), 0.3);  // some pairs nearly touch
  for (const double factor : {1.0 + 1e-9, 1.0 + 1e-4, 1.01, 1.2, 2.0}) {
    std::vector<sc::Pose> poses = start;
    sc::rescale_centres(poses, factor);
    const std::vector<double> after = pair_gaps_over_images(rod, poses, factor * side);
    for (std::size_t k = 0; k < before.size(); ++k)
      ASSERT_GE(after[k], before[k] - 1e-12 * side) << "pair " << k << ", factor " << factor;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      EXPECT_DOUBLE_EQ(poses[k].x.x(), factor * start[k].x.x());
      EXPECT_EQ(poses[k].q.coeffs(), start[k].q.coeffs());
    }
  }
  std::vector<sc::Pose> compressed = start;
  sc::rescale_centres(compressed, 0.99);
  const std::vector<double> after = pair_gaps_over_images(rod, compressed, 0.99 * side);
  EXPECT_LT(*std::min_element(after.begin(), after.end()), *std::min_element(before.begin(), before.end()));
  std::vector<sc::Pose> poses = start;
  for (const double factor : {0.0, -1.0, std::numeric_limits<double>::infinity(), std::nan("")})
    test_support::expect_rejects([&] { sc::rescale_centres(poses, factor); }, "factor");
}

TEST(PeriodicPlacement, AlignedColumnsRejectAPackingTheyCannotHold) {
  const sc::Spherocylinder rod{5.0, 0.5};
  // 493 rods in 14^3 (packing 0.8): 247 columns of 2 on a 16 x 16 lattice of spacing 0.875 < 1.
  test_support::expect_rejects([&] { sc::periodic_aligned_columns(rod, 493, 14.0, 0.01, 1); }, "count");
  test_support::expect_rejects([&] { sc::periodic_aligned_columns(rod, 2, 11.9, 0.0, 1); }, "side");
  test_support::expect_rejects([&] { sc::periodic_aligned_columns(rod, 2, 20.0, -0.1, 1); }, "min_gap");
}

}  // namespace

}  // namespace periodic_placement_tests
