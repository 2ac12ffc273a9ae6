// Writes three VTK series for the read-back test (tests/io/read_vtk_series.py, ctest
// vtk_readback): 2 spheres (one shared shape), 2 rods (one shape each) and 1 boomerang, 3
// frames each, with a per-body velocity field, and expected.json with what the frames hold.
// A file holds one shape type, so a mixed scene is one series per type.
//   write_vtk_example OUT_DIR
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "stokescontact/io/json.hpp"
#include "stokescontact/io/vtk_polydata.hpp"

namespace sc = stokescontact;

namespace {

// Body k at time t: translating and turning about a tilted axis.
sc::Pose pose_at(std::size_t k, double t, const sc::Vec3& start) {
  const sc::Vec3 axis = sc::Vec3(1.0, 0.5 * static_cast<double>(k), 2.0).normalized();
  return {start + t * sc::Vec3(0.3, -0.2, 0.1 * static_cast<double>(k)),
          sc::Quat(Eigen::AngleAxisd(0.4 + 1.3 * t + 0.7 * static_cast<double>(k), axis))};
}

struct Series {
  std::string stem;
  std::string shape;  // "sphere", "spherocylinder", "boomerang"
  std::vector<sc::Vec3> starts;
  std::string json;   // the frames so far
};

template <typename Shapes>
void write_series(sc::VtkSeriesWriter& writer, Series& s, const Shapes& shapes, const std::string& params) {
  const double times[] = {0.0, 0.25, 0.75};
  std::string frames;
  for (const double t : times) {
    std::vector<sc::Pose> poses;
    std::vector<double> velocity;
    std::string centres, quaternions;
    for (std::size_t k = 0; k < s.starts.size(); ++k) {
      poses.push_back(pose_at(k, t, s.starts[k]));
      const sc::Pose& p = poses.back();
      for (int c = 0; c < 3; ++c) velocity.push_back(static_cast<double>(k) + 0.1 * c + t);
      const double q[4] = {p.q.w(), p.q.x(), p.q.y(), p.q.z()};
      centres += std::string(k ? ", " : "") + sc::json_array(p.x);
      quaternions += std::string(k ? ", " : "") + sc::json_array(std::span<const double>(q, 4));
    }
    writer.write_frame(t, shapes, poses, {{"velocity", 3, velocity}});
    frames += std::string(frames.empty() ? "" : ", ") + "{\"time\": " + sc::json_number(t) + ", \"centre\": [" +
              centres + "], \"quaternion\": [" + quaternions + "], \"velocity\": " + sc::json_array(velocity) + "}";
  }
  s.json = "{\"pvd\": " + sc::json_quoted(s.stem + ".pvd") + ", \"shape\": " + sc::json_quoted(s.shape) +
           ", \"bodies\": " + std::to_string(s.starts.size()) + ", " + params + ", \"frames\": [" + frames + "]}";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_vtk_example OUT_DIR\n");
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    const sc::BodyMeshOptions mesh;  // the defaults: the reader derives the counts from them

    Series spheres{"spheres", "sphere", {sc::Vec3(-2, 0, 0), sc::Vec3(-2, 2, 0)}, ""};
    sc::VtkSeriesWriter sphere_writer(dir, spheres.stem, mesh);
    write_series(sphere_writer, spheres, sc::Sphere{0.6}, "\"radius\": [0.6, 0.6]");

    Series rods{"rods", "spherocylinder", {sc::Vec3(1, 0, 0), sc::Vec3(1, 2.5, 0.5)}, ""};
    const std::vector<sc::Spherocylinder> rod_shapes{{2.0, 0.4}, {1.0, 0.3}};
    sc::VtkSeriesWriter rod_writer(dir, rods.stem, mesh);
    write_series(rod_writer, rods, rod_shapes, "\"radius\": [0.4, 0.3], \"length\": [2, 1]");

    Series boomerangs{"boomerangs", "boomerang", {sc::Vec3(4, 1, 0)}, ""};
    const sc::Boomerang b = sc::broms_tornberg_boomerang();
    sc::VtkSeriesWriter boomerang_writer(dir, boomerangs.stem, mesh);
    write_series(boomerang_writer, boomerangs, b,
                 "\"radius\": [0.5], \"arm_length\": [1.5], \"bend_radius\": [0.5], \"bounding_radius\": " +
                     sc::json_number(sc::bounding_radius(b)));

    std::ofstream out(dir / "expected.json");
    out << "{\"ring_points\": " << mesh.ring_points << ", \"cap_rings\": " << mesh.cap_rings
        << ", \"arc_pieces\": " << mesh.arc_pieces << ", \"series\": [" << spheres.json << ", " << rods.json
        << ", " << boomerangs.json << "]}\n";
    if (!out) throw std::runtime_error("cannot write expected.json");
    std::printf("write_vtk_example: wrote spheres.pvd, rods.pvd, boomerangs.pvd and expected.json to %s\n",
                dir.string().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "write_vtk_example: %s\n", e.what());
    return 1;
  }
  return 0;
}
