// Accuracy of the sphere mobility models for two equal spheres against the exact
// two-sphere mobility (Jeffrey & Onishi 1984): the table a user needs to pick a model.
// Spheres of hydrodynamic radius a = 1 on the x axis at centre distance 2 + gap; for each
// model the error (model - exact) of the mobility functions, in their own units (Kim &
// Karrila's normalisation), read off the 12 x 12 matrix. Prints a table and writes one
// JSON object per (model, gap).
//
//   pair_mobility_accuracy [--output FILE] [--max-shell 12|42|162|642]

// Only the mobility headers it uses, not the contact solvers.
#include <stokescontact/io/json.hpp>
#include <stokescontact/mobility/multiblob_mobility.hpp>
#include <stokescontact/mobility/pair_mobility_exact.hpp>
#include <stokescontact/mobility/rpy_mobility.hpp>
#include <stokescontact/mobility/sphere_shell.hpp>

#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

namespace sc = stokescontact;

namespace pair_mobility_accuracy {

constexpr double kPi = std::numbers::pi;
constexpr std::array<double, 6> kGaps{0.1, 0.2, 0.5, 1.0, 2.0, 4.0};

// Matrix entry (row, column) and the unit that makes it a mobility function (a = eta = 1):
// 1/(6 pi) for translation, 1/(8 pi) for rotation.
struct Function {
  const char* name;
  int row, col;
  double unit;
};
constexpr double kTrans = 1.0 / (6.0 * kPi), kRot = 1.0 / (8.0 * kPi);
constexpr std::array<Function, 8> kFunctions{{{"x11a", 0, 0, kTrans},
                                              {"x12a", 0, 6, kTrans},
                                              {"y11a", 1, 1, kTrans},
                                              {"y12a", 1, 7, kTrans},
                                              {"x11c", 3, 3, kRot},
                                              {"x12c", 3, 9, kRot},
                                              {"y11c", 4, 4, kRot},
                                              {"y12c", 4, 10, kRot}}};

std::vector<sc::Pose> pair_at(double gap) {
  return {{sc::Vec3::Zero(), sc::Quat::Identity()}, {sc::Vec3(2.0 + gap, 0, 0), sc::Quat::Identity()}};
}

sc::MatX model_matrix(const std::string& model, double gap) {
  const auto poses = pair_at(gap);
  if (model == "rpy") {
    sc::RpyMobility m(2, {1.0, 1.0}, 6);
    m.set_configuration(poses);
    return m.dense_matrix();
  }
  const int blobs = std::stoi(model.substr(std::strlen("shell")));
  sc::MultiblobOptions options;
  options.solver = sc::MultiblobSolver::dense;
  sc::MultiblobMobility m(sc::sphere_shell(blobs, 1.0), 2, options);
  m.set_configuration(poses);
  return m.dense_matrix();
}

// The program's entry point (examples/CMakeLists.txt: the drivers are compiled in batches).
int main(int argc, char** argv) {
  std::string output;
  int max_shell = 162;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--output") == 0 && i + 1 < argc) {
      output = argv[++i];
    } else if (std::strcmp(argv[i], "--max-shell") == 0 && i + 1 < argc) {
      max_shell = std::stoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: %s [--output FILE] [--max-shell 12|42|162|642]\n", argv[0]);
      return 2;
    }
  }
  std::ofstream json;
  if (!output.empty()) {
    json.open(output);
    if (!json) {
      std::fprintf(stderr, "cannot write %s\n", output.c_str());
      return 1;
    }
  }
  std::vector<std::string> models{"rpy"};
  for (int n : {12, 42, 162, 642})
    if (n <= max_shell) models.push_back("shell" + std::to_string(n));

  std::printf("Two equal spheres (a = 1): model - exact for the mobility functions, in their units\n\n");
  std::printf("%-9s %6s", "model", "gap/a");
  for (const auto& f : kFunctions) std::printf(" %10s", f.name);
  std::printf("\n");
  for (const auto& model : models) {
    for (double gap : kGaps) {
      const sc::MatX m = model_matrix(model, gap);
      const sc::Mat12 exact = sc::two_sphere_mobility_matrix(sc::Vec3::Zero(), sc::Vec3(2.0 + gap, 0, 0), 1.0, 1.0);
      std::printf("%-9s %6.1f", model.c_str(), gap);
      if (json.is_open()) json << "{\"model\": \"" << model << "\", \"gap\": " << sc::json_number(gap);
      for (const auto& f : kFunctions) {
        const double value = m(f.row, f.col) / f.unit;
        const double reference = exact(f.row, f.col) / f.unit;
        std::printf(" %10.2e", value - reference);
        if (json.is_open())
          json << ", \"" << f.name << "\": " << sc::json_number(value) << ", \"" << f.name
               << "_exact\": " << sc::json_number(reference);
      }
      std::printf("\n");
      if (json.is_open()) json << "}\n";
    }
  }
  if (!output.empty()) std::printf("\nwrote %s\n", output.c_str());
  return 0;
}

}  // namespace pair_mobility_accuracy
