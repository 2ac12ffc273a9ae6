// The orientational structure of saved rod states (io/checkpoint.hpp files, as brownian_rods
// --save-state writes them): per file, the nematic order S, the order tensor's three
// eigenvalues and its director (dynamics/nematic_order.hpp), the slab profile of P2(n . u)
// across each box axis and the orientational correlation g2(r) (dynamics/order_structure.hpp),
// one JSON line each (to --output, when given, with a readable row per state on stdout). It
// tells a uniform nematic (every slab near S, g2 -> S^2 at large r) from ordered and
// disordered regions side by side (slabs far apart).
//
//   nematic_state --states A.checkpoint[,B.checkpoint,...] [--slabs 4] [--edges 0,2,4,6,8,10,14]
//                 [--aspect 5] [--d-hat 1e-2] [--output FILE]
//
// Rods of diameter D = 1 and cylinder length --aspect (brownian_rods' units); eta is the
// packing fraction of the hard core D + --d-hat that the contact step holds, as brownian_rods
// reports it. g2 is O(N^2) in the rods of a state.
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "common/cli.hpp"
#include "stokescontact/dynamics/nematic_order.hpp"
#include "stokescontact/dynamics/order_structure.hpp"
#include "stokescontact/io/checkpoint.hpp"
#include "stokescontact/io/json.hpp"

namespace nematic_state {

namespace sc = stokescontact;
namespace ex = examples;

namespace {

constexpr const char* kUsage =
    "usage: nematic_state --states A.checkpoint[,B.checkpoint,...] [--slabs 4] [--edges 0,2,4,6,8,10,14]\n"
    "                     [--aspect 5] [--d-hat 1e-2] [--output FILE]\n";

struct Options {
  std::vector<std::string> states;
  int slabs = 4;
  std::vector<double> edges{0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 14.0};
  double aspect = 5.0;
  double d_hat = 1e-2;
  std::string output;
};

Options parse(int argc, char** argv) {
  ex::Arguments args(argc, argv);
  Options o;
  o.states = args.list("--states", {});
  if (o.states.empty()) throw std::invalid_argument("--states: give at least one checkpoint file");
  o.slabs = static_cast<int>(args.integer("--slabs", o.slabs, 1));
  o.edges = args.numbers("--edges", o.edges, 0.0);
  o.aspect = args.number("--aspect", o.aspect, 0.0);
  if (!(o.aspect > 0.0)) throw std::invalid_argument("--aspect must be > 0");
  o.d_hat = args.number("--d-hat", o.d_hat, 0.0);
  o.output = args.text("--output", "");
  args.reject_unknown();
  return o;
}

std::string json_vector(const std::vector<double>& v) { return sc::json_array(std::span<const double>(v)); }

std::string json_counts(const std::vector<std::size_t>& v) {
  std::vector<double> d(v.begin(), v.end());
  return json_vector(d);
}

std::string row(const std::vector<double>& v) {
  std::string out;
  for (const double x : v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%s%.2f", out.empty() ? "" : " ", x);
    out += buf;
  }
  return out;
}

void run(const Options& o) {
  ex::JsonLines sink(o.output);
  const double hard_core = 1.0 + o.d_hat;
  const double rod_volume = std::numbers::pi * (0.25 * o.aspect * hard_core * hard_core + hard_core * hard_core * hard_core / 6.0);
  if (sink.to_file())
    std::printf("%-48s %5s %6s %6s  %-16s  %-20s  %-20s  %-20s  %s\n", "state", "N", "eta", "S", "Q eigenvalues",
                "slabs across x", "across y", "across z", "g2 per shell");
  for (const std::string& path : o.states) {
    const sc::Checkpoint c = sc::load_checkpoint(path);
    if (!c.box) throw std::invalid_argument(path + ": the state has no periodic box");
    const sc::NematicOrder order = sc::nematic_order(c.poses);
    const Eigen::SelfAdjointEigenSolver<sc::Mat3> eigen(sc::order_tensor(c.poses));
    const std::vector<double> eigenvalues{eigen.eigenvalues()(2), eigen.eigenvalues()(1), eigen.eigenvalues()(0)};
    std::vector<sc::SlabOrderProfile> slabs;
    for (int axis = 0; axis < 3; ++axis)
      slabs.push_back(sc::slab_order_profile(c.poses, *c.box, order.director, axis, o.slabs));
    const sc::OrientationalCorrelation g2 = sc::orientational_correlation(c.poses, *c.box, o.edges);
    const double n = static_cast<double>(c.poses.size());
    const double eta = n * rod_volume / c.box->lengths.prod();
    std::string json = "{\"state\": " + sc::json_quoted(path) + ", \"time\": " + sc::json_number(c.time) +
                       ", \"N\": " + std::to_string(c.poses.size()) + ", \"eta\": " + sc::json_number(eta) +
                       ", \"S\": " + sc::json_number(order.S) + ", \"order_tensor_eigenvalues\": " +
                       json_vector(eigenvalues) + ", \"director\": " + sc::json_array(order.director);
    const char* axes[3] = {"x", "y", "z"};
    for (int axis = 0; axis < 3; ++axis)
      json += std::string(", \"slab_order_") + axes[axis] + "\": " + json_vector(slabs[axis].order) + ", \"slab_rods_" +
              axes[axis] + "\": " + json_counts(slabs[axis].rods);
    json += ", \"g2_edges\": " + json_vector(o.edges) + ", \"g2\": " + json_vector(g2.g2) +
            ", \"g2_pairs\": " + json_counts(g2.pairs) + "}";
    char summary[512];
    std::snprintf(summary, sizeof summary, "%-48s %5zu %6.4f %6.3f  %-16s  %-20s  %-20s  %-20s  %s", path.c_str(),
                  c.poses.size(), eta, order.S, row(eigenvalues).c_str(), row(slabs[0].order).c_str(),
                  row(slabs[1].order).c_str(), row(slabs[2].order).c_str(), row(g2.g2).c_str());
    sink.line(json, summary);
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  return ex::driver_main("nematic_state", kUsage, [&] { o = parse(argc, argv); }, [&] { run(o); });
}

}  // namespace nematic_state
