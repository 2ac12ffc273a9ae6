#pragma once
// Reading a JSON document with every error naming its key path, e.g.
// `bodies.poses[3].position: must have 3 numbers, got 2`. A JsonReader is a view of one value
// and its path; objects must say which keys they know (known_keys), so a misspelt key stops the
// run instead of being ignored.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <stokescontact/core/types.hpp>

namespace stokescontact::apps {

// A scene that cannot run; what() is "<key path>: <why>".
class SceneError : public std::invalid_argument {
 public:
  SceneError(const std::string& path, const std::string& why)
      : std::invalid_argument((path.empty() ? std::string("scene") : path) + ": " + why) {}
};

inline std::string json_type_name(const nlohmann::json& j) {
  if (j.is_number()) return "a number";
  if (j.is_string()) return "a string";
  if (j.is_boolean()) return "a boolean";
  if (j.is_array()) return "an array";
  if (j.is_object()) return "an object";
  return "null";
}

class JsonReader {
 public:
  JsonReader(const nlohmann::json& value, std::string path) : value_(&value), path_(std::move(path)) {}

  const std::string& path() const { return path_; }
  const nlohmann::json& json() const { return *value_; }
  [[noreturn]] void fail(const std::string& why) const { throw SceneError(path_, why); }

  // An object whose keys all lie in `known`.
  void known_keys(std::initializer_list<std::string_view> known) const {
    require_object();
    for (auto it = value_->begin(); it != value_->end(); ++it) {
      bool ok = false;
      for (std::string_view k : known) ok = ok || it.key() == k;
      if (ok) continue;
      std::string list;
      for (std::string_view k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      throw SceneError(child_path(it.key()), "unknown key (known here: " + list + ")");
    }
  }

  bool has(std::string_view key) const { return value_->is_object() && value_->contains(key); }

  JsonReader at(std::string_view key) const {
    require_object();
    if (!value_->contains(key)) throw SceneError(child_path(key), "is required");
    return JsonReader(value_->at(std::string(key)), child_path(key));
  }

  std::optional<JsonReader> find(std::string_view key) const {
    if (!has(key)) return std::nullopt;
    return at(key);
  }

  JsonReader element(std::size_t k) const {
    return JsonReader(value_->at(k), path_ + "[" + std::to_string(k) + "]");
  }

  std::size_t array_size() const {
    if (!value_->is_array()) fail("must be an array, got " + json_type_name(*value_));
    return value_->size();
  }

  double number() const {
    if (!value_->is_number()) fail("must be a number, got " + json_type_name(*value_));
    const double x = value_->get<double>();
    if (!std::isfinite(x)) fail("must be finite");
    return x;
  }

  double positive() const {
    const double x = number();
    if (!(x > 0.0)) fail("must be > 0, got " + format(x));
    return x;
  }

  double non_negative() const {
    const double x = number();
    if (!(x >= 0.0)) fail("must be >= 0, got " + format(x));
    return x;
  }

  // An integer in [lo, hi] (JSON numbers like 3.0 count; 3.5 does not).
  long long integer(long long lo, long long hi = std::numeric_limits<long long>::max()) const {
    const double x = number();
    if (x != std::floor(x) || std::abs(x) > 9.0e15) fail("must be an integer, got " + format(x));
    const auto k = static_cast<long long>(x);
    if (k < lo || k > hi)
      fail("must lie in [" + std::to_string(lo) + ", " +
           (hi == std::numeric_limits<long long>::max() ? std::string("inf") : std::to_string(hi)) + "], got " +
           std::to_string(k));
    return k;
  }

  std::uint64_t seed() const { return static_cast<std::uint64_t>(integer(0)); }

  bool boolean() const {
    if (!value_->is_boolean()) fail("must be true or false, got " + json_type_name(*value_));
    return value_->get<bool>();
  }

  std::string text() const {
    if (!value_->is_string()) fail("must be a string, got " + json_type_name(*value_));
    return value_->get<std::string>();
  }

  // One of `choices`.
  std::string choice(std::initializer_list<std::string_view> choices) const {
    const std::string s = text();
    std::string list;
    for (std::string_view c : choices) {
      if (s == c) return s;
      list += (list.empty() ? "" : ", ") + std::string(c);
    }
    fail("unknown value '" + s + "' (known: " + list + ")");
  }

  Vec3 vec3() const {
    if (!value_->is_array() || value_->size() != 3)
      fail("must be an array of 3 numbers, got " +
           (value_->is_array() ? std::to_string(value_->size()) + " entries" : json_type_name(*value_)));
    return Vec3(element(0).number(), element(1).number(), element(2).number());
  }

  // A unit quaternion [w, x, y, z] (normalised when within 1e-6 of unit length).
  Quat quaternion() const {
    if (!value_->is_array() || value_->size() != 4)
      fail("must be a quaternion [w, x, y, z] of 4 numbers, got " +
           (value_->is_array() ? std::to_string(value_->size()) + " entries" : json_type_name(*value_)));
    Quat q(element(0).number(), element(1).number(), element(2).number(), element(3).number());
    if (std::abs(q.norm() - 1.0) > 1e-6) fail("must have unit length, got |q| = " + format(q.norm()));
    return q.normalized();
  }

  // A 3x3 matrix as 3 rows of 3 numbers.
  Mat3 mat3() const {
    if (!value_->is_array() || value_->size() != 3) fail("must be 3 rows of 3 numbers");
    Mat3 m;
    for (std::size_t r = 0; r < 3; ++r) m.row(static_cast<Eigen::Index>(r)) = element(r).vec3().transpose();
    return m;
  }

  static std::string format(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", x);
    return buf;
  }

 private:
  void require_object() const {
    if (!value_->is_object()) fail("must be an object, got " + json_type_name(*value_));
  }
  std::string child_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  const nlohmann::json* value_;
  std::string path_;
};

}  // namespace stokescontact::apps
