#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "stokescontact/geometry/centre_curve.hpp"
#include "stokescontact/mobility/blob_models.hpp"
#include "stokescontact/mobility/single_body_mobility.hpp"
#include "common/test_support.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace blob_models_tests {

namespace sc = stokescontact;

namespace {

using test_support::expect_rejects;

constexpr double kPi = std::numbers::pi;

struct Radii {
  double translational, rotational;
};

// Hydrodynamic radii of an isotropic body: 1 / (6 pi eta M_tt) and (1 / (8 pi eta M_rr))^(1/3).
Radii hydrodynamic_radii(const sc::Mat6& n, double eta) {
  const double mtt = n.topLeftCorner<3, 3>().trace() / 3.0;
  const double mrr = n.bottomRightCorner<3, 3>().trace() / 3.0;
  return {1.0 / (6.0 * kPi * eta * mtt), std::cbrt(1.0 / (8.0 * kPi * eta * mrr))};
}

double min_distance(const sc::Mat3X& x) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < x.cols(); ++i)
    for (Eigen::Index j = i + 1; j < x.cols(); ++j) best = std::min(best, (x.col(i) - x.col(j)).norm());
  return best;
}

// The x <-> z mirror of a boomerang's body frame, acting on (u, omega): velocities are
// vectors (P u), angular velocities pseudovectors (det(P) P omega = -P omega).
sc::Mat6 boomerang_mirror() {
  sc::Mat3 p;
  p << 0, 0, 1, 0, 1, 0, 1, 0, 0;
  sc::Mat6 t = sc::Mat6::Zero();
  t.topLeftCorner<3, 3>() = p;
  t.bottomRightCorner<3, 3>() = -p;
  return t;
}

}  // namespace

TEST(SphereShell, GeometryMatchesTheIcosahedralShells) {
  // Shortest blob distances at R_g = 1 of the RigidMultiblobsWall shells (2 a).
  const std::array<std::pair<int, double>, 4> published{
      {{12, 1.051462224238267}, {42, 0.5465330578253432}, {162, 0.2759044842552673}, {642, 0.1382831735471675}}};
  for (const auto& [blobs, spacing] : published) {
    const sc::BlobModel m = sc::sphere_shell_geometric(blobs, 1.0);
    ASSERT_EQ(m.size(), blobs);
    EXPECT_NEAR(2.0 * m.blob_radius, spacing, 1e-12) << blobs;
    EXPECT_NEAR(min_distance(m.positions), spacing, 1e-12);
    EXPECT_LT((m.positions.colwise().norm().array() - 1.0).abs().maxCoeff(), 1e-14);
    EXPECT_LT(m.positions.rowwise().sum().norm(), 1e-12);  // centred
  }
}

TEST(SphereShell, ReproducesPublishedTranslationalRadiusAndTabulatedRotationalRadius) {
  for (const sc::ShellRadii& row : sc::kShellRadii) {
    const double eta = 0.7, rg = 1.3;
    const sc::Mat6 n = sc::single_body_mobility(sc::sphere_shell_geometric(row.blobs, rg), eta);
    const Radii r = hydrodynamic_radii(n, eta);
    std::printf("shell %3d: R_h/R_g translational %.6f (published %.4f), rotational %.6f\n", row.blobs,
                r.translational / rg, row.published_translational, r.rotational / rg);
    EXPECT_NEAR(r.translational / rg, row.published_translational, 1e-4) << row.blobs;
    EXPECT_NEAR(r.translational / rg, row.translational, 1e-10) << row.blobs;
    EXPECT_NEAR(r.rotational / rg, row.rotational, 1e-10) << row.blobs;
    // Icosahedral symmetry: isotropic blocks, no translation-rotation coupling.
    const double mtt = n(0, 0), mrr = n(3, 3);
    EXPECT_LT((n.topLeftCorner<3, 3>() - mtt * sc::Mat3::Identity()).norm(), 1e-12 * mtt);
    EXPECT_LT((n.bottomRightCorner<3, 3>() - mrr * sc::Mat3::Identity()).norm(), 1e-12 * mrr);
    EXPECT_LT((n.topRightCorner<3, 3>().norm()), 1e-12 * mtt);
  }
}

