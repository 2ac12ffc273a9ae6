"""Renders VTK series written by io/vtk_polydata.hpp to a PNG with ParaView, offscreen.

    pvbatch scripts/render_scene.py SERIES.pvd [MORE.pvd ...] OUT.png [--frame last|first|N]
                                    [--size WIDTHxHEIGHT]

Each .pvd is loaded with PVDReader (several: a scene with several shape types, one series per
type), shown as its surfaces coloured by body_id, at the chosen frame (default: the last; N
counts from 0), with a camera that fits all of the data. Needs ParaView's pvbatch (Debian:
apt-get install paraview python3-paraview); not part of the test suite. Debian's ParaView 5.11
renders through X only (no EGL or OSMesa), so without a display run it under Xvfb:
    xvfb-run -a pvbatch scripts/render_scene.py SERIES.pvd OUT.png
"""
import argparse
import sys

from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetColorTransferFunction, PVDReader,
                             ResetCamera, Render, SaveScreenshot, Show)


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("files", nargs="+", help="SERIES.pvd ... OUT.png")
    parser.add_argument("--frame", default="last", help="last, first or a frame number (from 0)")
    parser.add_argument("--size", default="1200x800", help="image size, WIDTHxHEIGHT")
    args = parser.parse_args(argv)
    if len(args.files) < 2 or not args.files[-1].lower().endswith(".png"):
        parser.error("give one or more .pvd files, then the output .png")
    return args


def main(argv):
    args = parse_arguments(argv)
    series, out = args.files[:-1], args.files[-1]
    width, height = (int(v) for v in args.size.lower().split("x"))

    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = [width, height]
    view.Background = [1.0, 1.0, 1.0]
    try:  # ParaView >= 5.10 takes the background from the palette unless told otherwise
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    view.OrientationAxesVisibility = 1

    readers = [PVDReader(registrationName="series%d" % i, FileName=f) for i, f in enumerate(series)]
    times = sorted({t for r in readers for t in r.TimestepValues}) if any(
        len(r.TimestepValues) for r in readers) else [0.0]
    if args.frame == "last":
        time = times[-1]
    elif args.frame == "first":
        time = times[0]
    else:
        time = times[int(args.frame)]
    view.ViewTime = time

    lo, hi = float("inf"), float("-inf")
    for r in readers:
        r.UpdatePipeline(time)
        ids = r.PointData["body_id"].GetRange()
        lo, hi = min(lo, ids[0]), max(hi, ids[1])
    for r in readers:
        display = Show(r, view)
        display.Representation = "Surface"
        ColorBy(display, ("POINTS", "body_id"))
    lut = GetColorTransferFunction("body_id")
    lut.ApplyPreset("Rainbow Uniform", True)
    lut.RescaleTransferFunction(lo, max(hi, lo + 1.0))

    Render(view)  # the first render resets the camera: place it afterwards
    camera = view.GetActiveCamera()  # looking from the front right, above, z up
    camera.SetFocalPoint(0.0, 0.0, 0.0)
    camera.SetPosition(1.0, -2.0, 1.2)
    camera.SetViewUp(0.0, 0.0, 1.0)
    ResetCamera(view)  # keeps the direction, fits the data
    Render(view)
    SaveScreenshot(out, view, ImageResolution=[width, height])
    print("render_scene: %s at t = %g -> %s" % (", ".join(series), time, out))


if __name__ == "__main__":
    main(sys.argv[1:])
