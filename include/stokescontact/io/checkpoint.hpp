#pragma once
// A run's state written to a file and read back, to continue the run later (long Brownian
// melts span many processes): the time, the periodic box, Q_t and the Brownian stream.
// Continued from the file, a TimeStepper draws the same variates and, with the same options
// and solver, takes the same steps bit for bit as the run that wrote it would have
// (tests/io/test_checkpoint.cpp):
//   save_checkpoint("melt.checkpoint", checkpoint_of(stepper));
//   ...
//   const Checkpoint c = load_checkpoint("melt.checkpoint");
//   TimeStepper<S, M> next(shapes, c.poses, mobility, options, c.time);
//   if (c.noise) next.set_noise(*c.noise);
// The file is text, one item per line, every double with 17 significant digits (which
// read back to the same double):
//   stokescontact-checkpoint 1
//   time <t>
//   box none | box <Lx> <Ly> <Lz>
//   bodies <N>
//   <x> <y> <z> <qw> <qx> <qy> <qz>        (N lines, one pose each)
//   noise none | noise <the stream's state: core/gaussian_stream.hpp>
//   end
// Reading checks every line and throws std::invalid_argument naming the file, the line and
// what is wrong (a truncated file, a pose that is not finite or not a unit quaternion, ...).
// save_checkpoint writes a temporary file beside the target and renames it over the target,
// so an interrupted run never leaves a half-written checkpoint.
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <ios>
#include <istream>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "stokescontact/core/errors.hpp"
#include "stokescontact/core/gaussian_stream.hpp"
#include "stokescontact/core/pose.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/geometry/periodic_box.hpp"

namespace stokescontact {

struct Checkpoint {
  double time = 0.0;
  std::optional<PeriodicBox> box;       // none: open space
  std::vector<Pose> poses;              // Q_t
  std::optional<GaussianStream> noise;  // none: a run without Brownian motion
};

// The stepper's state now; the noise only when its options have Brownian motion.
template <Shape S, MobilityOperator M>
Checkpoint checkpoint_of(const TimeStepper<S, M>& stepper) {
  Checkpoint c{stepper.time(), stepper.options().box, stepper.poses(), std::nullopt};
  if (stepper.options().brownian) c.noise = stepper.noise();
  return c;
}

inline void write_checkpoint(std::ostream& out, const Checkpoint& c) {
  require_finite(c.time, "checkpoint.time");
  if (c.box)
    for (int a = 0; a < 3; ++a) require_positive(c.box->lengths[a], "checkpoint.box.lengths");
  validate(std::span<const Pose>(c.poses), "checkpoint.poses");
  const std::ios_base::fmtflags flags = out.flags();
  const std::streamsize precision = out.precision();
  out.precision(17);
  out << std::defaultfloat << "stokescontact-checkpoint 1\ntime " << c.time << "\nbox";
  if (c.box)
    out << ' ' << c.box->lengths[0] << ' ' << c.box->lengths[1] << ' ' << c.box->lengths[2] << '\n';
  else
    out << " none\n";
  out << "bodies " << c.poses.size() << '\n';
  for (const Pose& p : c.poses)
    out << p.x[0] << ' ' << p.x[1] << ' ' << p.x[2] << ' ' << p.q.w() << ' ' << p.q.x() << ' ' << p.q.y() << ' '
        << p.q.z() << '\n';
  out << "noise";
  if (c.noise)
    out << ' ' << *c.noise << '\n';
  else
    out << " none\n";
  out << "end\n";
  out.flags(flags);
  out.precision(precision);
}

namespace detail {

// Line-by-line reading of a checkpoint: each failure names the source and the line.
class CheckpointReader {
 public:
  CheckpointReader(std::istream& in, std::string_view source) : in_(in), source_(source) {}

  // The next line's words after `keyword` (which must open it).
  std::istringstream line(std::string_view keyword) {
    std::string text;
    if (!std::getline(in_, text)) fail_at_end("its '" + std::string(keyword) + "' line");
    ++number_;
    std::istringstream words(text);
    std::string first;
    words >> first;
    if (first != keyword) fail("expected '" + std::string(keyword) + "', got '" + text.substr(0, 60) + "'");
    return words;
  }

