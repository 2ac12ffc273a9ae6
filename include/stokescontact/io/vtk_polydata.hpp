#pragma once
// Trajectories for ParaView as VTK XML files, without the VTK library. File formats: the VTK
// User's Guide (Kitware), chapter "VTK File Formats", section "XML File Formats" (PolyData,
// .vtp), also https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html; the
// collection file (.pvd) as ParaView reads it (ParaView wiki, "ParaView/Data formats", PVD).
//
// One frame is one ASCII PolyData file (numbers with 17 significant digits, so they round-trip):
//   Piece: every body's true surface (io/body_mesh.hpp) as triangles, with the point arrays
//     body_id (Int64), Normals (outward unit normals, for smooth shading) and each caller
//     field expanded to the body's vertices (so ParaView can colour by it);
//   FieldData, one tuple per body, for glyphs instead of meshes: centre (3), orientation_quaternion
//     (4: w x y z), axis (3: the body z axis in the world), the shape's parameters (radius, and
//     length / arm_length / bend_radius where the shape has them), each caller field; and one
//     tuple TIME (VisIt's name) and TimeValue (what VTK's XML readers take as the time).
// A series is the frames <stem>_000000.vtp, <stem>_000001.vtp, ... and <stem>.pvd listing them
// with their times; the .pvd is rewritten after each frame through a temporary file and a
// rename, so a run stopped at any point leaves a valid .pvd of the complete frames.
//
// A file holds one shape type (the library's scenes are homogeneous, TimeStepper<S>); a scene
// mixing types is written as one series per type and opened together. With the time stepper:
//   VtkSeriesWriter out("frames", "rods");
//   stepper.add_step_observer([&](const StepDiagnostics& d, std::span<const Pose> poses) {
//     out.write_frame(d.time, rod, poses);
//   });
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <ranges>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "stokescontact/io/body_mesh.hpp"