TEST(SphereShell, ConvergesToTheSphereAtFirstOrderInTheBlobSpacing) {
  double previous_t = 1.0, previous_r = 1.0;
  for (const sc::ShellRadii& row : sc::kShellRadii) {
    const Radii r = hydrodynamic_radii(sc::single_body_mobility(sc::sphere_shell_geometric(row.blobs, 1.0), 1.0), 1.0);
    const double err_t = r.translational - 1.0, err_r = r.rotational - 1.0;
    EXPECT_GT(err_t, 0.0);
    EXPECT_GT(err_r, 0.0);
    if (row.blobs > 12) {
      // Each subdivision halves the spacing; the radius error falls by ~2 (0.43-0.48).
      EXPECT_GT(err_t / previous_t, 0.40) << row.blobs;
      EXPECT_LT(err_t / previous_t, 0.50) << row.blobs;
      EXPECT_GT(err_r / previous_r, 0.40) << row.blobs;
      EXPECT_LT(err_r / previous_r, 0.50) << row.blobs;
    }
    previous_t = err_t;
    previous_r = err_r;
  }
}

TEST(SphereShell, HydrodynamicRadiusRequestIsHonoured) {
  for (const int blobs : {12, 42, 162}) {
    const double a = 2.5, eta = 3.0;
    const sc::Mat6 n = sc::single_body_mobility(sc::sphere_shell(blobs, a), eta);
    EXPECT_NEAR(n(0, 0) * 6.0 * kPi * eta * a, 1.0, 1e-10) << blobs;
    EXPECT_LT(hydrodynamic_radii(n, eta).rotational, a);
  }
}

TEST(SphereShell, RejectsBadInput) {
  expect_rejects([] { sc::sphere_shell(13, 1.0); }, "blobs");
  expect_rejects([] { sc::sphere_shell(2562, 1.0); }, "blobs");
  expect_rejects([] { sc::sphere_shell(12, 0.0); }, "hydrodynamic_radius");
  expect_rejects([] { sc::sphere_shell(12, std::nan("")); }, "hydrodynamic_radius");
  expect_rejects([] { sc::sphere_shell_geometric(42, -1.0); }, "geometric_radius");
}

TEST(RodBlobs, BlobsLieOnTheSurfaceInInterlockingRings) {
  const sc::Spherocylinder rod{4.0, 0.5};
  const sc::BlobModel m = sc::rod_blob_model(rod, {8, 0.0, 0.0});
  const auto axis = sc::centre_curve(rod);
  for (Eigen::Index k = 0; k < m.size(); ++k)
    EXPECT_NEAR(sc::closest_point(axis, m.positions.col(k)).distance, rod.radius, 1e-14) << k;
  // Default spacing: the chord of a ring, 2 R sin(pi / 8); blob radius half of it.
  const double chord = 2.0 * rod.radius * std::sin(kPi / 8.0);
  EXPECT_NEAR(m.blob_radius, 0.5 * chord, 1e-15);
  EXPECT_GT(min_distance(m.positions), 0.7 * chord);
  EXPECT_LT(m.positions.rowwise().mean().norm(), 1e-12);  // centred on the body origin
  // Cylinder rings of 8 (L / chord = 10.45: 10 gaps, 11 rings) plus two caps.
  const int gaps = static_cast<int>(std::lround(rod.length / chord));
  const int cap_rings = static_cast<int>(std::lround(0.5 * kPi * rod.radius / chord));
  EXPECT_EQ(cap_rings, 2);  // the pole and one ring at 45 degrees of round(8 sin 45) = 6
  EXPECT_EQ(m.size(), 8 * (gaps + 1) + 2 * (1 + 6));
}

TEST(RodBlobs, ResolutionParametersAreUsed) {
  const sc::Spherocylinder rod{3.0, 1.0};
  const sc::BlobModel m = sc::rod_blob_model(rod, {12, 0.25, 0.2});
  EXPECT_EQ(m.blob_radius, 0.2);
  // Cylinder rings 0.25 apart: 13 rings of 12.
  int on_cylinder = 0;
  for (Eigen::Index k = 0; k < m.size(); ++k) on_cylinder += std::abs(m.positions(2, k)) <= 1.5 + 1e-12;
  EXPECT_EQ(on_cylinder, 13 * 12);
}

