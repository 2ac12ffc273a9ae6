// stokescontact-run: runs a scene file (JSON) and writes its diagnostics, summary and VTK
// series. docs/scenes.md lists every key; examples/scenes/ has one scene per experiment.
//
//   stokescontact-run SCENE.json [--output DIR] [--replace] [--max-steps N] [--progress|--quiet]
//
// Exit status: 0 the run finished; 1 the scene or the command line is wrong (nothing was
// written); 2 a step could not be held (the outputs record the run up to it).
#include <cstdlib>
#include <iostream>
#include <string>

#include "scene/scene_run.hpp"

namespace {

constexpr const char* kUsage =
    "usage: stokescontact-run SCENE.json [--output DIR] [--replace] [--max-steps N] [--progress|--quiet]\n"
    "  --output DIR     where to write (default out/<scene name>); refused if it exists\n"
    "  --replace        replace an existing DIR once the new run has ended\n"
    "  --max-steps N    stop after N steps (a short run of a long scene)\n"
    "  --progress       show progress on stderr (default: when stderr is a terminal)\n"
    "  --quiet          no progress\n";

stokescontact::apps::RunOptions parse(int argc, char** argv) {
  using stokescontact::apps::SceneError;
  stokescontact::apps::RunOptions o;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= argc) throw SceneError(a, "needs a value");
      return argv[++k];
    };
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      std::exit(0);
    } else if (a == "--output") {
      o.output = value();
    } else if (a == "--replace") {
      o.replace = true;
    } else if (a == "--max-steps") {
      const std::string v = value();
      std::size_t used = 0;
      long long n = 0;
      try {
        n = std::stoll(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != v.size() || n < 0) throw SceneError(a, "must be an integer >= 0, got '" + v + "'");
      o.max_steps = n;
    } else if (a == "--progress") {
      o.progress = true;
    } else if (a == "--quiet") {
      o.progress = false;
    } else if (a.starts_with("-")) {
      throw SceneError(a, "unknown option");
    } else if (o.scene.empty()) {
      o.scene = a;
    } else {
      throw SceneError(a, "a second scene file; one run takes one scene");
    }
  }
  if (o.scene.empty()) throw SceneError("SCENE.json", "is required");
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  stokescontact::apps::RunOptions options;
  try {
    options = parse(argc, argv);
  } catch (const std::invalid_argument& e) {
    std::cerr << "stokescontact-run: " << e.what() << '\n' << kUsage;
    return 1;
  }
  try {
    const stokescontact::apps::RunSummary summary = stokescontact::apps::run_scene(options, std::cout);
    stokescontact::apps::print_summary(summary, std::cout);
    return summary.status == "finished" ? 0 : 2;
  } catch (const std::exception& e) {
    std::cerr << "stokescontact-run: " << e.what() << '\n';
    return 1;
  }
}
