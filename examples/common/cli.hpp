#pragma once
// Command-line options of the experiment drivers ("--name value" or "--flag"), strictly
// checked: a malformed number, a missing value, a repeated or unknown option is an error
// (std::invalid_argument with the option's name); main prints it with the usage, exits 2.
// Plus the order statistics the drivers' summary tables use.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace examples {

class Arguments {
 public:
  Arguments(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
      const std::string key = argv[i];
      if (key.size() < 3 || key.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument '" + key + "'");
      std::optional<std::string> value;
      if (i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0) value = argv[++i];
      if (!values_.emplace(key, value).second) throw std::invalid_argument(key + " given twice");
    }
  }

  bool flag(const std::string& key) {
    const auto it = find(key);
    if (it == values_.end()) return false;
    if (it->second) throw std::invalid_argument(key + " takes no value, got '" + *it->second + "'");
    return true;
  }

  std::string text(const std::string& key, const std::string& fallback) {
    const auto it = find(key);
    return it == values_.end() ? fallback : value(it);
  }

  // A finite number; min_value (inclusive) when given.
  double number(const std::string& key, double fallback, double min_value = -std::numeric_limits<double>::infinity()) {
    const auto it = find(key);
    return it == values_.end() ? fallback : parse_number(key, value(it), min_value);
  }

  // A number > 0, or none when the option is absent.
  std::optional<double> positive(const std::string& key) {
    const auto it = find(key);
    if (it == values_.end()) return std::nullopt;
    const double out = parse_number(key, value(it), -std::numeric_limits<double>::infinity());
    if (!(out > 0.0)) throw std::invalid_argument(key + " must be > 0, got " + value(it));
    return out;
  }

  std::int64_t integer(const std::string& key, std::int64_t fallback, std::int64_t min_value) {
    const auto it = find(key);
    if (it == values_.end()) return fallback;
    const std::string v = value(it);
    std::size_t used = 0;
    std::int64_t out = 0;
    try {
      out = std::stoll(v, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != v.size()) throw std::invalid_argument(key + " needs an integer, got '" + v + "'");
    if (out < min_value) throw std::invalid_argument(key + " must be >= " + std::to_string(min_value) + ", got " + v);
    return out;
  }

  // A comma-separated list ("a,b,c"); fallback when absent.
  std::vector<std::string> list(const std::string& key, const std::vector<std::string>& fallback) {
    const auto it = find(key);
    if (it == values_.end()) return fallback;
    std::vector<std::string> items;
    const std::string v = value(it);
    for (std::size_t begin = 0;;) {
      const std::size_t end = v.find(',', begin);
      items.push_back(v.substr(begin, end - begin));
      if (items.back().empty()) throw std::invalid_argument(key + " has an empty item in '" + v + "'");
      if (end == std::string::npos) break;
      begin = end + 1;
    }
    return items;
  }

  std::vector<double> numbers(const std::string& key, const std::vector<double>& fallback, double min_value) {
    if (find(key) == values_.end()) return fallback;
    std::vector<double> out;
    for (const std::string& item : list(key, {})) out.push_back(parse_number(key, item, min_value));
    return out;
  }

  // After every option was read: the ones no one asked for are errors.
  void reject_unknown() const {
    for (const auto& [key, v] : values_)
      if (!read_.contains(key)) throw std::invalid_argument("unknown option " + key);
  }

 private:
  using Map = std::map<std::string, std::optional<std::string>>;

  Map::const_iterator find(const std::string& key) {
    read_.insert(key);
    return values_.find(key);
  }

  static std::string value(Map::const_iterator it) {
    if (!it->second) throw std::invalid_argument(it->first + " needs a value");
    return *it->second;
  }

  static double parse_number(const std::string& key, const std::string& v, double min_value) {
    std::size_t used = 0;
    double out = 0.0;
    try {
      out = std::stod(v, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != v.size() || !std::isfinite(out))
      throw std::invalid_argument(key + " needs a finite number, got '" + v + "'");
    if (out < min_value) throw std::invalid_argument(key + " must be >= " + shortest(min_value) + ", got " + v);
    return out;
  }

  static std::string shortest(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", x);
    return buf;
  }

  Map values_;
  std::set<std::string> read_;
};

// Where a driver's JSON lines go: the --output file, or stdout when none is given. With a
// file, stdout gets the (optional) progress line instead.
class JsonLines {
 public:
  explicit JsonLines(const std::string& path) {
    if (path.empty()) return;
    file_.open(path);
    if (!file_) throw std::runtime_error("cannot write " + path);
  }

  bool to_file() const { return file_.is_open(); }

  void line(const std::string& json, const std::string& progress = "") {
    if (!to_file()) {
      std::printf("%s\n", json.c_str());
    } else {
      file_ << json << '\n' << std::flush;
      if (!progress.empty()) std::printf("%s\n", progress.c_str());
    }
    std::fflush(stdout);
  }

 private:
  std::ofstream file_;
};

// Order statistics of a sample (NaN for an empty one).
inline double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(v.begin(), mid));
}

inline double minimum(const std::vector<double>& v) {
  return v.empty() ? std::numeric_limits<double>::quiet_NaN() : *std::min_element(v.begin(), v.end());
}

inline double maximum(const std::vector<double>& v) {
  return v.empty() ? std::numeric_limits<double>::quiet_NaN() : *std::max_element(v.begin(), v.end());
}

// A driver's main: `parse` throwing std::invalid_argument prints the error and the usage
// (exit 2), `run` throwing anything prints the error (exit 1). A `run` that returns an int
// gives the exit status itself (a run that found an ERROR); one that returns nothing exits 0.
// stdout is line-buffered, redirected or not: each JSON line reaches its file when printed, so
// a long run stopped by a signal (timeout, a killed job) keeps every line it wrote.
template <typename Parse, typename Run>
int driver_main(const char* name, const char* usage, Parse&& parse, Run&& run) {
  std::setvbuf(stdout, nullptr, _IOLBF, BUFSIZ);
  try {
    parse();
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "%s: %s\n%s", name, e.what(), usage);
    return 2;
  }
  try {
    if constexpr (std::is_same_v<decltype(run()), int>) return run();
    else run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 1;
  }
  return 0;
}

}  // namespace examples
