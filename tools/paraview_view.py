"""What a new user sees in ParaView: opens a run's solution.xdmf with
ParaView's default reader, and either checks it (--check: one block, every
array, every time) or renders the screenshot of docs/user-guide.md (--screenshot
PNG: warped by the displacement, coloured by a field, at the last time).

    xvfb-run -a pvpython tools/paraview_view.py RUN_DIR --check
    xvfb-run -a pvpython tools/paraview_view.py RUN_DIR --screenshot docs/paraview.png [--color pressure]

(pvpython comes with Debian's `paraview` package, which the set-up does not
install; `--force-offscreen-rendering` segfaults there, xvfb-run works.)"""
import argparse
import json
import os
import sys
import xml.etree.ElementTree as ET

from paraview import servermanager
from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene, GetColorTransferFunction,
                             GetScalarBar, OpenDataFile, ResetCamera, SaveScreenshot, Show, Text, WarpByVector)


RESOLUTION = [1400, 700]  # the screenshot, in pixels

def expected(xdmf):
    """(times, point arrays, cell arrays) as the XDMF declares them."""
    tree = ET.parse(xdmf)
    grids = [g for g in tree.iter("Grid") if g.get("GridType") == "Uniform"]
    point = {a.get("Name") for a in grids[0].findall("Attribute") if a.get("Center") == "Node"}
    cell = {a.get("Name") for a in grids[0].findall("Attribute") if a.get("Center") == "Cell"}
    return [float(g.find("Time").get("Value")) for g in grids], point, cell


def check(reader, xdmf):
    times, point, cell = expected(xdmf)
    reader.UpdatePipeline(times[-1])
    data = servermanager.Fetch(reader)
    problems = []
    if data.IsA("vtkMultiBlockDataSet"):
        problems.append(f"a multiblock of {data.GetNumberOfBlocks()} blocks, not one grid")
    else:
        got_point = {data.GetPointData().GetArrayName(i) for i in range(data.GetPointData().GetNumberOfArrays())}
        got_cell = {data.GetCellData().GetArrayName(i) for i in range(data.GetCellData().GetNumberOfArrays())}
        if not point <= got_point:
            problems.append(f"point arrays {sorted(got_point)}, expected {sorted(point)}")
        if not cell <= got_cell:
            problems.append(f"cell arrays {sorted(got_cell)}, expected {sorted(cell)}")
        for name in sorted(point | cell):
            array = (data.GetPointData() if name in point else data.GetCellData()).GetArray(name)
            if array is not None and array.GetDataTypeAsString() != "double":
                problems.append(f"{name} arrives as {array.GetDataTypeAsString()}, not double")
    steps = list(reader.TimestepValues) if hasattr(reader.TimestepValues, "__len__") else [reader.TimestepValues]
    if len(steps) != len(times):
        problems.append(f"{len(steps)} time steps, expected {len(times)}")
    print(f"reader {reader.GetXMLName()}: {type(data).__name__ if not hasattr(data, 'GetClassName') else data.GetClassName()}, "
          f"{len(steps)} times, point {sorted(point)}, cell {sorted(cell)}")
    for p in problems:
        print("problem: " + p)
    return 1 if problems else 0


def screenshot(reader, xdmf, path, color):
    times, point, cell = expected(xdmf)
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = times[-1]
    view = GetActiveViewOrCreate("RenderView")
    # Rendered at the size of the picture: a smaller view scaled up to it
    # scales the fonts too, and cut the title off at both edges.
    view.ViewSize = RESOLUTION
    source = reader
    if "displacement" in point:
        source = WarpByVector(Input=reader)
        source.Vectors = ["POINTS", "displacement"]
        # Magnified so that the largest displacement shows as a tenth of the
        # domain (millimetres on a metre-sized block are invisible otherwise).
        reader.UpdatePipeline(times[-1])
        largest = reader.PointData["displacement"].GetRange(-1)[1]
        bounds = reader.GetDataInformation().GetBounds()
        size = max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4])
        source.ScaleFactor = 0.1 * size / largest if largest > 0 else 1.0
        print(f"displacement magnified {source.ScaleFactor:.3g} times")
    view.ViewTime = times[-1]
    source.UpdatePipeline(times[-1])
    display = Show(source, view)
    ColorBy(display, ("POINTS" if color in point else "CELLS", color))
    display.RescaleTransferFunctionToDataRange(False, True)
    bar = GetScalarBar(GetColorTransferFunction(color), view)
    bar.Orientation = "Horizontal"
    bar.WindowLocation = "Lower Right Corner"
    bar.ScalarBarLength = 0.3
    bar.TitleFontSize = 24
    bar.LabelFontSize = 22
    bar.Title = color
    bar.ComponentTitle = ""
    display.SetScalarBarVisibility(view, True)
    summary = os.path.join(os.path.dirname(xdmf), "summary.json")
    name = json.load(open(summary)).get("scene", "") if os.path.exists(summary) else ""
    label = Text(Text=f"scene {name}: {color} at t = {times[-1]:g}"
                 + (f", displacement x {source.ScaleFactor:.3g}" if source is not reader else ""))
    label_display = Show(label, view)
    label_display.WindowLocation = "Upper Center"
    label_display.FontSize = 30
    view.OrientationAxesVisibility = 0
    view.InteractionMode = "2D"
    ResetCamera(view)
    view.CameraParallelScale *= 0.6
    SaveScreenshot(path, view, ImageResolution=RESOLUTION)
    print("wrote " + path)
    return 0


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("directory")
    p.add_argument("--check", action="store_true")
    p.add_argument("--screenshot")
    p.add_argument("--color", default="pressure")
    args = p.parse_args()
    xdmf = os.path.join(args.directory, "solution.xdmf")
    reader = OpenDataFile(xdmf)  # ParaView's default reader for .xdmf
    if args.check:
        return check(reader, xdmf)
    return screenshot(reader, xdmf, args.screenshot, args.color)


if __name__ == "__main__":
    sys.exit(main())
