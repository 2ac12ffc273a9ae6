// Body meshes (io/body_mesh.hpp) and the VTK XML writers (io/vtk_polydata.hpp): every vertex
// one radius from the centre curve, closed and outward-oriented meshes whose volume approaches
// the shape's, PolyData and .pvd files whose counts and values parse back, and bad input refused.
// tests/io/read_vtk_series.py reads the files again with VTK's own reader (test vtk_readback).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/test_support.hpp"
#include "stokescontact/geometry/line_contact.hpp"
#include "stokescontact/io/vtk_polydata.hpp"

// The whole file in its own namespace: tests of one layer are compiled together (unity build).
namespace vtk_polydata_tests {

namespace sc = stokescontact;
namespace fs = std::filesystem;

namespace {

static_assert(sc::Shape<sc::LineContactRod>, "a LineContactRod is drawn as its rod");

sc::Pose some_pose(unsigned seed) {
  test_support::Rng rng(seed);
  return {test_support::uniform_vector(rng, -3.0, 3.0), test_support::random_rotation(rng)};
}

// Distance from q to the segment [a, b], written out here (not point_distance.hpp's).
double segment_distance(const sc::Vec3& a, const sc::Vec3& b, const sc::Vec3& q) {
  const sc::Vec3 d = b - a;
  double s = (q - a).dot(d) / d.squaredNorm();
  s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
  return (q - (a + s * d)).norm();
}

double signed_volume(const sc::BodyMesh& m) {
  double v = 0.0;
  for (const auto& t : m.triangles) {
    sc::Mat3 abc;
    abc << m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]];
    v += abc.determinant() / 6.0;
  }
  return v;
}

