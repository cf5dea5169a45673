#!/usr/bin/env python3
"""Render one frame of a libwrapsim VTK series to a PNG with VTK's Python (no ParaView needed).

    xvfb-run -a python3 tools/vtk_render_frame.py OUT/run.pvd frame.png [--frame N] [--size W H]

Reads the .pvd, takes frame N (default: the last; negative counts from the end), draws the bodies
in grey, the contacts as points and the film coloured by its around tension (N) with a colour bar,
and writes the picture off screen. Needs Debian's python3-vtk9 and, without a display, xvfb-run
(package xvfb). Prints the frame's time and the tension range it coloured.
"""

import argparse
import pathlib
import sys
import xml.etree.ElementTree as ET

import vtk


def frames(pvd):
    """(time, path of the .vtm) of every frame of a .pvd, in its order."""
    root = ET.parse(pvd).getroot()
    base = pathlib.Path(pvd).parent
    return [(float(d.get("timestep")), base / d.get("file")) for d in root.iter("DataSet")]


def blocks(vtm):
    """{name: dataset or list of (name, dataset)} of a frame's multiblock."""
    r = vtk.vtkXMLMultiBlockDataReader()
    r.SetFileName(str(vtm))
    r.Update()
    mb = r.GetOutput()
    out = {}
    for b in range(mb.GetNumberOfBlocks()):
        name = mb.GetMetaData(b).Get(vtk.vtkCompositeDataSet.NAME())
        blk = mb.GetBlock(b)
        if blk is not None and blk.IsA("vtkMultiBlockDataSet"):
            out[name] = [(blk.GetMetaData(c).Get(vtk.vtkCompositeDataSet.NAME()), blk.GetBlock(c))
                         for c in range(blk.GetNumberOfBlocks())]
        else:
            out[name] = blk
    return out


def actor(ds, color=None, scalars=None, lut=None, rng=None, point_size=None):
    m = vtk.vtkDataSetMapper()
    m.SetInputData(ds)
    a = vtk.vtkActor()
    a.SetMapper(m)
    if scalars:
        m.SetScalarModeToUseCellFieldData()
        m.SelectColorArray(scalars)
        m.SetLookupTable(lut)
        m.SetScalarRange(*rng)
        m.ScalarVisibilityOn()
    else:
        m.ScalarVisibilityOff()
        a.GetProperty().SetColor(*color)
    if point_size:
        a.GetProperty().SetPointSize(point_size)
        a.GetProperty().SetRepresentationToPoints()
    return a


def render(pvd, png, frame=-1, size=(800, 600)):
    fr = frames(pvd)
    if not fr:
        raise SystemExit(f"{pvd}: no frames")
    t, vtm = fr[frame]
    b = blocks(vtm)
    ren = vtk.vtkRenderer()
    ren.SetBackground(1.0, 1.0, 1.0)
    ren.AddActor(actor(b["bodies"], color=(0.62, 0.62, 0.66)))
    lut = vtk.vtkLookupTable()
    lut.SetHueRange(0.667, 0.0)  # blue (slack) to red (taut)
    lut.Build()
    lo, hi = float("inf"), float("-inf")
    for _, film in b.get("film", []):
        a = film.GetCellData().GetArray("tension_around")
        if a is not None and a.GetNumberOfTuples():
            lo, hi = min(lo, a.GetRange()[0]), max(hi, a.GetRange()[1])
    if lo > hi:
        lo, hi = 0.0, 1.0
    for _, film in b.get("film", []):
        ren.AddActor(actor(film, scalars="tension_around", lut=lut, rng=(lo, hi)))
    if b.get("contacts") is not None and b["contacts"].GetNumberOfPoints():
        ren.AddActor(actor(b["contacts"], color=(0.1, 0.1, 0.1), point_size=4))
    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(lut)
    bar.SetTitle("film tension around, N")
    bar.GetTitleTextProperty().SetColor(0, 0, 0)
    bar.GetLabelTextProperty().SetColor(0, 0, 0)
    bar.SetNumberOfLabels(5)
    ren.AddActor2D(bar)
    cam = ren.GetActiveCamera()
    cam.SetViewUp(0, 0, 1)
    cam.SetPosition(2.0, -3.0, 1.6)
    cam.SetFocalPoint(0, 0, 0.25)
    # Frame the film (the load) when there is one, the whole scene otherwise.
    films = [f for _, f in b.get("film", []) if f.GetNumberOfPoints()]
    if films:
        ren.ResetCamera(films[0].GetBounds())
        cam.Zoom(0.6)
    else:
        ren.ResetCamera()
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(*size)
    win.AddRenderer(ren)
    win.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    grab.Update()
    w = vtk.vtkPNGWriter()
    w.SetFileName(str(png))
    w.SetInputConnection(grab.GetOutputPort())
    w.Write()
    return t, lo, hi


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("pvd")
    p.add_argument("png")
    p.add_argument("--frame", type=int, default=-1)
    p.add_argument("--size", type=int, nargs=2, default=(800, 600))
    a = p.parse_args(argv)
    t, lo, hi = render(a.pvd, a.png, a.frame, tuple(a.size))
    print(f"{a.png}: frame at t = {t:g} s, film tension around {lo:.3g} .. {hi:.3g} N")
    return 0


if __name__ == "__main__":
    sys.exit(main())
