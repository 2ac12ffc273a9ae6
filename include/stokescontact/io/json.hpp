#pragma once
// Minimal JSON formatting for the drivers' JSON-lines output: numbers keep all 17
// significant digits, and non-finite values become null (JSON has no NaN or infinity).
#include <cmath>
#include <cstdio>
#include <string>

#include "stokescontact/core/types.hpp"

namespace stokescontact {

inline std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

inline std::string json_array(const Vec3& v) {
  return "[" + json_number(v.x()) + ", " + json_number(v.y()) + ", " + json_number(v.z()) + "]";
}

}  // namespace stokescontact
