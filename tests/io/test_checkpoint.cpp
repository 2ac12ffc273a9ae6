// A run continued from a checkpoint (io/checkpoint.hpp, GaussianStream's text form,
// TimeStepper::set_noise): the same variates and the same steps bit for bit as the run that
// went on without stopping; the file read back exactly; bad files refused naming the line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/dynamics/time_stepper.hpp"
#include "stokescontact/io/checkpoint.hpp"
#include "stokescontact/mobility/free_draining.hpp"
#include "stokescontact/scenes/periodic_placement.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace checkpoint_tests {

namespace sc = stokescontact;

namespace {

using RodStepper = sc::TimeStepper<sc::Spherocylinder, sc::FreeDrainingMobility>;

const sc::Spherocylinder kRod{5.0, 0.5};
constexpr std::size_t kRods = 90;
constexpr double kSide = 14.0;  // packing fraction 90 * 4.45 / 14^3 = 0.15

sc::TimeStepperOptions rod_options(double dt) {
  sc::TimeStepperOptions o;
  o.dt = dt;
  o.d_hat = 0.01;
  o.box = sc::PeriodicBox{sc::Vec3::Constant(kSide)};
  o.brownian.emplace();
  o.brownian->kT = 1.0;
  o.brownian->seed = 11;
  return o;
}

std::string text_of(const sc::Checkpoint& c) {
  std::ostringstream out;
  sc::write_checkpoint(out, c);
  return out.str();
}

sc::Checkpoint read_text(const std::string& text) {
  std::istringstream in(text);
  return sc::read_checkpoint(in, "test.checkpoint");
}

void expect_same_poses(const std::vector<sc::Pose>& a, const std::vector<sc::Pose>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x) << "body " << i;
    EXPECT_EQ(a[i].q.coeffs(), b[i].q.coeffs()) << "body " << i;
  }
}

}  // namespace

// After an odd number of variates the stream keeps the pair's second: the text carries it.
TEST(Checkpoint, AStreamReadBackDrawsWhatTheOriginalDraws) {
  for (const int drawn : {0, 3, 4, 1001}) {
    sc::GaussianStream a(2024);
    for (int k = 0; k < drawn; ++k) a();
    std::stringstream text;
    text << a;
    sc::GaussianStream b(7);
    text >> b;
    ASSERT_TRUE(text) << drawn;
    EXPECT_EQ(a, b);
    EXPECT_EQ(b.seed(), 2024u);
    for (int k = 0; k < 1000; ++k) ASSERT_EQ(a(), b()) << "after " << drawn << ", variate " << k;
  }
}

TEST(Checkpoint, MalformedStreamTextLeavesTheStreamAsItWas) {
  sc::GaussianStream g(5);
  g();
  const sc::GaussianStream before = g;
  for (const std::string text : {"", "5 2 0.5", "5 1 0.5 12 13", "x 1 0.5"}) {
    std::istringstream in(text);
    in >> g;
    EXPECT_FALSE(in) << "'" << text << "'";
    EXPECT_EQ(g, before) << "'" << text << "'";
  }
}

// 90 Brownian rods at packing 0.15 in a periodic box, 12 steps with contacts: stopped after 5,
// written, read back and continued by a new stepper, they end where the uninterrupted run ends,
// bit for bit. Without the stream (a new stepper from the seed alone) they do not.
TEST(Checkpoint, AContinuedRunTakesTheSameStepsBitForBit) {
  const std::vector<sc::Pose> start = sc::periodic_random_placement(kRod, kRods, kSide, 0.01, 3);
  const sc::TimeStepperOptions options = rod_options(5e-3);
  const sc::Mat6 body = sc::spherocylinder_mobility(kRod, 1.0);
  sc::FreeDrainingMobility mobility(body, kRods, 6);
  RodStepper whole({kRod}, start, mobility, options);
  std::size_t pushed = 0;
  for (int k = 0; k < 12; ++k) pushed += whole.step().active_pairs;
  EXPECT_GT(pushed, 0u);  // the steps had contacts to resolve

  RodStepper first({kRod}, start, mobility, options);
  first.run(5);
  const sc::Checkpoint c = read_text(text_of(sc::checkpoint_of(first)));
  ASSERT_TRUE(c.noise);
  ASSERT_TRUE(c.box);
  EXPECT_EQ(c.box->lengths, sc::Vec3::Constant(kSide));
  EXPECT_EQ(c.time, first.time());
  expect_same_poses(c.poses, first.poses());

  RodStepper continued({kRod}, c.poses, mobility, options, c.time);
  continued.set_noise(*c.noise);
  continued.run(7);
  expect_same_poses(continued.poses(), whole.poses());
  EXPECT_EQ(continued.noise(), whole.noise());
  EXPECT_NEAR(continued.time(), whole.time(), 1e-15);

  RodStepper reseeded({kRod}, c.poses, mobility, options, c.time);
  reseeded.run(7);
  EXPECT_NE(reseeded.poses()[0].x, whole.poses()[0].x);
}