  // The next line into `words`; false at the end of the input.
  bool next_line(std::istringstream& words) {
    std::string text;
    if (!std::getline(in_, text)) return false;
    ++number_;
    words = std::istringstream(text);
    return true;
  }

  // Nothing but white space may follow what was read from `words`.
  void finish(std::istringstream& words, std::string_view what) {
    std::string rest;
    if (!words || (words >> rest)) fail("cannot read " + std::string(what));
  }

  [[noreturn]] void fail(const std::string& why) const {
    fail_argument("checkpoint", std::string(source_) + ", line " + std::to_string(number_) + ": " + why);
  }

  [[noreturn]] void fail_at_end(std::string_view missing) const {
    fail_argument("checkpoint", std::string(source_) + " ends after line " + std::to_string(number_) + ", before " +
                                    std::string(missing));
  }

 private:
  std::istream& in_;
  std::string_view source_;
  std::size_t number_ = 0;
};

}  // namespace detail

// `source` names the input in error messages (a file name).
inline Checkpoint read_checkpoint(std::istream& in, std::string_view source = "checkpoint") {
  detail::CheckpointReader r(in, source);
  Checkpoint c;
  {
    std::istringstream header = r.line("stokescontact-checkpoint");
    int version = 0;
    header >> version;
    r.finish(header, "the format version");
    if (version != 1) r.fail("format version " + std::to_string(version) + " is not 1");
  }
  {
    std::istringstream time = r.line("time");
    time >> c.time;
    r.finish(time, "the time");
    if (!std::isfinite(c.time)) r.fail("the time is not finite");
  }
  {
    std::istringstream box = r.line("box");
    std::string first;
    box >> first;
    if (first != "none") {
      PeriodicBox b;
      std::istringstream lengths(first);
      lengths >> b.lengths[0];
      box >> b.lengths[1] >> b.lengths[2];
      if (!lengths) r.fail("cannot read the box");
      r.finish(box, "the box: 'none' or three lengths");
      if (!(b.lengths.minCoeff() > 0.0) || !b.lengths.allFinite()) r.fail("the box lengths must be finite and > 0");
      c.box = b;
    }
  }
  long long bodies = -1;
  {
    std::istringstream count = r.line("bodies");
    count >> bodies;
    r.finish(count, "the number of bodies");
    if (bodies < 0) r.fail("the number of bodies must be >= 0");
  }
  // Pose by pose as read (no storage claimed for a count the file may not hold).
  for (long long k = 0; k < bodies; ++k) {
    std::istringstream words;
    if (!r.next_line(words)) r.fail_at_end("pose " + std::to_string(k) + " of " + std::to_string(bodies));
    Pose p;
    double w = 0.0, x = 0.0, y = 0.0, z = 0.0;
    words >> p.x[0] >> p.x[1] >> p.x[2] >> w >> x >> y >> z;
    r.finish(words, "a pose: x y z qw qx qy qz");
    p.q = Quat(w, x, y, z);
    if (!is_valid(p)) r.fail("the pose is not finite or its quaternion is not of unit length");
    c.poses.push_back(p);
  }
  {
    std::istringstream noise = r.line("noise");
    std::string rest;
    const std::streampos start = noise.tellg();
    noise >> rest;
    if (rest != "none") {
      noise.clear();
      noise.seekg(start);
      GaussianStream stream(0);
      noise >> stream;
      r.finish(noise, "the Brownian stream's state");
      c.noise = stream;
    } else {
      r.finish(noise, "'noise none'");
    }
  }
  {
    std::istringstream end = r.line("end");
    r.finish(end, "'end'");
  }
  return c;
}

inline void save_checkpoint(const std::filesystem::path& path, const Checkpoint& c) {
  std::filesystem::path temporary = path;
  temporary += ".partial";
  {
    std::ofstream out(temporary);
    if (!out) fail_argument("checkpoint", "cannot write " + temporary.string());
    write_checkpoint(out, c);
    out.flush();
    if (!out) fail_argument("checkpoint", "writing " + temporary.string() + " failed");
  }
  std::filesystem::rename(temporary, path);
}

inline Checkpoint load_checkpoint(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) fail_argument("checkpoint", "cannot open " + path.string());
  return read_checkpoint(in, path.string());
}

}  // namespace stokescontact