namespace stokescontact {

// Caller data per body (a velocity, a force, a scalar): `components` values per body, body
// after body, written as FieldData and as PointData on the body's vertices.
struct BodyField {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

// A .pvd entry: a frame's time and its file, relative to the .pvd's directory.
struct PvdEntry {
  double time = 0.0;
  std::string file;
};

namespace detail {

inline void append_number(std::string& out, double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  out += buf;
}

inline std::string xml_escaped(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

// Writes `path.tmp`, then renames it onto `path` (atomic on POSIX file systems).
inline void write_file_atomically(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + tmp.string() + ": " + std::strerror(errno));
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);
      throw std::runtime_error("writing " + tmp.string() + " failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("cannot rename " + tmp.string() + " to " + path.string());
  }
}

// One DataArray of `tuples` tuples of `components` doubles, value(i, c).
template <typename Value>
void append_array(std::string& out, std::string_view indent, std::string_view name, int components,
                  std::size_t tuples, bool with_tuple_count, Value value) {
  out += indent;
  out += "<DataArray type=\"Float64\"";
  if (!name.empty()) out += " Name=\"" + xml_escaped(name) + "\"";
  out += " NumberOfComponents=\"" + std::to_string(components) + "\"";
  if (with_tuple_count) out += " NumberOfTuples=\"" + std::to_string(tuples) + "\"";
  out += " format=\"ascii\">\n";
  for (std::size_t i = 0; i < tuples; ++i) {
    out += indent;
    for (int c = 0; c < components; ++c) {
      out += c == 0 ? "  " : " ";
      append_number(out, value(i, c));
    }
    out += '\n';
  }
  out += indent;
  out += "</DataArray>\n";
}

template <typename Value>
void append_int_array(std::string& out, std::string_view indent, std::string_view name, std::size_t count,
                      Value value) {
  out += indent;
  out += "<DataArray type=\"Int64\" Name=\"" + std::string(name) + "\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < count; ++i) {
    out += (i % 12 == 0) ? std::string(indent) + "  " : std::string(" ");
    out += std::to_string(value(i));
    if (i % 12 == 11 || i + 1 == count) out += '\n';
  }
  out += indent;
  out += "</DataArray>\n";
}

inline bool reserved_name(std::string_view name) {
  for (const std::string_view r : {"body_id", "Normals", "centre", "orientation_quaternion", "axis", "radius",
                                   "length", "arm_length", "bend_radius", "TIME", "TimeValue"})
    if (name == r) return true;
  return false;
}

inline void validate_fields(const std::vector<BodyField>& fields, std::size_t bodies) {
  for (std::size_t f = 0; f < fields.size(); ++f) {
    const std::string name = "fields[" + std::to_string(f) + "]";
    const BodyField& field = fields[f];
    if (field.name.empty()) fail_argument(name + ".name", "must not be empty");
    if (reserved_name(field.name)) fail_argument(name + ".name", "'" + field.name + "' is written by the writer");
    for (std::size_t g = 0; g < f; ++g)
      if (fields[g].name == field.name) fail_argument(name + ".name", "'" + field.name + "' appears twice");
    if (field.components < 1)
      fail_argument(name + ".components", "must be >= 1, got " + std::to_string(field.components));
    const std::size_t expected = bodies * static_cast<std::size_t>(field.components);
    if (field.values.size() != expected)
      fail_argument(name + ".values", "has " + std::to_string(field.values.size()) + " values, expected " +
                                          std::to_string(expected) + " (components x bodies)");
    require_finite(Eigen::Map<const VecX>(field.values.data(), static_cast<Eigen::Index>(expected)),
                   name + ".values");
  }
}

// The shape's parameters, as (name, value) pairs: radius, then those the shape has.
template <Shape S>
std::vector<std::pair<std::string, double>> shape_parameters(const S& s) {
  std::vector<std::pair<std::string, double>> p{{"radius", s.radius}};
  if constexpr (requires { s.length; }) p.emplace_back("length", s.length);
  if constexpr (requires { s.arm_length; }) p.emplace_back("arm_length", s.arm_length);
  if constexpr (requires { s.bend_radius; }) p.emplace_back("bend_radius", s.bend_radius);
  return p;
}

// The PolyData document; meshes[k] is body k's body-frame mesh, parameters[k] its shape's.
inline std::string vtp_document(double time, std::span<const BodyMesh* const> meshes, std::span<const Pose> poses,
                                const std::vector<std::vector<std::pair<std::string, double>>>& parameters,
                                const std::vector<BodyField>& fields) {
  const std::size_t bodies = poses.size();
  std::vector<BodyMesh> world;
  std::vector<std::size_t> first_vertex{0}, owner;  // owner: the body of each vertex
  world.reserve(bodies);
  std::size_t triangles = 0;
  for (std::size_t k = 0; k < bodies; ++k) {
    world.push_back(posed(*meshes[k], poses[k]));
    first_vertex.push_back(first_vertex.back() + world[k].vertices.size());
    owner.insert(owner.end(), world[k].vertices.size(), k);
    triangles += world[k].triangles.size();
  }
  const std::size_t points = first_vertex.back();
  std::vector<const Vec3*> point(points), normal(points);
  std::vector<std::size_t> connectivity;
  connectivity.reserve(3 * triangles);
  for (std::size_t k = 0; k < bodies; ++k) {
    for (std::size_t i = 0; i < world[k].vertices.size(); ++i) {
      point[first_vertex[k] + i] = &world[k].vertices[i];
      normal[first_vertex[k] + i] = &world[k].normals[i];
    }
    for (const auto& t : world[k].triangles)
      for (const std::size_t i : t) connectivity.push_back(first_vertex[k] + i);
  }

  std::string out = "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n";
  out += "  <PolyData>\n    <FieldData>\n";
  const std::string_view fi = "      ";
  append_array(out, fi, "TIME", 1, 1, true, [&](std::size_t, int) { return time; });
  append_array(out, fi, "TimeValue", 1, 1, true, [&](std::size_t, int) { return time; });
  append_array(out, fi, "centre", 3, bodies, true, [&](std::size_t k, int c) { return poses[k].x[c]; });
  // Eigen stores (x, y, z, w); VTK and ParaView's conventions put w first.
  append_array(out, fi, "orientation_quaternion", 4, bodies, true,
               [&](std::size_t k, int c) { return c == 0 ? poses[k].q.w() : poses[k].q.vec()[c - 1]; });
  append_array(out, fi, "axis", 3, bodies, true,
               [&](std::size_t k, int c) { return poses[k].direction_to_world(Vec3::UnitZ())[c]; });
  for (std::size_t p = 0; bodies > 0 && p < parameters[0].size(); ++p)
    append_array(out, fi, parameters[0][p].first, 1, bodies, true,
                 [&](std::size_t k, int) { return parameters[k][p].second; });
  for (const BodyField& f : fields)
    append_array(out, fi, f.name, f.components, bodies, true,
                 [&](std::size_t k, int c) { return f.values[k * static_cast<std::size_t>(f.components) + c]; });
  out += "    </FieldData>\n";
  out += "    <Piece NumberOfPoints=\"" + std::to_string(points) +
         "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
         std::to_string(triangles) + "\">\n";
  out += "      <PointData Scalars=\"body_id\" Normals=\"Normals\">\n";
  const std::string_view pi = "        ";
  append_int_array(out, pi, "body_id", points, [&](std::size_t i) { return owner[i]; });
  append_array(out, pi, "Normals", 3, points, false, [&](std::size_t i, int c) { return (*normal[i])[c]; });
  for (const BodyField& f : fields)
    append_array(out, pi, f.name, f.components, points, false, [&](std::size_t i, int c) {
      return f.values[owner[i] * static_cast<std::size_t>(f.components) + c];
    });
  out += "      </PointData>\n      <Points>\n";
  append_array(out, pi, "", 3, points, false, [&](std::size_t i, int c) { return (*point[i])[c]; });
  out += "      </Points>\n      <Polys>\n";
  append_int_array(out, pi, "connectivity", connectivity.size(), [&](std::size_t i) { return connectivity[i]; });
  append_int_array(out, pi, "offsets", triangles, [&](std::size_t i) { return 3 * (i + 1); });
  out += "      </Polys>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  return out;
}

// Checks the frame's input and writes it; meshes are built once per distinct shape object.
template <Shape S>
void write_vtp_frame(const std::filesystem::path& file, double time, std::span<const S> shapes, bool shared,
                     std::span<const Pose> poses, const std::vector<BodyField>& fields,
                     const BodyMeshOptions& options) {
  require_finite(time, "time");
  if (!shared && shapes.size() != poses.size())
    fail_argument("shapes", "has " + std::to_string(shapes.size()) + " shapes for " +
                                std::to_string(poses.size()) + " poses");
  validate(poses, "poses");
  validate_fields(fields, poses.size());
  std::vector<BodyMesh> body_meshes;
  std::vector<std::vector<std::pair<std::string, double>>> parameters;
  for (std::size_t k = 0; k < (shared ? 1 : shapes.size()); ++k) body_meshes.push_back(body_mesh(shapes[k], options));
  std::vector<const BodyMesh*> mesh_of(poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    mesh_of[k] = &body_meshes[shared ? 0 : k];
    parameters.push_back(shape_parameters(shapes[shared ? 0 : k]));
  }
  write_file_atomically(file, vtp_document(time, mesh_of, poses, parameters, fields));
}

}  // namespace detail