// Every double read back is the double written (17 significant digits), and the file is
// replaced whole: no partial file is left beside it.
TEST(Checkpoint, TheFileReadsBackExactly) {
  sc::Checkpoint c;
  c.time = 0.1 + 0.2;
  c.box = sc::PeriodicBox{sc::Vec3(1.0 / 3.0, 1e4 + 1e-9, 7.0)};
  c.poses = {{sc::Vec3(-0.0, 1e-300, 1.0 / 7.0), sc::Quat(Eigen::AngleAxisd(1.234567, sc::Vec3(1, 2, 3).normalized()))},
             {sc::Vec3(1e4 + 0.1, -2.5, 3.0), sc::Quat::Identity()}};
  c.noise = sc::GaussianStream(99);
  (*c.noise)();
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "stokescontact_test.checkpoint";
  sc::save_checkpoint(path, c);
  sc::save_checkpoint(path, c);  // over an existing file
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".partial"));
  const sc::Checkpoint back = sc::load_checkpoint(path);
  std::filesystem::remove(path);
  EXPECT_EQ(back.time, c.time);
  EXPECT_EQ(back.box->lengths, c.box->lengths);
  expect_same_poses(back.poses, c.poses);
  EXPECT_EQ(back.noise, c.noise);

  sc::Checkpoint open_space;  // no box, no bodies, no noise
  const sc::Checkpoint empty = read_text(text_of(open_space));
  EXPECT_FALSE(empty.box);
  EXPECT_TRUE(empty.poses.empty());
  EXPECT_FALSE(empty.noise);
}

TEST(Checkpoint, BadFilesAreRefusedNamingTheLine) {
  sc::Checkpoint c;
  c.box = sc::PeriodicBox{sc::Vec3::Constant(10.0)};
  c.poses = {{sc::Vec3(1, 2, 3), sc::Quat::Identity()}, {sc::Vec3(4, 5, 6), sc::Quat::Identity()}};
  c.noise = sc::GaussianStream(1);
  const std::string good = text_of(c);
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  using test_support::expect_rejects;
  expect_rejects([&] { read_text(good.substr(0, good.find("noise"))); }, "ends after line 6, before its 'noise' line");
  expect_rejects([&] { read_text(replaced("checkpoint 1", "checkpoint 2")); }, "line 1: format version 2");
  expect_rejects([&] { read_text(replaced("time 0", "time nan")); }, "line 2");
  expect_rejects([&] { read_text(replaced("box 10 10 10", "box 10 -1 10")); }, "line 3: the box lengths");
  expect_rejects([&] { read_text(replaced("bodies 2", "bodies 3")); }, "line 7: cannot read a pose");
  expect_rejects([&] { read_text(good.substr(0, good.find("4 5 6"))); }, "ends after line 5, before pose 1 of 2");
  expect_rejects([&] { read_text(replaced("bodies 2", "bodies 4000000000000000000")); }, "line 7: cannot read a pose");
  expect_rejects([&] { read_text(replaced("4 5 6 1 0 0 0", "4 5 6 1 0 0 0.5")); }, "line 6: the pose");
  expect_rejects([&] { read_text(replaced("1 2 3 1 0 0 0", "1 2 3 1 0 0")); }, "line 5: cannot read a pose");
  expect_rejects([&] { read_text(replaced("noise 1 0", "noise 1 7")); }, "line 7: cannot read the Brownian stream");
  expect_rejects([&] { read_text(replaced("end", "en")); }, "line 8: expected 'end'");
  expect_rejects([&] { sc::load_checkpoint("/nonexistent/run.checkpoint"); }, "cannot open /nonexistent/run.checkpoint");
  sc::Checkpoint bad = c;
  bad.poses[1].x[0] = std::nan("");
  expect_rejects([&] { text_of(bad); }, "checkpoint.poses[1].x");
}

}  // namespace checkpoint_tests
