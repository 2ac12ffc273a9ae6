// Headline example (for now): exact closest points between the library's shapes.
// Prints a readable table and writes one JSON object per shape pair.
//
//   geometry_demo [--output FILE]

// Only the headers it uses: a geometry program need not compile the contact solvers.
#include <stokescontact/geometry/closest_points.hpp>
#include <stokescontact/geometry/shapes.hpp>
#include <stokescontact/io/json.hpp>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <numbers>
#include <stdexcept>
#include <string>

namespace sc = stokescontact;

namespace geometry_demo {

sc::Pose pose_at(double x, double y, double z, double angle = 0.0,
                 const sc::Vec3& axis = sc::Vec3::UnitX()) {
  return {sc::Vec3(x, y, z), sc::Quat(Eigen::AngleAxisd(angle, axis.normalized()))};
}

struct Reporter {
  std::ostream* json = nullptr;

  template <typename A, typename B>
  void pair(const std::string& label, const A& a, const sc::Pose& pa, const B& b,
            const sc::Pose& pb) {
    const sc::ClosestPoints cp = sc::closest_points(a, pa, b, pb);
    std::printf("%-34s %12.6f   (%7.3f %7.3f %7.3f)  (%7.3f %7.3f %7.3f)  (%6.3f %6.3f %6.3f)\n",
                label.c_str(), cp.distance, cp.point_a.x(), cp.point_a.y(), cp.point_a.z(),
                cp.point_b.x(), cp.point_b.y(), cp.point_b.z(), cp.normal.x(), cp.normal.y(),
                cp.normal.z());
    if (json)
      *json << "{\"pair\": \"" << label << "\", \"distance\": " << sc::json_number(cp.distance)
            << ", \"point_a\": " << sc::json_array(cp.point_a) << ", \"point_b\": " << sc::json_array(cp.point_b)
            << ", \"normal\": " << sc::json_array(cp.normal) << "}\n";
  }
};

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  std::string output;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--output") == 0 && i + 1 < argc) {
      output = argv[++i];
    } else {
      std::fprintf(stderr, "usage: %s [--output FILE]\n", argv[0]);
      return 2;
    }
  }
  std::ofstream file;
  Reporter report;
  if (!output.empty()) {
    file.open(output);
    if (!file) {
      std::fprintf(stderr, "cannot write %s\n", output.c_str());
      return 1;
    }
    report.json = &file;
  }

  const sc::Sphere sphere{1.0};
  const sc::Spherocylinder rod{4.0, 0.5};
  const sc::Boomerang boomerang = sc::broms_tornberg_boomerang();
  const double pi = std::numbers::pi;

  std::printf("StokesContact geometry demo: signed distance d (negative = overlap), witness\n"
              "points on each surface and the unit normal from a to b.\n\n");
  std::printf("%-34s %12s   %-25s  %-25s  %-22s\n", "pair", "d", "point_a", "point_b", "normal");
  report.pair("sphere-sphere, gap 0.5", sphere, pose_at(0, 0, 0), sphere, pose_at(2.5, 0, 0));
  report.pair("sphere-sphere, overlap 0.2", sphere, pose_at(0, 0, 0), sphere, pose_at(0, 1.8, 0));
  report.pair("sphere-rod, at the cylinder", sphere, pose_at(0, 0, 0), rod, pose_at(1.6, 0, 0.7));
  report.pair("sphere-rod, at the cap", sphere, pose_at(0, 0, 0), rod, pose_at(0, 0, 3.7));
  report.pair("rod-rod, parallel", rod, pose_at(0, 0, 0), rod, pose_at(1.05, 0, 1.0));
  report.pair("rod-rod, crossing at right angle", rod, pose_at(0, 0, 0), rod,
              pose_at(0, 1.2, 0, pi / 2));
  report.pair("rod-rod, touching caps", rod, pose_at(0, 0, 0), rod, pose_at(0, 0, 5.0));
  report.pair("sphere-boomerang, in the bend", sphere, pose_at(-0.2, 0, -0.2), boomerang,
              pose_at(1.0, 0, 1.0));
  report.pair("rod-boomerang", rod, pose_at(0, 0, 0), boomerang, pose_at(1.5, 0.3, 0.0, pi / 3));
  report.pair("boomerang-boomerang, interlocked", boomerang, pose_at(0, 0, 0), boomerang,
              pose_at(0.6, 0.0, 0.6, pi / 2, sc::Vec3::UnitZ()));
  report.pair("boomerang-boomerang, apart", boomerang, pose_at(0, 0, 0), boomerang,
              pose_at(0, 3.2, 0, pi / 4, sc::Vec3(1, 1, 0)));
  if (!output.empty()) std::printf("\nwrote %s\n", output.c_str());
  return 0;
}

}  // namespace geometry_demo
