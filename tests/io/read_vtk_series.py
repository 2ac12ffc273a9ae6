#!/usr/bin/python3
"""Reads the series written by write_vtk_example back with VTK's own XML reader.

    /usr/bin/python3 tests/io/read_vtk_series.py OUT_DIR/expected.json

For each series in expected.json: the .pvd (xml.etree) lists the frames with their times; each
.vtp (vtkXMLPolyDataReader) has bodies x the vertices and triangles per body that the mesh
resolution implies (derived here from io/body_mesh.hpp's documented rule, not read from the
C++ side), only triangles, TIME = TimeValue = the .pvd timestep, the body centres, orientation
quaternions (w x y z), axes and shape parameters in its FieldData, body_id and velocity on the
points, unit normals, sphere vertices one radius from their centre, and each body's mesh bounds
containing its centre. Exits 1 with the failures listed.
"""
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

import vtk
from vtk.util.numpy_support import vtk_to_numpy

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
    return condition


def close(a, b, tol=1e-12):
    return abs(a - b) <= tol * max(1.0, abs(a), abs(b))


def samples_along_curve(series, k, ring_points, arc_pieces):
    """Curve samples K of body k: 1 for a sphere (or a rod of zero length), 2 for a rod, the
    arc's pieces + 1 and one per arm for a boomerang."""
    shape = series["shape"]
    if shape == "sphere":
        return 1
    if shape == "spherocylinder":
        return 2 if series["length"][k] > 0 else 1
    if shape == "boomerang":
        pieces = arc_pieces or max(2, math.ceil((math.pi / 2) / (math.pi / ring_points) - 1e-9))
        return pieces + 1 + (2 if series["arm_length"][k] > 0 else 0)
    raise ValueError("unknown shape " + shape)


def rotate(q, v):
    w, x, y, z = q
    u = (x, y, z)
    t = [2 * (u[1] * v[2] - u[2] * v[1]), 2 * (u[2] * v[0] - u[0] * v[2]), 2 * (u[0] * v[1] - u[1] * v[0])]
    c = (u[1] * t[2] - u[2] * t[1], u[2] * t[0] - u[0] * t[2], u[0] * t[1] - u[1] * t[0])
    return [v[i] + w * t[i] + c[i] for i in range(3)]


def field_tuples(data, name):
    array = data.GetFieldData().GetAbstractArray(name)
    if not check(array is not None, "FieldData array %s missing" % name):
        return None
    return vtk_to_numpy(array).reshape(array.GetNumberOfTuples(), array.GetNumberOfComponents())


