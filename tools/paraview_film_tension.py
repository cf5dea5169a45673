"""ParaView script: colour a libwrapsim film by its tension and save a picture or an animation.

    xvfb-run -a pvbatch tools/paraview_film_tension.py OUT/run.pvd [film.png] [--array A]
        [--time T] [--movie]

Run by pvbatch (Debian package paraview; xvfb-run from package xvfb gives it a display when there
is none), or in the ParaView GUI's Python shell with the same arguments in sys.argv. It opens the
.pvd, takes the multiblock's named blocks, shows the bodies in grey and the film surface coloured
by the cell array A (default tension_around, N; also tension_up, strain_around, strain_up) over
its range in the whole run, with a colour bar, and writes the frame at time T (default: the
last) to the PNG, or every frame as film_NNNN.png with --movie.
"""

import argparse
import os
import sys

from paraview import simple as pv  # noqa: E402  (pvbatch puts paraview on the path)


def main(argv):
    p = argparse.ArgumentParser(description="colour the film of a libwrapsim run by tension")
    p.add_argument("pvd")
    p.add_argument("png", nargs="?", default="film.png")
    p.add_argument("--array", default="tension_around")
    p.add_argument("--time", type=float, default=None)
    p.add_argument("--movie", action="store_true")
    a = p.parse_args(argv)

    run = pv.PVDReader(FileName=a.pvd)
    run.UpdatePipelineInformation()
    times = list(run.TimestepValues) if run.TimestepValues else [0.0]
    view = pv.GetActiveViewOrCreate("RenderView")
    view.ViewSize = [1200, 900]
    view.Background = [1.0, 1.0, 1.0]
    try:  # ParaView 5.10+ takes the background from the palette unless told otherwise
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    view.OrientationAxesVisibility = 0

    # The blocks by name: the selectors are the paths of the multiblock.
    bodies = pv.ExtractBlock(Input=run, Selectors=["/Root/bodies"])
    film = pv.ExtractBlock(Input=run, Selectors=["/Root/film"])
    grey = pv.Show(bodies, view)
    pv.ColorBy(grey, None)  # not by the active cell scalars ("body")
    grey.DiffuseColor = grey.AmbientColor = [0.62, 0.62, 0.66]
    shown = pv.Show(film, view)
    pv.ColorBy(shown, ("CELLS", a.array))
    lut = pv.GetColorTransferFunction(a.array)
    lut.ApplyPreset("Turbo" if "Turbo" in pv.GetLookupTableNames() else "Jet", True)
    # One range over the whole run, so the colours mean the same newtons in every frame.
    lo, hi = float("inf"), float("-inf")
    for t in times:
        film.UpdatePipeline(t)
        rng = film.CellData[a.array].GetRange()
        lo, hi = min(lo, rng[0]), max(hi, rng[1])
    lut.RescaleTransferFunction(lo, hi)
    bar = pv.GetScalarBar(lut, view)
    bar.Title = a.array.replace("_", " ") + (" (N)" if a.array.startswith("tension") else "")
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0, 0, 0]
    shown.SetScalarBarVisibility(view, True)

    view.CameraPosition = [2.0, -3.0, 1.6]
    view.CameraFocalPoint = [0.0, 0.0, 0.25]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    if a.movie:
        stem = a.png[:-4] if a.png.endswith(".png") else a.png
        for k, t in enumerate(times):
            view.ViewTime = t
            pv.SaveScreenshot(f"{stem}_{k:04d}.png", view)
        print(f"{len(times)} frames, {a.array} {lo:.4g} .. {hi:.4g}: {stem}_NNNN.png")
    else:
        view.ViewTime = times[-1] if a.time is None else min(times, key=lambda t: abs(t - a.time))
        pv.SaveScreenshot(a.png, view)
        print(f"t = {view.ViewTime:g} s, {a.array} {lo:.4g} .. {hi:.4g}: {a.png}")
    return 0


if __name__ == "__main__":
    status = main(sys.argv[1:])
    # Debian's pvbatch 5.11 under Xvfb fails a GLX call while it tears its render window down,
    # after the pictures are written, and exits 1 for it. Leave without the teardown so that the
    # exit status says whether the work was done.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