// Closed and consistently oriented: each directed edge once, and its reverse once.
void expect_watertight(const sc::BodyMesh& m) {
  std::map<std::pair<std::size_t, std::size_t>, int> directed;
  for (const auto& t : m.triangles)
    for (int e = 0; e < 3; ++e) ++directed[{t[e], t[(e + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << "edge " << edge.first << "-" << edge.second;
    const auto reverse = directed.find({edge.second, edge.first});
    ASSERT_NE(reverse, directed.end()) << "edge " << edge.first << "-" << edge.second << " is on one triangle";
    EXPECT_EQ(reverse->second, 1);
  }
  // Euler characteristic of a sphere: V - E + F = 2.
  const long v = static_cast<long>(m.vertices.size()), f = static_cast<long>(m.triangles.size());
  EXPECT_EQ(v - static_cast<long>(directed.size() / 2) + f, 2);
}

template <sc::Shape S>
void expect_closed_outward_volume(const S& shape) {
  const sc::BodyMesh coarse = sc::body_mesh(shape);
  expect_watertight(coarse);
  const double exact = sc::volume(shape);
  EXPECT_GT(signed_volume(coarse), 0.0);
  EXPECT_NEAR(signed_volume(coarse) / exact, 1.0, 0.05);
  const sc::BodyMesh fine = sc::body_mesh(shape, {64, 32, 0});
  expect_watertight(fine);
  EXPECT_NEAR(signed_volume(fine) / exact, 1.0, 0.005);
  // Rigid motions keep all of it.
  EXPECT_NEAR(signed_volume(sc::posed(coarse, some_pose(3))), signed_volume(coarse), 1e-12 * exact);
}

TEST(BodyMesh, SphereVerticesOnSurfaceAndCounts) {
  const sc::Sphere s{0.7};
  const sc::Pose pose = some_pose(1);
  for (const sc::BodyMeshOptions o : {sc::BodyMeshOptions{}, sc::BodyMeshOptions{5, 1, 0}, sc::BodyMeshOptions{24, 11, 0}}) {
    const sc::BodyMesh m = sc::posed(sc::body_mesh(s, o), pose);
    const std::size_t rings = 2 * (o.cap_rings - 1) + 1;
    EXPECT_EQ(m.vertices.size(), o.ring_points * rings + 2);
    EXPECT_EQ(m.triangles.size(), 2 * o.ring_points * rings);
    ASSERT_EQ(m.normals.size(), m.vertices.size());
    for (std::size_t i = 0; i < m.vertices.size(); ++i) {
      EXPECT_NEAR((m.vertices[i] - pose.x).norm(), s.radius, 1e-12 * s.radius);
      EXPECT_NEAR((m.normals[i] - (m.vertices[i] - pose.x) / s.radius).norm(), 0.0, 1e-12);
    }
  }
}

TEST(BodyMesh, CapsuleVerticesOnSurface) {
  const sc::Spherocylinder rod{2.5, 0.4};
  const sc::Pose pose = some_pose(2);
  const sc::Vec3 a = pose.to_world(sc::Vec3(0, 0, -1.25)), b = pose.to_world(sc::Vec3(0, 0, 1.25));
  const sc::BodyMesh m = sc::posed(sc::body_mesh(rod), pose);
  EXPECT_EQ(m.vertices.size(), 16u * (2 * 7 + 2) + 2);
  for (const sc::Vec3& v : m.vertices) EXPECT_NEAR(segment_distance(a, b, v), rod.radius, 1e-12 * rod.radius);
  // A rod of zero length is a sphere.
  EXPECT_EQ(sc::body_mesh(sc::Spherocylinder{0.0, 0.4}).vertices.size(), sc::body_mesh(sc::Sphere{0.4}).vertices.size());
}

TEST(BodyMesh, BoomerangVerticesOnSurface) {
  for (const sc::Boomerang& boomerang : {sc::broms_tornberg_boomerang(), sc::Boomerang{0.8, 0.3, 0.9},
                                         sc::Boomerang{0.0, 0.3, 0.6}}) {
    const sc::Pose pose = some_pose(4);
    const auto curve = sc::to_world(sc::centre_curve(boomerang), pose);
    const sc::BodyMesh m = sc::posed(sc::body_mesh(boomerang), pose);
    // 8 arc pieces at 16 ring points; arms add a ring each at their tips.
    const std::size_t samples = boomerang.arm_length > 0.0 ? 11 : 9;
    EXPECT_EQ(m.vertices.size(), 16 * (14 + samples) + 2);
    for (const sc::Vec3& v : m.vertices)
      EXPECT_NEAR(sc::closest_point(curve, v).distance, boomerang.radius, 1e-12 * boomerang.radius);
  }
}

TEST(BodyMesh, ClosedOutwardAndVolumeConverges) {
  expect_closed_outward_volume(sc::Sphere{0.7});
  expect_closed_outward_volume(sc::Spherocylinder{2.5, 0.4});
  expect_closed_outward_volume(sc::Spherocylinder{0.0, 0.4});
  expect_closed_outward_volume(sc::broms_tornberg_boomerang());
  expect_closed_outward_volume(sc::Boomerang{0.8, 0.3, 0.9});
  expect_closed_outward_volume(sc::LineContactRod{{3.0, 0.5}, {0.1, 0.2}});
}

// The tube's rings follow the bend without twisting: the vertex j of consecutive rings are as
// close as the rings' centres allow (at most (bend_radius + radius) / bend_radius apart).
TEST(BodyMesh, RingsDoNotTwistThroughTheBend) {
  const sc::Boomerang b{0.8, 0.3, 0.9};
  const sc::BodyMesh m = sc::body_mesh(b);
  const std::size_t ring_points = 16, first_tube_ring = 7, tube_rings = 11;
  for (std::size_t q = first_tube_ring; q + 1 < first_tube_ring + tube_rings; ++q) {
    const auto v = [&](std::size_t ring, std::size_t j) { return m.vertices[1 + ring * ring_points + j]; };
    sc::Vec3 c0 = sc::Vec3::Zero(), c1 = sc::Vec3::Zero();
    for (std::size_t j = 0; j < ring_points; ++j) {
      c0 += v(q, j) / ring_points;
      c1 += v(q + 1, j) / ring_points;
    }
    for (std::size_t j = 0; j < ring_points; ++j)
      EXPECT_LE((v(q + 1, j) - v(q, j)).norm(), (c1 - c0).norm() * (b.bend_radius + b.radius) / b.bend_radius + 1e-12)
          << "ring " << q << " vertex " << j;
  }
}

TEST(BodyMesh, LineContactRodIsDrawnAsItsRod) {
  const sc::LineContactRod rod{{3.0, 0.5}, {0.1, 0.2}};
  const sc::BodyMesh a = sc::body_mesh(rod), b = sc::body_mesh(sc::Spherocylinder{3.0, 0.5});
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i) EXPECT_EQ(a.vertices[i], b.vertices[i]);
  EXPECT_EQ(a.triangles, b.triangles);
}

// --- files ---------------------------------------------------------------------------------

fs::path scratch_directory() {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::path(testing::TempDir()) / (std::string("vtk_") + info->test_suite_name() + "_" + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The value of attribute `name` in the first element that starts with `tag` at or after `from`.
std::string attribute(const std::string& xml, const std::string& tag, const std::string& name, std::size_t from = 0) {
  const std::size_t at = xml.find(tag, from);
  if (at == std::string::npos) return {};
  const std::size_t end = xml.find('>', at);
  const std::size_t a = xml.find(" " + name + "=\"", at);
  if (a == std::string::npos || a > end) return {};
  const std::size_t start = a + name.size() + 3;
  return xml.substr(start, xml.find('"', start) - start);
}

// The numbers of the DataArray whose opening tag contains `key` (e.g. Name="centre").
std::vector<double> array_values(const std::string& xml, const std::string& key, std::size_t from = 0) {
  const std::size_t at = xml.find(key, from);
  if (at == std::string::npos) return {};
  const std::size_t open = xml.find('>', at) + 1, close = xml.find("</DataArray>", open);
  std::istringstream in(xml.substr(open, close - open));
  std::vector<double> values;
  for (std::string word; in >> word;) values.push_back(std::strtod(word.c_str(), nullptr));
  return values;
}

TEST(VtkPolyData, FrameParsesBack) {
  const fs::path dir = scratch_directory();
  const std::vector<sc::Spherocylinder> rods{{2.0, 0.4}, {1.0, 0.3}, {0.0, 0.2}};
  const std::vector<sc::Pose> poses{some_pose(5), some_pose(6), some_pose(7)};
  const std::vector<sc::BodyField> fields{{"velocity", 3, {1, 2, 3, 4, 5, 6, 7, 8, 9}}, {"energy", 1, {0.5, -1.0 / 3.0, 2}}};
  sc::write_vtp(dir / "rods.vtp", 0.125, rods, poses, fields);
  const std::string xml = read_text(dir / "rods.vtp");
  EXPECT_NE(xml.find("<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"),
            std::string::npos);

  std::size_t points = 0, triangles = 0;
  for (const auto& rod : rods) {
    const sc::BodyMesh m = sc::body_mesh(rod);
    points += m.vertices.size();
    triangles += m.triangles.size();
  }
  EXPECT_EQ(attribute(xml, "<Piece", "NumberOfPoints"), std::to_string(points));
  EXPECT_EQ(attribute(xml, "<Piece", "NumberOfPolys"), std::to_string(triangles));
  EXPECT_EQ(array_values(xml, "<DataArray", xml.find("<Points>")).size(), 3 * points);
  EXPECT_EQ(array_values(xml, "Name=\"connectivity\"").size(), 3 * triangles);
  const std::vector<double> offsets = array_values(xml, "Name=\"offsets\"");
  ASSERT_EQ(offsets.size(), triangles);
  EXPECT_EQ(offsets.back(), 3.0 * triangles);
  const std::vector<double> body_id = array_values(xml, "Name=\"body_id\"");
  ASSERT_EQ(body_id.size(), points);
  EXPECT_EQ(body_id.front(), 0.0);
  EXPECT_EQ(body_id.back(), 2.0);

  EXPECT_EQ(array_values(xml, "Name=\"TIME\""), std::vector<double>{0.125});
  EXPECT_EQ(array_values(xml, "Name=\"TimeValue\""), std::vector<double>{0.125});
  const std::vector<double> centre = array_values(xml, "Name=\"centre\""), q = array_values(xml, "Name=\"orientation_quaternion\"");
  const std::vector<double> axis = array_values(xml, "Name=\"axis\""), length = array_values(xml, "Name=\"length\"");
  ASSERT_EQ(centre.size(), 9u);
  ASSERT_EQ(q.size(), 12u);
  ASSERT_EQ(axis.size(), 9u);
  for (std::size_t k = 0; k < 3; ++k) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(centre[3 * k + c], poses[k].x[c]);  // round-trips exactly
    EXPECT_EQ(q[4 * k], poses[k].q.w());
    for (int c = 0; c < 3; ++c) EXPECT_EQ(q[4 * k + 1 + c], poses[k].q.vec()[c]);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(axis[3 * k + c], poses[k].rotation()(c, 2), 1e-15);
    EXPECT_EQ(length[k], rods[k].length);
  }
  EXPECT_EQ(array_values(xml, "Name=\"radius\""), (std::vector<double>{0.4, 0.3, 0.2}));
  EXPECT_EQ(attribute(xml, "Name=\"velocity\"", "NumberOfTuples"), "3");  // the FieldData copy first
  EXPECT_EQ(array_values(xml, "Name=\"energy\"")[1], -1.0 / 3.0);
  const std::size_t point_data = xml.find("<PointData");
  const std::vector<double> velocity_points = array_values(xml, "Name=\"velocity\"", point_data);
  ASSERT_EQ(velocity_points.size(), 3 * points);
  EXPECT_EQ(velocity_points.back(), 9.0);
  EXPECT_EQ(array_values(xml, "Name=\"Normals\"", point_data).size(), 3 * points);
  EXPECT_EQ(xml.find("Name=\"arm_length\""), std::string::npos);  // rods have none
}

TEST(VtkPolyData, SharedShapeAndBoomerangParameters) {
  const fs::path dir = scratch_directory();
  const sc::Boomerang b = sc::broms_tornberg_boomerang();
  sc::write_vtp(dir / "b.vtp", 1.0, b, std::vector<sc::Pose>{some_pose(8), some_pose(9)});
  const std::string xml = read_text(dir / "b.vtp");
  EXPECT_EQ(attribute(xml, "<Piece", "NumberOfPoints"), std::to_string(2 * sc::body_mesh(b).vertices.size()));
  EXPECT_EQ(array_values(xml, "Name=\"arm_length\""), (std::vector<double>{1.5, 1.5}));
  EXPECT_EQ(array_values(xml, "Name=\"bend_radius\""), (std::vector<double>{0.5, 0.5}));
  // No bodies: a valid empty frame.
  sc::write_vtp(dir / "none.vtp", 0.0, b, std::vector<sc::Pose>{});
  EXPECT_EQ(attribute(read_text(dir / "none.vtp"), "<Piece", "NumberOfPoints"), "0");
}

TEST(VtkSeries, PvdListsTheFramesWrittenSoFar) {
  const fs::path dir = scratch_directory();
  sc::VtkSeriesWriter series(dir, "spheres", {8, 4, 0});
  const sc::Sphere s{0.5};
  const std::vector<double> times{0.0, 0.1, 0.30000000000000004};
  for (std::size_t f = 0; f < times.size(); ++f) {
    const fs::path frame = series.write_frame(times[f], s, std::vector<sc::Pose>{some_pose(10 + f)});
    EXPECT_TRUE(fs::exists(frame));
    EXPECT_EQ(series.frames(), f + 1);
    const std::string pvd = read_text(series.pvd_path());
    EXPECT_NE(pvd.find("<VTKFile type=\"Collection\" version=\"0.1\""), std::string::npos);
    std::size_t at = 0;
    for (std::size_t g = 0; g <= f; ++g) {
      at = pvd.find("<DataSet", at);
      ASSERT_NE(at, std::string::npos) << pvd;
      EXPECT_EQ(std::strtod(attribute(pvd, "<DataSet", "timestep", at).c_str(), nullptr), times[g]);
      char name[32];
      std::snprintf(name, sizeof name, "spheres_%06zu.vtp", g);
      EXPECT_EQ(attribute(pvd, "<DataSet", "file", at), name);
      EXPECT_EQ(array_values(read_text(dir / name), "Name=\"TIME\""), std::vector<double>{times[g]});
      ++at;
    }
    EXPECT_EQ(pvd.find("<DataSet", at), std::string::npos);
  }
  for (const auto& entry : fs::directory_iterator(dir)) EXPECT_NE(entry.path().extension(), ".tmp");
}

TEST(VtkSeries, RejectsBadInput) {
  using test_support::expect_rejects;
  const fs::path dir = scratch_directory();
  expect_rejects([&] { sc::VtkSeriesWriter(dir / "missing", "x"); }, "directory");
  std::ofstream(dir / "file") << "x";
  expect_rejects([&] { sc::VtkSeriesWriter(dir / "file", "x"); }, "directory");
  expect_rejects([&] { sc::VtkSeriesWriter(dir, ""); }, "stem");
  expect_rejects([&] { sc::VtkSeriesWriter(dir, "a/b"); }, "stem");
  expect_rejects([&] { sc::VtkSeriesWriter(dir, "x", {2, 8, 0}); }, "BodyMeshOptions.ring_points");
  expect_rejects([&] { sc::VtkSeriesWriter(dir, "x", {16, 0, 0}); }, "BodyMeshOptions.cap_rings");

  sc::VtkSeriesWriter series(dir, "rods");
  const std::vector<sc::Spherocylinder> rods(2, sc::Spherocylinder{1.0, 0.2});
  std::vector<sc::Pose> poses{some_pose(20), some_pose(21)};
  expect_rejects([&] { series.write_frame(0.0, rods, std::vector<sc::Pose>{poses[0]}); }, "shapes");
  expect_rejects([&] { series.write_frame(0.0, sc::Spherocylinder{1.0, -0.2}, poses); }, "Spherocylinder.radius");
  expect_rejects([&] { series.write_frame(std::nan(""), rods, poses); }, "time");
  std::vector<sc::Pose> bad = poses;
  bad[1].x.y() = std::numeric_limits<double>::infinity();
  expect_rejects([&] { series.write_frame(0.0, rods, bad); }, "poses[1].x");
  bad = poses;
  bad[0].q.coeffs() *= 2.0;
  expect_rejects([&] { series.write_frame(0.0, rods, bad); }, "poses[0].q");
  expect_rejects([&] { series.write_frame(0.0, rods, poses, {{"velocity", 3, {1, 2, 3}}}); }, "fields[0].values");
  expect_rejects([&] { series.write_frame(0.0, rods, poses, {{"v", 1, {1, std::nan("")}}}); }, "fields[0].values");
  expect_rejects([&] { series.write_frame(0.0, rods, poses, {{"e", 1, {1, 2}}, {"e", 1, {1, 2}}}); }, "fields[1].name");
  expect_rejects([&] { series.write_frame(0.0, rods, poses, {{"centre", 1, {1, 2}}}); }, "fields[0].name");
  expect_rejects([&] { series.write_frame(0.0, rods, poses, {{"e", 0, {}}}); }, "fields[0].components");
  EXPECT_EQ(series.frames(), 0u);
  EXPECT_FALSE(fs::exists(series.pvd_path()));

  series.write_frame(1.0, rods, poses);
  expect_rejects([&] { series.write_frame(1.0, rods, poses); }, "time");
  // The directory gone: the frame cannot be written, and the series stays as it was.
  fs::remove_all(dir);
  EXPECT_THROW(series.write_frame(2.0, rods, poses), std::runtime_error);
  EXPECT_EQ(series.frames(), 1u);
}

}  // namespace

}  // namespace vtk_polydata_tests
