#pragma once
// A scene file (JSON) read into plain values: what to simulate, with which model, for how
// long, and what to write. read_scene only reads and checks; it generates nothing and writes
// nothing, so a bad scene stops before any work with one message naming its key path.
// docs/scenes.md describes every key; examples/scenes/ holds one scene per experiment.
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <stokescontact/contact/solvers/contact_solver.hpp>
#include <stokescontact/dynamics/background_flow.hpp>
#include <stokescontact/geometry/line_contact.hpp>
#include <stokescontact/geometry/shapes.hpp>
#include <stokescontact/scenes/sphere_packing.hpp>

#include "scene/json_reader.hpp"

namespace stokescontact::apps {

using SceneShape = std::variant<Sphere, Spherocylinder, Boomerang>;

// Bodies placed on an nx x ny x nz grid of the given spacing, centred on `centre`, all with
// one orientation.
struct LatticeSpec {
  std::array<long long, 3> counts{1, 1, 1};
  Vec3 spacing = Vec3::Zero();
  Vec3 centre = Vec3::Zero();
  Quat orientation = Quat::Identity();
};

// Spheres only: the library's packings (scenes/sphere_packing.hpp) of unit-radius-scaled
// spheres in a cube of side (4/3 pi N / phi)^(1/3) R.
struct SpherePackingSpec {
  bool dense = false;  // false: random sequential addition
  std::size_t count = 0;
  double packing_fraction = 0.0;
  std::uint64_t seed = 0;
};

// Any shape: uniform centres in [0, side)^3 and uniform orientations, one at a time, each kept
// only if every gap to the bodies kept so far exceeds min_gap.
struct RandomPlacementSpec {
  std::size_t count = 0;
  double side = 0.0;
  double min_gap = 0.0;
  std::uint64_t seed = 0;
  long long max_attempts = 1000000;
};

using BodiesSpec = std::variant<std::vector<Pose>, LatticeSpec, SpherePackingSpec, RandomPlacementSpec>;

enum class MobilityModel { automatic, free_draining, rpy, multiblob };

struct MobilitySpec {
  MobilityModel model = MobilityModel::automatic;
  bool hydrodynamic_interactions = true;  // automatic: false picks free-draining
  double accuracy = 0.05;                 // automatic: largest relative pair-mobility error
  double viscosity = 1.0;
  int shell_blobs = 0;                    // spheres, multiblob: 12, 42, 162 or 642 (0: automatic / 12)
  int blobs_per_ring = 8;                 // rods, multiblob
  double blob_spacing = 0.0;              // boomerangs (curve blobs; 0: the default)
};

struct ContactSpec {
  double d_hat = 0.0;
  bool d_hat_is_minimum_gap = false;  // "d_hat": "minimum_gap": the smallest gap at t = 0
  double d_try = 0.0;                 // 0: the d_try rule
  double d_try_multiplier = 1.0;
  DTryRule d_try_rule = DTryRule::relative;
  std::string solver = "default";
  std::optional<int> max_iterations;
  ContactStepOptions step;            // directions, cost, node spacing, whole step, margin
  bool line_contact = false;          // rods: "directions": "line"
  LineContactParameters line;
  int max_substep_halvings = 4;
};

struct ForcesSpec {
  enum class Kind { none, constant, per_body, random } kind = Kind::none;
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero();  // constant: on every body
  std::vector<Vec3> forces, torques;                 // per_body
  double magnitude = 0.0;                            // random: |f_i|, directions uniform
  std::uint64_t seed = 0;
  bool has_torques() const {
    if (kind == Kind::constant) return !torque.isZero(0.0);
    if (kind == Kind::per_body)
      for (const Vec3& t : torques)
        if (!t.isZero(0.0)) return true;
    return false;
  }
};

struct OutputSpec {
  bool vtk = true;
  long long vtk_every = 1;  // a frame every this many steps (and the first and last)
  int ring_points = 16;     // mesh resolution of the drawn bodies
};

struct SceneSpec {
  std::string name;
  std::string description;
  SceneShape shape;
  BodiesSpec bodies;
  MobilitySpec mobility;
  ContactSpec contact;
  std::optional<Mat3> velocity_gradient;  // background flow u = E x
  ForcesSpec forces;
  std::optional<Vec3> box;                // periodic box lengths
  double dt = 0.0;
  long long steps = 0;
  OutputSpec output;
};

namespace detail {

inline SceneShape read_shape(const JsonReader& r) {
  const std::string type = r.at("type").choice({"sphere", "spherocylinder", "boomerang"});
  if (type == "sphere") {
    r.known_keys({"type", "radius"});
    return Sphere{r.at("radius").positive()};
  }
  if (type == "spherocylinder") {
    r.known_keys({"type", "length", "radius"});
    return Spherocylinder{r.at("length").positive(), r.at("radius").positive()};
  }
  r.known_keys({"type", "arm_length", "radius", "bend_radius"});
  const Boomerang paper = broms_tornberg_boomerang();
  Boomerang b;
  b.arm_length = r.has("arm_length") ? r.at("arm_length").positive() : paper.arm_length;
  b.radius = r.has("radius") ? r.at("radius").positive() : paper.radius;
  b.bend_radius = r.has("bend_radius") ? r.at("bend_radius").positive() : paper.bend_radius;
  return b;
}

inline BodiesSpec read_bodies(const JsonReader& r, const SceneShape& shape) {
  r.known_keys({"poses", "lattice", "random_sequential_addition", "dense_packing", "random_placement"});
  if (r.json().size() != 1)
    r.fail("must hold exactly one of poses, lattice, random_sequential_addition, dense_packing, random_placement");
  if (const auto poses = r.find("poses")) {
    std::vector<Pose> out(poses->array_size());
    if (out.empty()) poses->fail("needs at least one body");
    for (std::size_t k = 0; k < out.size(); ++k) {
      const JsonReader p = poses->element(k);
      p.known_keys({"position", "orientation"});
      out[k].x = p.at("position").vec3();
      if (const auto q = p.find("orientation")) out[k].q = q->quaternion();
    }
    return out;
  }
  if (const auto l = r.find("lattice")) {
    l->known_keys({"counts", "spacing", "centre", "orientation"});
    LatticeSpec s;
    const JsonReader counts = l->at("counts");
    if (counts.array_size() != 3) counts.fail("must be an array of 3 integers");
    for (std::size_t k = 0; k < 3; ++k) s.counts[k] = counts.element(k).integer(1, 1000000);
    s.spacing = l->at("spacing").vec3();
    for (int k = 0; k < 3; ++k)
      if (s.counts[static_cast<std::size_t>(k)] > 1 && !(s.spacing(k) > 0.0))
        l->at("spacing").fail("must be > 0 along every axis with more than one body");
    if (const auto c = l->find("centre")) s.centre = c->vec3();
    if (const auto q = l->find("orientation")) s.orientation = q->quaternion();
    return s;
  }
  for (const char* key : {"random_sequential_addition", "dense_packing"}) {
    const auto p = r.find(key);
    if (!p) continue;
    if (!std::holds_alternative<Sphere>(shape))
      p->fail("packs spheres only; use random_placement or lattice for other shapes");
    p->known_keys({"count", "packing_fraction", "seed"});
    SpherePackingSpec s;
    s.dense = std::string(key) == "dense_packing";
    s.count = static_cast<std::size_t>(p->at("count").integer(2, 10000000));
    s.packing_fraction = p->at("packing_fraction").positive();
    const double limit = s.dense ? kDensePackingLimit : kRandomSequentialAdditionLimit;
    if (s.packing_fraction > limit)
      p->at("packing_fraction").fail("must be <= " + JsonReader::format(limit) + " for " + key + ", got " +
                                     JsonReader::format(s.packing_fraction));
    s.seed = p->has("seed") ? p->at("seed").seed() : 0;
    return s;
  }
  const JsonReader p = r.at("random_placement");
  p.known_keys({"count", "side", "min_gap", "seed", "max_attempts"});
  RandomPlacementSpec s;
  s.count = static_cast<std::size_t>(p.at("count").integer(1, 10000000));
  s.side = p.at("side").positive();
  s.min_gap = p.at("min_gap").positive();
  s.seed = p.has("seed") ? p.at("seed").seed() : 0;
  if (const auto m = p.find("max_attempts")) s.max_attempts = m->integer(1);
  return s;
}

inline MobilitySpec read_mobility(const JsonReader& r) {
  r.known_keys({"model", "hydrodynamic_interactions", "accuracy", "viscosity", "shell_blobs", "blobs_per_ring",
                "blob_spacing"});
  MobilitySpec m;
  const std::string model = r.has("model")
                                ? r.at("model").choice({"automatic", "free-draining", "rpy", "multiblob"})
                                : std::string("automatic");
  m.model = model == "free-draining" ? MobilityModel::free_draining
            : model == "rpy"         ? MobilityModel::rpy
            : model == "multiblob"   ? MobilityModel::multiblob
                                     : MobilityModel::automatic;
  if (const auto h = r.find("hydrodynamic_interactions")) {
    m.hydrodynamic_interactions = h->boolean();
    if (m.model != MobilityModel::automatic)
      h->fail("is read only with \"model\": \"automatic\" (the model is named here as '" + model + "')");
  }
  if (const auto a = r.find("accuracy")) {
    m.accuracy = a->positive();
    if (m.model != MobilityModel::automatic) a->fail("is read only with \"model\": \"automatic\"");
  }
  if (const auto v = r.find("viscosity")) m.viscosity = v->positive();
  if (const auto s = r.find("shell_blobs")) {
    m.shell_blobs = static_cast<int>(s->integer(12, 642));
    if (m.shell_blobs != 12 && m.shell_blobs != 42 && m.shell_blobs != 162 && m.shell_blobs != 642)
      s->fail("must be 12, 42, 162 or 642 (the icosahedral shells), got " + std::to_string(m.shell_blobs));
  }
  if (const auto b = r.find("blobs_per_ring")) m.blobs_per_ring = static_cast<int>(b->integer(3, 64));
  if (const auto b = r.find("blob_spacing")) m.blob_spacing = b->positive();
  return m;
}

inline ContactSpec read_contact(const JsonReader& r, const SceneShape& shape) {
  r.known_keys({"d_hat", "d_try", "d_try_multiplier", "d_try_rule", "solver", "max_iterations", "directions",
                "cost", "node_spacing", "whole_step", "separation_margin", "line_width", "line_angle",
                "max_substep_halvings", "max_correction_turn", "broad_phase_skin", "max_flagged_pairs_per_body"});
  ContactSpec c;
  const JsonReader d_hat = r.at("d_hat");
  if (d_hat.json().is_string()) {
    d_hat.choice({"minimum_gap"});
    c.d_hat_is_minimum_gap = true;
  } else {
    c.d_hat = d_hat.positive();
  }
  if (const auto d = r.find("d_try")) {
    c.d_try = d->non_negative();
    if (c.d_try > 0.0 && !c.d_hat_is_minimum_gap && c.d_try < c.d_hat)
      d->fail("must be 0 (the d_try rule) or >= contact.d_hat = " + JsonReader::format(c.d_hat) + ", got " +
              JsonReader::format(c.d_try));
  }
  if (const auto m = r.find("d_try_multiplier")) {
    c.d_try_multiplier = m->number();
    if (!(c.d_try_multiplier >= 1.0)) m->fail("must be >= 1, got " + JsonReader::format(c.d_try_multiplier));
  }
  if (const auto rule = r.find("d_try_rule"))
    c.d_try_rule = rule->choice({"relative", "absolute"}) == "absolute" ? DTryRule::absolute : DTryRule::relative;
  if (const auto s = r.find("solver")) {
    c.solver = s->text();
    try {
      (void)contact_solver_from_name(c.solver);
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      s->fail(what.substr(what.find(": ") + 2));
    }
  }
  if (const auto m = r.find("max_iterations")) c.max_iterations = static_cast<int>(m->integer(1, 1000000));
  if (const auto d = r.find("directions")) {
    const std::string dir = d->choice({"automatic", "particle", "surface", "line", "overlap-ends"});
    c.step.directions = dir == "particle"       ? ContactDirections::particle
                        : dir == "surface"      ? ContactDirections::surface
                        : dir == "line"         ? ContactDirections::particle
                        : dir == "overlap-ends" ? ContactDirections::overlap_ends
                                                : ContactDirections::automatic;
    c.line_contact = dir == "line";
    if (c.line_contact && !std::holds_alternative<Spherocylinder>(shape))
      d->fail("'line' spreads the force of near-parallel rods: spherocylinders only");
    if (dir == "overlap-ends" && !std::holds_alternative<Spherocylinder>(shape))
      d->fail("'overlap-ends' holds near-parallel rods at both ends of their overlap: spherocylinders only");
  }
  if (const auto cost = r.find("cost"))
    c.step.cost = mobility_cost_from_name(cost->choice({"automatic", "formed", "matrix-free", "blocks"}), "cost");
  if (const auto s = r.find("node_spacing")) c.step.node_spacing = s->non_negative();
  if (const auto w = r.find("whole_step")) c.step.whole_step = w->boolean();
  if (const auto m = r.find("separation_margin")) {
    c.step.separation_margin = m->positive();
    if (c.step.separation_margin >= 1.0) m->fail("must be < 1");
  }
  if (const auto t = r.find("max_correction_turn")) c.step.max_correction_turn = t->positive();
  if (const auto k = r.find("broad_phase_skin")) c.step.broad_phase_skin = k->non_negative();
  if (const auto k = r.find("max_flagged_pairs_per_body")) c.step.max_flagged_pairs_per_body = k->non_negative();
  c.line.width = std::get_if<Spherocylinder>(&shape) ? 2.0 * std::get<Spherocylinder>(shape).radius : 1.0;
  c.line.angle = 0.05;
  for (const char* key : {"line_width", "line_angle"})
    if (const auto v = r.find(key)) {
      if (!c.line_contact) v->fail("is read only with \"directions\": \"line\"");
      (std::string(key) == "line_width" ? c.line.width : c.line.angle) = v->positive();
    }
  if (const auto h = r.find("max_substep_halvings")) c.max_substep_halvings = static_cast<int>(h->integer(0, 30));
  return c;
}

inline ForcesSpec read_forces(const JsonReader& r) {
  const std::string type = r.at("type").choice({"none", "constant", "per_body", "random"});
  ForcesSpec f;
  if (type == "none") {
    r.known_keys({"type"});
  } else if (type == "constant") {
    r.known_keys({"type", "force", "torque"});
    f.kind = ForcesSpec::Kind::constant;
    if (const auto v = r.find("force")) f.force = v->vec3();
    if (const auto v = r.find("torque")) f.torque = v->vec3();
  } else if (type == "per_body") {
    r.known_keys({"type", "force", "torque"});
    f.kind = ForcesSpec::Kind::per_body;
    for (const char* key : {"force", "torque"}) {
      const auto list = r.find(key);
      if (!list) continue;
      std::vector<Vec3>& out = std::string(key) == "force" ? f.forces : f.torques;
      for (std::size_t k = 0; k < list->array_size(); ++k) out.push_back(list->element(k).vec3());
    }
  } else {
    r.known_keys({"type", "magnitude", "seed"});
    f.kind = ForcesSpec::Kind::random;
    f.magnitude = r.at("magnitude").positive();
    f.seed = r.has("seed") ? r.at("seed").seed() : 0;
  }
  return f;
}

inline Mat3 read_flow(const JsonReader& r) {
  r.known_keys({"velocity_gradient", "biaxial_compression", "shear"});
  if (r.json().size() != 1) r.fail("must hold exactly one of velocity_gradient, biaxial_compression, shear");
  if (const auto e = r.find("velocity_gradient")) {
    const Mat3 E = e->mat3();
    if (!(std::abs(E.trace()) <= LinearBackgroundFlow::kTraceTolerance * E.norm()))
      e->fail("must be traceless (incompressible flow), got trace " + JsonReader::format(E.trace()));
    return E;
  }
  if (const auto b = r.find("biaxial_compression"))
    return LinearBackgroundFlow::biaxial_compression(b->number()).velocity_gradient();
  return LinearBackgroundFlow::shear(r.at("shear").number()).velocity_gradient();
}

}  // namespace detail

// The whole scene. `name_fallback` names it when the file has no "name" (the file's stem).
inline SceneSpec read_scene(const nlohmann::json& document, const std::string& name_fallback = "scene") {
  const JsonReader root(document, "");
  if (const auto mixed = root.find("shapes"))
    mixed->fail("one scene holds one shape type (\"shape\"): the time stepper carries one shape type, so "
                "spheres mixed with rods or boomerangs are not supported");
  root.known_keys({"name", "description", "shape", "bodies", "mobility", "contact", "flow", "forces", "box",
                   "time", "output", "temperature"});
  if (const auto t = root.find("temperature"))
    t->fail("Brownian motion is not supported by this version of the runner; remove the key");
  SceneSpec s;
  s.name = root.has("name") ? root.at("name").text() : name_fallback;
  if (s.name.empty() || s.name.find_first_of("/\\") != std::string::npos)
    root.at("name").fail("must be a non-empty file name without slashes");
  if (const auto d = root.find("description")) s.description = d->text();
  s.shape = detail::read_shape(root.at("shape"));
  s.bodies = detail::read_bodies(root.at("bodies"), s.shape);
  if (const auto m = root.find("mobility")) s.mobility = detail::read_mobility(*m);
  s.contact = detail::read_contact(root.at("contact"), s.shape);
  if (const auto f = root.find("flow")) s.velocity_gradient = detail::read_flow(*f);
  if (const auto f = root.find("forces")) s.forces = detail::read_forces(*f);
  if (const auto b = root.find("box")) {
    s.box = b->vec3();
    for (int k = 0; k < 3; ++k)
      if (!((*s.box)(k) > 0.0)) b->fail("lengths must be > 0, got " + JsonReader::format((*s.box)(k)));
    if (s.velocity_gradient) b->fail("a periodic box cannot hold a background flow (u = E x is not periodic)");
  }
  const JsonReader time = root.at("time");
  time.known_keys({"dt", "steps", "end"});
  s.dt = time.at("dt").positive();
  if (time.has("steps") == time.has("end")) time.fail("needs exactly one of steps, end");
  if (const auto n = time.find("steps")) {
    s.steps = n->integer(1);
  } else {
    const double end = time.at("end").positive();
    s.steps = static_cast<long long>(std::ceil(end / s.dt - 1e-9));
  }
  if (const auto o = root.find("output")) {
    o->known_keys({"vtk", "vtk_every", "ring_points"});
    if (const auto v = o->find("vtk")) s.output.vtk = v->boolean();
    if (const auto e = o->find("vtk_every")) s.output.vtk_every = e->integer(1);
    if (const auto p = o->find("ring_points")) s.output.ring_points = static_cast<int>(p->integer(4, 256));
  }
  return s;
}

}  // namespace stokescontact::apps
