#pragma once
// Minimal JSON formatting for JSON-lines output (the drivers', the stepper's diagnostics):
// numbers keep all 17 significant digits, non-finite values become null (JSON has no NaN or
// infinity), strings are quoted with quotes, backslashes and control characters escaped.
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>

#include "stokescontact/core/types.hpp"

namespace stokescontact {

inline std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

// Appended piece by piece: `"[" + json_number(x)` trips GCC 12's false -Wrestrict (PR 105651).
inline std::string json_array(std::span<const double> values) {
  std::string out = "[";
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (k > 0) out += ", ";
    out += json_number(values[k]);
  }
  out += ']';
  return out;
}

inline std::string json_array(const Vec3& v) { return json_array(std::span<const double>(v.data(), 3)); }

// A JSON string literal: `"` and `\` escaped by a backslash, control characters as \u00XX.
inline std::string json_quoted(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace stokescontact
