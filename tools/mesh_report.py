#!/usr/bin/python3
"""What a gmsh geometry makes, and whether its faults can be split.
It meshes each geometry as the solver does (gmsh, dimension 3 if it has a
volume, else 2) and prints the time to mesh, the nodes the cells use, the
cells of each physical group of cells, and for each physical group of
facets how many cells each of its facets bounds: 1 on the outer boundary,
2 inside the body. A fault (`--fault`, default "crack" and "fault") must be
conforming, every facet a facet of exactly two cells, and inside the body;
the exit status is 1 if one is not. It also prints the fault's facet sizes
(edge lengths), which are what the mesh resolves the opening or slip by.
"""
import argparse
import collections
import sys
import time

import gmsh
import numpy as np

# The facets of a cell, by local vertex: a triangle's edges, a tetrahedron's faces.
LOCAL_FACETS = {2: [(0, 1), (1, 2), (2, 0)], 3: [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]}


def mesh(path):
    """Meshes `path` (gmsh open, generate); its dimension and the seconds taken."""
    gmsh.open(path)
    d = 3 if gmsh.model.getEntities(3) else 2
    start = time.perf_counter()
    gmsh.model.mesh.generate(d)
    return d, time.perf_counter() - start


def facet_counts(cells, d):
    """The sorted facets (rows of node tags) of all cells and how many cells each bounds."""
    facets = np.sort(cells[:, LOCAL_FACETS[d]], axis=2).reshape(-1, d)
    return np.unique(facets, axis=0, return_counts=True)


def group_facets(dim, tag, d):
    """The facets (rows of sorted node tags) of one physical group of dimension d - 1."""
    rows = []
    for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
        _, nodes = gmsh.model.mesh.getElementsByType(1 if d == 2 else 2, entity)
        rows.append(np.asarray(nodes, dtype=np.int64).reshape(-1, d))
    return np.sort(np.concatenate(rows), axis=1)


def cells_per_facet(facets, unique, counts):
    """How many cells bound each of `facets` (0 for a facet of no cell)."""
    keys = unique.view([("", unique.dtype)] * unique.shape[1]).ravel()
    wanted = np.ascontiguousarray(facets).view(keys.dtype).ravel()
    at = np.clip(np.searchsorted(keys, wanted), 0, len(keys) - 1)
    return np.where(keys[at] == wanted, counts[at], 0)


def facet_sizes(facets):
    """The shortest and longest edge of `facets` (rows of node tags)."""
    tags, x, _ = gmsh.model.mesh.getNodes()
    position = dict(zip(tags, np.asarray(x).reshape(-1, 3)))
    points = np.array([[position[t] for t in row] for row in facets])
    k = facets.shape[1]
    edges = [np.linalg.norm(points[:, i] - points[:, (i + 1) % k], axis=1) for i in range(k if k > 2 else 1)]
    return float(np.min(edges)), float(np.max(edges))


def report(path, faults):
    """Prints what `path` makes; False if one of its faults cannot be split."""
    d, seconds = mesh(path)
    _, nodes = gmsh.model.mesh.getElementsByType(2 if d == 2 else 4)
    cells = np.asarray(nodes, dtype=np.int64).reshape(-1, d + 1)
    print(f"{path}: {d}D, meshed in {seconds:.2f} s: {len(np.unique(cells))} nodes, {len(cells)} cells")
    for dim, tag in gmsh.model.getPhysicalGroups(d):
        n = sum(len(gmsh.model.mesh.getElementsByType(2 if d == 2 else 4, e)[0])
                for e in gmsh.model.getEntitiesForPhysicalGroup(dim, tag))
        print(f"  cells {gmsh.model.getPhysicalName(dim, tag)!r}: {n}")
    unique, counts = facet_counts(cells, d)
    ok = True
    for dim, tag in gmsh.model.getPhysicalGroups(d - 1):
        name = gmsh.model.getPhysicalName(dim, tag)
        facets = group_facets(dim, tag, d)
        bounding = collections.Counter(cells_per_facet(facets, unique, counts).tolist())
        line = f"  facets {name!r}: {len(facets)}, cells per facet {dict(sorted(bounding.items()))}"
        if name in faults:
            conforming = set(bounding) == {2}
            ok = ok and conforming
            low, high = facet_sizes(facets)
            line += f", edges {low:.3g} .. {high:.3g}, {'conforming' if conforming else 'NOT CONFORMING'}"
        print(line)
    return ok


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("geometry", nargs="+")
    parser.add_argument("--fault", action="append", help='a fault group (default "crack" and "fault")')
    args = parser.parse_args()
    faults = set(args.fault or ["crack", "fault"])
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    ok = True
    for path in args.geometry:
        ok = report(path, faults) and ok
        gmsh.clear()
    gmsh.finalize()
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
