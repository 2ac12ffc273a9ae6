// JSON formatting (io/json.hpp): numbers round-trip, non-finite values are null, strings are
// escaped so that any message stays one valid JSON string on one line.
#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "stokescontact/io/json.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace json_tests {

namespace sc = stokescontact;

namespace {

TEST(Json, NumbersRoundTripAndNonFiniteIsNull) {
  for (const double x : {0.0, -1.5, 1.0 / 3.0, std::numbers::pi * 1e-300, 6.02214076e23})
    EXPECT_EQ(std::strtod(sc::json_number(x).c_str(), nullptr), x) << sc::json_number(x);
  EXPECT_EQ(sc::json_number(2.0), "2");
  EXPECT_EQ(sc::json_number(std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(sc::json_number(-std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(sc::json_number(std::numeric_limits<double>::quiet_NaN()), "null");
}

TEST(Json, ArraysOfNumbers) {
  EXPECT_EQ(sc::json_array(sc::Vec3(1, -2, 0.5)), "[1, -2, 0.5]");
  EXPECT_EQ(sc::json_array(std::vector<double>{}), "[]");
  EXPECT_EQ(sc::json_array(std::vector<double>{0.25, std::numeric_limits<double>::infinity(), 3}), "[0.25, null, 3]");
}

TEST(Json, StringsEscapeQuotesBackslashesAndControlCharacters) {
  EXPECT_EQ(sc::json_quoted(""), R"("")");
  EXPECT_EQ(sc::json_quoted("plain text, d / d_hat = 0.99"), R"("plain text, d / d_hat = 0.99")");
  EXPECT_EQ(sc::json_quoted("say \"hi\""), R"("say \"hi\"")");
  EXPECT_EQ(sc::json_quoted("C:\\path"), R"("C:\\path")");
  EXPECT_EQ(sc::json_quoted("a\nb\tc\r"), R"("a\u000ab\u0009c\u000d")");
  EXPECT_EQ(sc::json_quoted(std::string("\x01\x1f", 2)), R"("\u0001\u001f")");
  EXPECT_EQ(sc::json_quoted(std::string("nul\0!", 5)), R"("nul\u0000!")");
  // DEL and UTF-8 bytes (negative as char) are valid in JSON strings: kept as they are.
  EXPECT_EQ(sc::json_quoted("\x7f"), "\"\x7f\"");
  EXPECT_EQ(sc::json_quoted("d\xc3\xa9j\xc3\xa0 vu"), "\"d\xc3\xa9j\xc3\xa0 vu\"");
}

}  // namespace

}  // namespace json_tests
