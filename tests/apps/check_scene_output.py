#!/usr/bin/python3
"""Runs a scene through stokescontact-run and reads what it wrote back independently.

    /usr/bin/python3 tests/apps/check_scene_output.py RUNNER SCENE.json OUT_DIR MAX_STEPS

The summary (summary.json) and the step log (steps.jsonl, one object per step, steps 1..n,
times n dt) agree with each other and with the scene; the VTK series (bodies.pvd, read with
xml.etree, and each frame with VTK's own vtkXMLPolyDataReader) lists frames at increasing
times equal to the .pvd timesteps, every frame holds the scene's bodies (body_id 0..N-1 on the
points, one centre and one unit quaternion per body in the FieldData), rods' axes are their
quaternion applied to e_z, the last frame is at the run's final time, and the collision stress log (stress.jsonl) has a
symmetric tensor with pressure trace / 3 each step, nonzero exactly when pairs pushed, whose
mean is the summary's. Exits 1 with the
failures listed.
"""
import json
import math
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import vtk
from vtk.util.numpy_support import vtk_to_numpy

runner, scene_file, out_dir, max_steps = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


shutil.rmtree(out_dir, ignore_errors=True)
run = subprocess.run([runner, scene_file, "--output", out_dir, "--max-steps", str(max_steps), "--quiet"],
                     capture_output=True, text=True)
print(run.stdout)
if run.returncode != 0:
    sys.exit("runner failed (%d): %s" % (run.returncode, run.stderr))

scene = json.load(open(scene_file))
summary = json.load(open(os.path.join(out_dir, "summary.json")))
dt = scene["time"]["dt"]
steps = [json.loads(line) for line in open(os.path.join(out_dir, "steps.jsonl"))]
check(len(steps) == summary["steps_done"] == max_steps, "steps: %d lines, summary %d, asked %d"
      % (len(steps), summary["steps_done"], max_steps))
for k, s in enumerate(steps):
    check(s["step"] == k + 1, "step %d numbered %d" % (k + 1, s["step"]))
    check(math.isclose(s["time"], (k + 1) * dt, rel_tol=1e-12), "step %d at t %g" % (k + 1, s["time"]))
check(summary["applications_total"] == sum(s["mobility_applications"] for s in steps),
      "summary's applications differ from the step log's sum")
check(math.isclose(summary["min_distance_ratio"], min(s["min_distance_ratio"] for s in steps), rel_tol=1e-12),
      "summary's min d / d_hat differs from the step log's")
check(summary["min_distance_ratio"] >= 1 - 1e-3, "min d / d_hat %g below the margin" % summary["min_distance_ratio"])
# The scene leaves contact.cost at automatic and its model is free draining: the blocks mode.
check(summary["contact_cost"] == "blocks", "contact cost mode %r, expected blocks" % summary["contact_cost"])

stress = [json.loads(line) for line in open(os.path.join(out_dir, "stress.jsonl"))]
check(len(stress) == len(steps), "stress.jsonl has %d lines for %d steps" % (len(stress), len(steps)))
for k, s in enumerate(stress):
    check(s["step"] == k + 1, "stress line %d numbered %d" % (k + 1, s["step"]))
    sigma = s["collision_stress"]
    check(math.isclose(s["collision_pressure"], (sigma[0] + sigma[4] + sigma[8]) / 3, rel_tol=1e-12, abs_tol=1e-300),
          "step %d: collision pressure is not trace / 3" % (k + 1))
    check(all(abs(sigma[3 * i + j] - sigma[3 * j + i]) <= 1e-9 * max(1.0, max(map(abs, sigma)))
              for i in range(3) for j in range(3)), "step %d: frictionless collision stress not symmetric" % (k + 1))
    check((sum(map(abs, sigma)) > 0) == (steps[k]["active_pairs"] > 0),
          "step %d: stress %s with %d active pairs" % (k + 1, sigma, steps[k]["active_pairs"]))
mean_pressure = sum(s["collision_pressure"] for s in stress) / len(stress)
check(math.isclose(summary["collision_pressure_mean"], mean_pressure, rel_tol=1e-9),
      "summary's collision pressure %g is not the mean %g of the steps'" % (summary["collision_pressure_mean"], mean_pressure))

pvd = ET.parse(os.path.join(out_dir, "bodies.pvd")).getroot()
frames = [(float(d.get("timestep")), d.get("file")) for d in pvd.iter("DataSet")]
check(len(frames) == summary["frames"], "pvd lists %d frames, summary %d" % (len(frames), summary["frames"]))
check(all(a[0] < b[0] for a, b in zip(frames, frames[1:])), "frame times do not increase")
check(math.isclose(frames[-1][0], summary["time"], rel_tol=1e-12), "last frame at %g, run ended at %g"
      % (frames[-1][0], summary["time"]))
bodies = summary["bodies"]
for time, name in frames:
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(os.path.join(out_dir, name))
    reader.Update()
    poly = reader.GetOutput()
    check(poly.GetNumberOfPoints() > 0 and poly.GetNumberOfPolys() > 0, "%s: no mesh" % name)
    ids = vtk_to_numpy(poly.GetPointData().GetArray("body_id"))
    check(sorted(set(ids.tolist())) == list(range(bodies)), "%s: body ids are not 0..%d" % (name, bodies - 1))
    fd = poly.GetFieldData()
    check(math.isclose(fd.GetArray("TIME").GetValue(0), time, rel_tol=1e-12), "%s: TIME differs from the pvd" % name)
    centres = vtk_to_numpy(fd.GetArray("centre"))
    quats = vtk_to_numpy(fd.GetArray("orientation_quaternion"))
    axes = vtk_to_numpy(fd.GetArray("axis"))
    check(centres.shape == (bodies, 3) and quats.shape == (bodies, 4), "%s: per-body field data sizes" % name)
    for k in range(bodies):
        w, x, y, z = quats[k]
        check(abs(w * w + x * x + y * y + z * z - 1) < 1e-9, "%s: body %d quaternion not unit" % (name, k))
        # R e_z for q = (w, x, y, z)
        ez = (2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y))
        check(all(abs(a - b) < 1e-9 for a, b in zip(ez, axes[k])), "%s: body %d axis is not q e_z" % (name, k))

if failures:
    print("\n".join(failures[:20]))
    sys.exit(1)
print("check_scene_output: %d steps, %d frames of %d bodies read back" % (len(steps), len(frames), bodies))