TEST(RodBlobs, TendsToSlenderBodyTheoryAsTheAspectRatioGrows) {
  // Yan et al. eq. 45-50 (D = 2R, L the segment length): M_par = 2b / (8 pi eta L),
  // M_perp = (b + 2) / (8 pi eta L), M_rot = 3 (b + 2) / (2 pi eta L^3), b = -(1 + 2 ln(D / 2L)).
  // The multiblob rod sits below, by a deficit that shrinks like C / ln(L/D): the blob rod is
  // a bit fatter than R, and eq. 47-49 carry end constants (ln 2 -+ 1/2) above the exact ones
  // (ln(L/D) - 0.21, + 0.84, - 0.66 for par, perp, rot; Tirado & Garcia de la Torre).
  const double eta = 1.0;
  std::array<double, 3> previous{0.0, 0.0, 0.0};
  for (const double aspect : {5.0, 10.0, 20.0, 40.0}) {
    const sc::Spherocylinder rod{aspect, 0.5};  // D = 1, L = aspect
    const sc::Mat6 n = sc::single_body_mobility(sc::rod_blob_model(rod), eta);
    const double L = rod.length, D = 2.0 * rod.radius;
    const double b = -(1.0 + 2.0 * std::log(D / (2.0 * L)));
    const std::array<double, 3> ratio{n(2, 2) / (2.0 * b / (8.0 * kPi * eta * L)),
                                      n(0, 0) / ((b + 2.0) / (8.0 * kPi * eta * L)),
                                      n(3, 3) / (3.0 * (b + 2.0) / (2.0 * kPi * eta * L * L * L))};
    std::printf("rod L/D = %4.0f: multiblob / slender body  parallel %.4f  perpendicular %.4f  rotation %.4f\n",
                aspect, ratio[0], ratio[1], ratio[2]);
    for (int k = 0; k < 3; ++k) {
      EXPECT_LT(ratio[k], 1.0) << aspect << " " << k;
      EXPECT_GT(ratio[k], previous[k]) << aspect << " " << k;  // increasing towards 1
      previous[k] = ratio[k];
    }
    // The deficit times ln(L/D) stays bounded: 1 - ratio = O(1 / ln(L/D)).
    const double log_p = std::log(aspect);
    EXPECT_LT((1.0 - ratio[0]) * log_p, 0.7);
    EXPECT_LT((1.0 - ratio[1]) * log_p, 0.7);
    EXPECT_LT((1.0 - ratio[2]) * log_p, 2.1);
    // Nearly axisymmetric: isotropic across the axis, no translation-rotation coupling (the
    // caps' rings of round(n sin(theta)) blobs leave only a 2-fold symmetry about the axis).
    EXPECT_NEAR(n(0, 0), n(1, 1), 1e-3 * n(0, 0));
    EXPECT_LT((n.topRightCorner<3, 3>().norm()), 1e-6 * n(0, 0));
  }
}

TEST(RodBlobs, RejectsBadInput) {
  expect_rejects([] { sc::rod_blob_model({1.0, 0.5}, {2, 0.0, 0.0}); }, "blobs_per_ring");
  expect_rejects([] { sc::rod_blob_model({1.0, 0.5}, {8, -0.1, 0.0}); }, "ring_spacing");
  expect_rejects([] { sc::rod_blob_model({1.0, 0.5}, {8, 0.0, -1.0}); }, "blob_radius");
  expect_rejects([] { sc::rod_blob_model({-1.0, 0.5}); }, "Spherocylinder.length");
  expect_rejects([] { sc::rod_blob_model({1.0, 0.0}); }, "Spherocylinder.radius");
}

TEST(BoomerangBlobs, CurveBlobsLieOnTheCentreCurveAtEqualSpacing) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const sc::BlobModel m = sc::boomerang_curve_blobs(b);
  const auto curve = sc::centre_curve(b);
  for (Eigen::Index k = 0; k < m.size(); ++k)
    EXPECT_LT(sc::closest_point(curve, m.positions.col(k)).distance, 1e-14) << k;
  // Arclength 2 * 1.5 + pi / 4 = 3.785 at spacing ~0.5: 8 gaps, 9 blobs, both tips included.
  EXPECT_EQ(m.size(), 9);
  EXPECT_LT((m.positions.col(0) - curve.segments[0].p0).norm(), 1e-15);
  EXPECT_LT((m.positions.col(8) - curve.segments[1].p1).norm(), 1e-15);
  EXPECT_EQ(m.blob_radius, b.radius);
}