def check_frame(series, frame, path, ring_points, cap_rings, arc_pieces, timestep):
    where = os.path.basename(path)
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    check(reader.GetErrorCode() == 0, "%s: reader error %d" % (where, reader.GetErrorCode()))
    data = reader.GetOutput()
    bodies = series["bodies"]
    rings = [2 * (cap_rings - 1) + samples_along_curve(series, k, ring_points, arc_pieces) for k in range(bodies)]
    vertices = [ring_points * r + 2 for r in rings]
    triangles = [2 * ring_points * r for r in rings]
    check(data.GetNumberOfPoints() == sum(vertices),
          "%s: %d points, expected %d" % (where, data.GetNumberOfPoints(), sum(vertices)))
    check(data.GetNumberOfPolys() == sum(triangles),
          "%s: %d polygons, expected %d" % (where, data.GetNumberOfPolys(), sum(triangles)))
    check(data.GetNumberOfCells() == data.GetNumberOfPolys(), "%s: cells other than polygons" % where)
    check(data.GetPolys().GetMaxCellSize() == 3, "%s: polygons are not all triangles" % where)

    for name in ("TIME", "TimeValue"):
        t = field_tuples(data, name)
        if t is not None:
            check(t.shape == (1, 1) and t[0, 0] == timestep and t[0, 0] == frame["time"],
                  "%s: %s = %s, .pvd timestep %r" % (where, name, t.ravel(), timestep))
    centre = field_tuples(data, "centre")
    quaternion = field_tuples(data, "orientation_quaternion")
    axis = field_tuples(data, "axis")
    velocity = field_tuples(data, "velocity")
    for a, n in ((centre, 3), (quaternion, 4), (axis, 3), (velocity, 3)):
        if a is not None:
            check(a.shape == (bodies, n), "%s: a FieldData array has shape %s, expected (%d, %d)" % (where, a.shape, bodies, n))
    for name in ("radius", "length", "arm_length", "bend_radius"):
        if name in series:
            p = field_tuples(data, name)
            if p is not None:
                check(p.shape == (bodies, 1) and all(close(p[k, 0], series[name][k]) for k in range(bodies)),
                      "%s: %s = %s, expected %s" % (where, name, p.ravel(), series[name]))

    points = vtk_to_numpy(data.GetPoints().GetData())
    point_data = data.GetPointData()
    body_id = point_data.GetArray("body_id")
    normals = point_data.GetNormals()
    point_velocity = point_data.GetArray("velocity")
    if not (check(body_id is not None, "%s: no body_id" % where) and check(normals is not None, "%s: no Normals" % where)
            and check(point_velocity is not None, "%s: no velocity on the points" % where)):
        return
    body_id = vtk_to_numpy(body_id)
    normals = vtk_to_numpy(normals)
    point_velocity = vtk_to_numpy(point_velocity)
    check(abs(abs(normals).sum(axis=1).min()) > 0 and
          max(abs(math.sqrt(sum(c * c for c in n)) - 1.0) for n in normals) < 1e-12, "%s: normals not unit" % where)

    for k in range(bodies):
        mine = body_id == k
        check(int(mine.sum()) == vertices[k], "%s: body %d has %d vertices, expected %d" % (where, k, mine.sum(), vertices[k]))
        c = frame["centre"][k]
        q = frame["quaternion"][k]
        if centre is not None:
            check(all(close(centre[k, i], c[i]) for i in range(3)), "%s: centre %d = %s, expected %s" % (where, k, centre[k], c))
        if quaternion is not None:
            check(all(close(quaternion[k, i], q[i]) for i in range(4)),
                  "%s: quaternion %d = %s, expected %s" % (where, k, quaternion[k], q))
        if axis is not None:
            z = rotate(q, (0.0, 0.0, 1.0))
            check(all(close(axis[k, i], z[i]) for i in range(3)), "%s: axis %d = %s, expected %s" % (where, k, axis[k], z))
        v = frame["velocity"][3 * k:3 * k + 3]
        if velocity is not None:
            check(all(velocity[k, i] == v[i] for i in range(3)), "%s: velocity %d = %s, expected %s" % (where, k, velocity[k], v))
        check(all((point_velocity[mine] == v).all(axis=1)), "%s: body %d's point velocity differs from %s" % (where, k, v))
        p = points[mine]
        lo, hi = p.min(axis=0), p.max(axis=0)
        check(all(lo[i] < c[i] < hi[i] for i in range(3)), "%s: body %d's bounds %s..%s miss its centre %s" % (where, k, lo, hi, c))
        distance = [math.dist(x, c) for x in p]
        if series["shape"] == "sphere":
            r = series["radius"][k]
            check(max(abs(d - r) for d in distance) <= 1e-12 * r, "%s: sphere %d's vertices are not one radius out" % (where, k))
        elif series["shape"] == "spherocylinder":
            check(max(distance) <= 0.5 * series["length"][k] + series["radius"][k] + 1e-12,
                  "%s: rod %d reaches beyond its ends" % (where, k))
        elif "bounding_radius" in series:
            check(max(distance) <= series["bounding_radius"] + 1e-12, "%s: body %d beyond its bounding radius" % (where, k))


def main():
    if len(sys.argv) != 2:
        print("usage: read_vtk_series.py OUT_DIR/expected.json", file=sys.stderr)
        return 2
    expected_path = sys.argv[1]
    directory = os.path.dirname(os.path.abspath(expected_path))
    with open(expected_path) as f:
        expected = json.load(f)
    frames_read = 0
    for series in expected["series"]:
        pvd = os.path.join(directory, series["pvd"])
        root = ET.parse(pvd).getroot()
        check(root.tag == "VTKFile" and root.get("type") == "Collection", "%s: not a VTK collection" % pvd)
        datasets = root.findall("./Collection/DataSet")
        check(len(datasets) == len(series["frames"]),
              "%s lists %d frames, expected %d" % (series["pvd"], len(datasets), len(series["frames"])))
        for dataset, frame in zip(datasets, series["frames"]):
            timestep = float(dataset.get("timestep"))
            check(timestep == frame["time"], "%s: timestep %r, expected %r" % (series["pvd"], timestep, frame["time"]))
            check_frame(series, frame, os.path.join(directory, dataset.get("file")), expected["ring_points"],
                        expected["cap_rings"], expected["arc_pieces"], timestep)
            frames_read += 1
    if failures:
        print("read_vtk_series: %d failure(s):" % len(failures))
        for f in failures:
            print("  " + f)
        return 1
    print("read_vtk_series: VTK %s read %d frames of %d series: counts, times, centres, quaternions, fields OK"
          % (vtk.vtkVersion.GetVTKVersion(), frames_read, len(expected["series"])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
