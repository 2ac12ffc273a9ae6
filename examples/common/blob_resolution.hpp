#pragma once
// One row of a blob grid's resolution study: the relative errors of one body's 6x6 mobility
// against a reference (a finer grid taken as the converged value), block by block (Frobenius
// norms of the translation, rotation and coupling blocks), and of the whole matrix scaled by
// the body's length scale ell, (u, omega ell) / (f, tau / ell), in which the three blocks are
// of one size. Shared by fig9_boomerangs --resolution and fig7_rod_chains --resolution.
#include <stokescontact/core/types.hpp>
#include <stokescontact/io/json.hpp>

#include <cstddef>
#include <cstdio>
#include <string>

namespace examples {

namespace sc = stokescontact;

// The row as a JSON object; `key` and `value` name the grid's resolution parameter (a spacing,
// blobs per ring).
inline std::string resolution_row(const std::string& model, std::size_t blobs, const std::string& key, double value,
                                  const sc::Mat6& M, const sc::Mat6& ref, double ell) {
  const auto rel = [&](int r, int c) {
    return (M.block<3, 3>(r, c) - ref.block<3, 3>(r, c)).norm() / ref.block<3, 3>(r, c).norm();
  };
  sc::Vec6 scale;
  scale << 1, 1, 1, ell, ell, ell;
  const sc::Mat6 a = scale.asDiagonal() * M * scale.asDiagonal(), b = scale.asDiagonal() * ref * scale.asDiagonal();
  char line[400];
  std::snprintf(line, sizeof line,
                "{\"record\": \"resolution\", \"model\": \"%s\", \"blobs\": %zu, \"%s\": %s, "
                "\"err_translation\": %.3e, \"err_rotation\": %.3e, \"err_coupling\": %.3e, \"err_all\": %.3e}",
                model.c_str(), blobs, key.c_str(), sc::json_number(value).c_str(), rel(0, 0), rel(3, 3), rel(0, 3),
                (a - b).norm() / b.norm());
  return line;
}

}  // namespace examples