// One frame as a PolyData file: body k has shapes[k] (or the one `shape`) at poses[k].
template <std::ranges::contiguous_range R>
  requires Shape<std::ranges::range_value_t<R>>
void write_vtp(const std::filesystem::path& file, double time, const R& shapes, std::span<const Pose> poses,
               const std::vector<BodyField>& fields = {}, const BodyMeshOptions& options = {}) {
  using S = std::ranges::range_value_t<R>;
  detail::write_vtp_frame(file, time, std::span<const S>(std::ranges::data(shapes), std::ranges::size(shapes)),
                          false, poses, fields, options);
}

template <Shape S>
void write_vtp(const std::filesystem::path& file, double time, const S& shape, std::span<const Pose> poses,
               const std::vector<BodyField>& fields = {}, const BodyMeshOptions& options = {}) {
  detail::write_vtp_frame(file, time, std::span<const S>(&shape, 1), true, poses, fields, options);
}

// A ParaView collection file listing the frames (written atomically).
inline void write_pvd(const std::filesystem::path& file, std::span<const PvdEntry> entries) {
  std::string out = "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
  for (const PvdEntry& e : entries) {
    out += "    <DataSet timestep=\"";
    detail::append_number(out, e.time);
    out += "\" group=\"\" part=\"0\" file=\"" + detail::xml_escaped(e.file) + "\"/>\n";
  }
  out += "  </Collection>\n</VTKFile>\n";
  detail::write_file_atomically(file, out);
}

// A series in `directory` (which must exist): frames <stem>_000000.vtp, ... and <stem>.pvd,
// rewritten after every frame. Times must increase. An existing series of that stem is replaced
// frame by frame (its .pvd at the first frame).
class VtkSeriesWriter {
 public:
  VtkSeriesWriter(std::filesystem::path directory, std::string stem, BodyMeshOptions mesh = {})
      : directory_(std::move(directory)), stem_(std::move(stem)), mesh_(mesh) {
    std::error_code ec;
    if (!std::filesystem::is_directory(directory_, ec))
      fail_argument("directory", "'" + directory_.string() + "' is not an existing directory");
    if (stem_.empty() || stem_.find_first_of("/\\") != std::string::npos)
      fail_argument("stem", "must be a non-empty file name without separators, got '" + stem_ + "'");
    validate(mesh_);
  }

  // Writes the frame and the updated .pvd; returns the frame's path.
  template <std::ranges::contiguous_range R>
    requires Shape<std::ranges::range_value_t<R>>
  std::filesystem::path write_frame(double time, const R& shapes, std::span<const Pose> poses,
                                    const std::vector<BodyField>& fields = {}) {
    return add(time, [&](const std::filesystem::path& f) { write_vtp(f, time, shapes, poses, fields, mesh_); });
  }

  template <Shape S>
  std::filesystem::path write_frame(double time, const S& shape, std::span<const Pose> poses,
                                    const std::vector<BodyField>& fields = {}) {
    return add(time, [&](const std::filesystem::path& f) { write_vtp(f, time, shape, poses, fields, mesh_); });
  }

  std::filesystem::path pvd_path() const { return directory_ / (stem_ + ".pvd"); }
  std::size_t frames() const { return entries_.size(); }

 private:
  template <typename Write>
  std::filesystem::path add(double time, Write write) {
    require_finite(time, "time");
    if (!entries_.empty() && !(time > entries_.back().time))
      fail_argument("time", "must increase from frame to frame, got " + std::to_string(time) + " after " +
                                std::to_string(entries_.back().time));
    char name[32];
    std::snprintf(name, sizeof name, "_%06zu.vtp", entries_.size());
    const std::string file = stem_ + name;
    write(directory_ / file);
    entries_.push_back({time, file});
    write_pvd(pvd_path(), entries_);
    return directory_ / file;
  }

  std::filesystem::path directory_;
  std::string stem_;
  BodyMeshOptions mesh_;
  std::vector<PvdEntry> entries_;
};

}  // namespace stokescontact
