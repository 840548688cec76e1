"""The XDMF output opens in meshio and ParaView (issue 11): one temporal
collection, one grid per output time on the one mesh, every field an
attribute of every grid, 64-bit precision declared. meshio's
TimeSeriesReader reads every array at every output time as float64, equal to
the datasets in solution.h5, on a single-rate, a multirate, a pure-flow and
a two-rank run; the contact flags are exactly 0 or 1; at a fine multirate
time the mechanics fields repeat the last mechanics state."""
import os
import xml.etree.ElementTree as ET

import h5py
import meshio
import numpy as np
from support import check, run, scene, summary

CASES = [("single rate", "default", [], 1, {"pressure", "flux", "displacement", "sigma_v", "contact_pressure",
                                             "contact_active", "contact_boundary"}),
         ("multirate", "default", ["--set", "coupling.scheme=multirate", "--set", "coupling.q=4"], 1,
          {"pressure", "flux", "displacement", "sigma_v", "contact_pressure", "contact_active", "contact_boundary"}),
         ("pure flow", "darcy", [], 1, {"pressure", "flux"}),
         ("two ranks", "default", [], 2, {"pressure", "flux", "displacement", "sigma_v", "contact_pressure",
                                          "contact_active", "contact_boundary"})]

for label, name, options, ranks, fields in CASES:
    out, _ = run(scene(name), *options, ranks=ranks)
    xdmf = os.path.join(out, "solution.xdmf")
    tree = ET.parse(xdmf)
    collections = [g for g in tree.iter("Grid") if g.get("GridType") == "Collection"]
    grids = [g for g in tree.iter("Grid") if g.get("GridType") == "Uniform"]
    check(len(collections) == 1 and collections[0].get("CollectionType") == "Temporal",
          f"{label}: one temporal collection")
    items = list(tree.iter("DataItem"))
    check(all(d.get("Precision") == "8" for d in items), f"{label}: all {len(items)} data items are 64-bit")
    geometry = {g.find("Geometry/DataItem").text for g in grids} | {g.find("Topology/DataItem").text for g in grids}
    check(len(geometry) == 2, f"{label}: every grid shares one geometry and one topology dataset")
    for g in grids:
        names = {a.get("Name") for a in g.findall("Attribute")}
        if names != fields:
            check(False, f"{label}: grid at t = {g.find('Time').get('Value')} has {sorted(names)}")
    check(True, f"{label}: each of the {len(grids)} grids carries {sorted(fields)}")

    # Every array through meshio, equal to the HDF5 dataset the XDMF names.
    with h5py.File(os.path.join(out, "solution.h5"), "r") as h5, meshio.xdmf.TimeSeriesReader(xdmf) as reader:
        points, cells = reader.read_points_cells()
        check(points.shape[0] == h5["Mesh/geometry"].shape[0] and cells[0].data.shape[0] == h5["Mesh/topology"].shape[0],
              f"{label}: meshio reads the mesh ({points.shape[0]} nodes, {cells[0].data.shape[0]} cells)")
        check(reader.num_steps == len(grids), f"{label}: meshio reads {reader.num_steps} times")
        worst = 0.0
        for k, grid in enumerate(grids):
            t, point_data, cell_data = reader.read_data(k)
            check_t = float(grid.find("Time").get("Value"))
            if t != check_t:
                check(False, f"{label}: time {k} is {t} in meshio, {check_t} in the XDMF")
            arrays = dict(point_data)
            arrays.update({n: v[0] for n, v in cell_data.items()})
            if set(arrays) != fields:
                check(False, f"{label}: meshio reads {sorted(arrays)} at t = {t}")
            for a in grid.findall("Attribute"):
                values = arrays[a.get("Name")]
                stored = h5[a.find("DataItem").text.split(":")[1]][:]
                if values.dtype != np.float64 or not np.array_equal(values.reshape(stored.shape), stored):
                    check(False, f"{label}: {a.get('Name')} at t = {t}: meshio gives {values.dtype}, "
                                 "not the stored float64 values")
            for flag in ("contact_active", "contact_boundary"):
                if flag in arrays and not np.all((arrays[flag] == 0) | (arrays[flag] == 1)):
                    check(False, f"{label}: {flag} is not exactly 0 or 1 at t = {t}")
        check(True, f"{label}: every array at every time is float64 and equal to solution.h5")

    if label == "multirate":
        s = summary(out)
        datasets = [g.find("Attribute[@Name='displacement']/DataItem").text for g in grids]
        check(len(grids) == s["fine_steps"] + 1 and len(set(datasets)) == s["steps"] + 1,
              f"multirate: {len(grids)} grids (every fine time), {len(set(datasets))} mechanics states "
              f"({s['steps']} mechanics steps + the initial state), repeated at the fine times")
