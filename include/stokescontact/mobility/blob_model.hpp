#pragma once
// A rigid multiblob model of one body (Usabiaga et al., CAMCOS 11 (2016) 217): blob
// centres in the body frame, about the body origin (the shape's centre of mass), and the
// one blob radius a that the RPY interactions between them use.
//
// Overlap rule: blobs of one body may overlap (neighbours on a shell or a rod overlap by
// design), since RPY's overlap branch keeps the blob mobility positive definite for any
// distinct positions; two blobs closer than kMinBlobSeparation * a make it numerically
// singular and are refused. The blobs must not lie on one line: a line of blobs offers no
// resistance to spinning about it, and the body mobility would not exist.
#include <cstddef>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/types.hpp"

namespace stokescontact {

// Two blobs (of one body, or of two bodies) closer than this many blob radii are refused:
// at distance r the pair's RPY block has its smallest eigenvalue ~ (9/32)(r/a) mu0.
inline constexpr double kMinBlobSeparation = 1e-2;

struct BlobModel {
  std::string name;      // for messages: "shell_42", "rod", ...
  Mat3X positions;       // body frame, one blob centre per column
  double blob_radius = 0.0;

  Eigen::Index size() const { return positions.cols(); }
};

// Throws std::invalid_argument naming `field` (e.g. "models[1]") and the culprit.
inline void validate(const BlobModel& model, const std::string& field = "model") {
  if (model.size() < 3)
    fail_argument(field + ".positions", "needs at least 3 blobs, got " + std::to_string(model.size()));
  require_positive(model.blob_radius, field + ".blob_radius");
  require_finite(model.positions.reshaped(), field + ".positions");
  const double min_sep = kMinBlobSeparation * model.blob_radius;
  for (Eigen::Index i = 0; i < model.size(); ++i)
    for (Eigen::Index j = i + 1; j < model.size(); ++j)
      if ((model.positions.col(i) - model.positions.col(j)).norm() < min_sep)
        fail_argument(field + ".positions", "blobs " + std::to_string(i) + " and " + std::to_string(j) +
                                                " are closer than 1e-2 blob radii");
  // Not collinear: the blobs' second moment about their centroid has rank >= 2.
  const Vec3 c = model.positions.rowwise().mean();
  const Mat3X d = model.positions.colwise() - c;
  const Eigen::SelfAdjointEigenSolver<Mat3> moments(d * d.transpose());
  if (moments.eigenvalues()(1) <= 1e-12 * moments.eigenvalues()(2))
    fail_argument(field + ".positions", "blobs lie on one line; the body could spin freely about it");
}

}  // namespace stokescontact
