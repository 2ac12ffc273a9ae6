#pragma once
// Input checks at the API boundary: each throws std::invalid_argument naming the field.
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "stokescontact/core/types.hpp"

namespace stokescontact {

[[noreturn]] inline void fail_argument(std::string_view field, std::string_view why) {
  throw std::invalid_argument(std::string(field) + ": " + std::string(why));
}

inline void require_finite(double value, std::string_view field) {
  if (!std::isfinite(value)) fail_argument(field, "must be finite, got " + std::to_string(value));
}

// Names the first offending entry only: a 6N force vector must not flood the message.
template <typename Derived>
void require_finite(const Eigen::DenseBase<Derived>& value, std::string_view field) {
  if (value.allFinite()) return;
  for (Eigen::Index j = 0; j < value.cols(); ++j)
    for (Eigen::Index i = 0; i < value.rows(); ++i)
      if (!std::isfinite(value(i, j))) {
        std::ostringstream os;
        os << "must be finite, got " << value(i, j) << " at entry ";
        if (value.cols() == 1) os << i; else os << "(" << i << ", " << j << ")";
        os << " of " << value.size();
        fail_argument(field, os.str());
      }
}

// A vector argument of a fixed size with finite entries (forces, velocities).
template <typename Derived>
void require_finite(const Eigen::DenseBase<Derived>& value, Eigen::Index size, std::string_view field) {
  if (value.size() != size)
    fail_argument(field, "has size " + std::to_string(value.size()) + ", expected " + std::to_string(size));
  require_finite(value, field);
}

inline void require_positive(double value, std::string_view field) {
  require_finite(value, field);
  if (!(value > 0.0)) fail_argument(field, "must be > 0, got " + std::to_string(value));
}

inline void require_non_negative(double value, std::string_view field) {
  require_finite(value, field);
  if (!(value >= 0.0)) fail_argument(field, "must be >= 0, got " + std::to_string(value));
}

}  // namespace stokescontact