TEST(BoomerangBlobs, SurfaceBlobsLieOnTheSurface) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const sc::BlobModel m = sc::boomerang_surface_blobs(b, 0.3);
  const auto curve = sc::centre_curve(b);
  EXPECT_GT(m.size(), 100);
  EXPECT_EQ(m.blob_radius, 0.15);
  for (Eigen::Index k = 0; k < m.size(); ++k)
    EXPECT_NEAR(sc::closest_point(curve, m.positions.col(k)).distance, b.radius, 1e-12) << k;
}

TEST(BoomerangBlobs, MobilitiesHaveTheMirrorSymmetryAndAgreeAcrossResolutions) {
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  const sc::Mat6 t = boomerang_mirror();
  const sc::Mat6 coarse = sc::single_body_mobility(sc::boomerang_curve_blobs(b), 1.0);
  const sc::Mat6 fine = sc::single_body_mobility(sc::boomerang_surface_blobs(b, 0.3), 1.0);
  const sc::Mat6 finer = sc::single_body_mobility(sc::boomerang_surface_blobs(b, 0.2), 1.0);
  for (const sc::Mat6* n : {&coarse, &fine, &finer}) {
    EXPECT_LT((t * *n * t.transpose() - *n).norm(), 1e-6 * n->norm());
    EXPECT_GT((n->topRightCorner<3, 3>().norm()), 1e-3 * n->norm());  // off-centre: coupled
  }
  // Two surface resolutions agree to a few percent.
  const auto rel = [](const sc::MatX& x, const sc::MatX& y) { return (x - y).norm() / y.norm(); };
  std::printf("boomerang: |fine - finer| / |finer| = %.4f; curve / finer: translation block %.4f, "
              "spin about the bend axis %.3f, about the arm axes %.3f\n",
              rel(fine, finer), rel(coarse.topLeftCorner<3, 3>(), finer.topLeftCorner<3, 3>()),
              coarse(4, 4) / finer(4, 4), coarse(3, 3) / finer(3, 3));
  EXPECT_LT(rel(fine, finer), 0.05);
  // The curve chain is a fair translational model; it cannot resist an arm spinning about
  // its own axis (blobs on an axis do not move), so its mobility for rotations about the
  // arm axes (x, z) is about twice the surface model's: use surface blobs for rotations.
  EXPECT_LT(rel(coarse.topLeftCorner<3, 3>(), finer.topLeftCorner<3, 3>()), 0.15);
  EXPECT_NEAR(coarse(4, 4) / finer(4, 4), 1.0, 0.35);
  EXPECT_GT(coarse(3, 3) / finer(3, 3), 1.5);
}

TEST(BlobModel, ValidationNamesTheField) {
  sc::BlobModel m = sc::sphere_shell(12, 1.0);
  m.blob_radius = -1.0;
  expect_rejects([&] { sc::validate(m, "models[3]"); }, "models[3].blob_radius");
  m = sc::sphere_shell(12, 1.0);
  m.positions(1, 4) = std::numeric_limits<double>::infinity();
  expect_rejects([&] { sc::validate(m); }, "model.positions");
  m = sc::sphere_shell(12, 1.0);
  m.positions.col(5) = m.positions.col(2);  // coincident blobs
  expect_rejects([&] { sc::validate(m); }, "model.positions");
  sc::BlobModel line{"line", sc::Mat3X::Zero(3, 5), 0.5};
  for (Eigen::Index k = 0; k < 5; ++k) line.positions(2, k) = static_cast<double>(k);
  expect_rejects([&] { sc::validate(line); }, "model.positions");
  expect_rejects([&] { sc::single_body_mobility(line, 1.0); }, "model.positions");
  sc::BlobModel two{"two", sc::Mat3X::Identity(3, 2), 0.5};
  expect_rejects([&] { sc::validate(two); }, "model.positions");
  expect_rejects([] { sc::single_body_mobility(sc::sphere_shell(12, 1.0), -1.0); }, "viscosity");
}

}  // namespace blob_models_tests
