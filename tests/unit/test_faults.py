"""Unit tests of the prototype's split along faults
(python_prototype/domain/faults.py), the twins of tests/unit/test_faults.cpp,
on the same handmade meshes with the same expected arrays: tips kept shared;
a fault from the outer boundary splits its node there; a fault across the
body cuts it in two; in 3D a patch keeps its rim; bad faults refused in one
line naming the key; faults that cross (X) or end on one another (T) give
their meeting node one node per piece around it, and their cells one
junction there. Then gmsh meshes with an embedded curve: area kept, the two
faces at the same points, each a face of one cell. Last, the cells of a
fault's own flow (domain/fault_cells.py) on the fault across the square:
cells, links and ends; the cells a well meets; the two-point
transmissibility and BDF2's history value of the fault's storage
(assembly/fault_flow.py)."""
import os
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.assembly.fault_compliance import (closure_aperture, closure_compliance,  # noqa: E402
                                                        open_patches, patch_compliance)
from python_prototype.assembly.fault_flow import FineStep, history_value, transmissibilities  # noqa: E402
from python_prototype.assembly.fault_flow_jacobian import star_flux_derivative, transmissibility_slopes  # noqa: E402
from python_prototype.domain.fault_cells import FaultEdges, fault_cells, fault_network, well_cells  # noqa: E402
from python_prototype.domain.faults import FaultRequest, InputMesh, split_along_faults  # noqa: E402
from python_prototype.scene.scene import ClosureSpec, WellSpec  # noqa: E402
from python_prototype.scene.input import SceneError  # noqa: E402

PREFIX = "scene.toml: fault."
N = 4  # the 2D square [0, 4]^2: 4 x 4 squares, 32 triangles, node (i, j) = i + 5 j


def node(i, j, k=0):
    return i + (N + 1) * j + (N + 1) ** 2 * k


def square(faults):
    """The square's 4 x 4 unit squares, each cut along its diagonal from
    (i, j) to (i+1, j+1); groups bottom, right, top, left, then `faults`
    (name -> facets)."""
    x = [(i, j) for j in range(N + 1) for i in range(N + 1)]
    cells = []
    for j in range(N):
        for i in range(N):
            v = node(i, j)
            cells += [(v, v + node(1, 0), v + node(1, 1)), (v, v + node(1, 1), v + node(0, 1))]
    groups = {"bottom": [(node(i, 0), node(i + 1, 0)) for i in range(N)],
              "right": [(node(N, j), node(N, j + 1)) for j in range(N)],
              "top": [(node(i, N), node(i + 1, N)) for i in range(N)],
              "left": [(node(0, j), node(0, j + 1)) for j in range(N)], **faults}
    return input_mesh(2, x, cells, groups)


def box(faults):
    """The box [0, 4]^3: 4 x 4 x 4 unit cubes, each cut into 6 tetrahedra
    along its diagonal (one per order of the axes, a conforming mesh); no
    groups but `faults`."""
    x = [(i, j, k) for k in range(N + 1) for j in range(N + 1) for i in range(N + 1)]
    step = [node(1, 0), node(0, 1), node(0, 0, 1)]
    orders = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    cells = []
    for k in range(N):
        for j in range(N):
            for i in range(N):
                for order in orders:
                    cell = [node(i, j, k)]
                    for axis in order:
                        cell.append(cell[-1] + step[axis])
                    cells.append(cell)
    return input_mesh(3, x, cells, faults)


def patch(lo, hi):
    """The triangles of the plane z = 2 over [lo, hi]^2, two per square, as
    the box's tetrahedra have them."""
    facets = []
    for j in range(lo, hi):
        for i in range(lo, hi):
            v = node(i, j, 2)
            facets += [(v, v + node(1, 0), v + node(1, 1)), (v, v + node(0, 1), v + node(1, 1))]
    return facets


def wall(lo, hi):
    """The triangles of the plane x = 2 over [lo, hi]^2 in (y, z), two per
    square, as the box's tetrahedra have them."""
    facets = []
    for k in range(lo, hi):
        for j in range(lo, hi):
            v = node(2, j, k)
            facets += [(v, v + node(0, 1), v + node(0, 1, 1)), (v, v + node(0, 0, 1), v + node(0, 1, 1))]
    return facets


def input_mesh(d, x, cells, groups):
    facets, group = [], []
    for g, name in enumerate(groups):
        facets += groups[name]
        group += [g] * len(groups[name])
    return InputMesh(d, np.array(x, dtype=float), np.array(cells, dtype=np.int64),
                     np.array(facets, dtype=np.int64).reshape(-1, d), np.array(group, dtype=np.int32), list(groups))


def segment(*points):
    """The facets of a polyline through the square's nodes (i, j)."""
    return [(node(*a), node(*b)) for a, b in zip(points, points[1:])]


def cells_with(mesh, nodes):
    """The cells that have all of `nodes`."""
    return [c for c, cell in enumerate(mesh.cells.tolist()) if set(nodes) <= set(cell)]


def pieces(mesh):
    """The number of pieces of the mesh: cells joined through shared facets
    (a union-find)."""
    parent = list(range(len(mesh.cells)))

    def root(c):
        while parent[c] != c:
            parent[c] = parent[parent[c]]
            c = parent[c]
        return c
    first = {}
    for c, cell in enumerate(mesh.cells.tolist()):
        for j in range(len(cell)):
            key = tuple(sorted(cell[:j] + cell[j + 1:]))
            if key in first:
                parent[root(c)] = root(first[key])
            first.setdefault(key, c)
    return len({root(c) for c in range(len(parent))})


def volume(mesh):
    """The total area (2D) or volume (3D) of the cells."""
    edges = mesh.x[mesh.cells[:, 1:]] - mesh.x[mesh.cells[:, :1]]
    return abs(np.linalg.det(edges)).sum() / (2 if mesh.dim == 2 else 6)


def check_split(test, mesh, fault):
    """Each pair at one point; each facet's two faces at the same points and,
    unless all its nodes are tips (then it stays shared: the same nodes, two
    cells), each a face of one cell, the + face's cell on the side the
    normal points into, the - face's on the other; every facet left in the
    groups (all on the outer boundary here) a face of one cell."""
    for plus, minus in fault.pairs:
        np.testing.assert_array_equal(mesh.x[plus], mesh.x[minus])
    for plus, minus, n in zip(fault.plus_facets, fault.minus_facets, fault.normals):
        np.testing.assert_array_equal(mesh.x[plus], mesh.x[minus])
        test.assertAlmostEqual(np.linalg.norm(n), 1.0, delta=1e-15)
        if set(plus) <= set(fault.tips):
            np.testing.assert_array_equal(plus, minus)
            test.assertEqual(len(cells_with(mesh, plus)), 2, f"face {plus}")
            continue
        for face, sign in ((plus, 1), (minus, -1)):
            cells = cells_with(mesh, face)
            test.assertEqual(len(cells), 1, f"face {face}")
            centroid = mesh.x[mesh.cells[cells[0]]].mean(axis=0)
            test.assertGreater(sign * np.dot(centroid - mesh.x[face[0]], n[:mesh.dim]), 0, f"face {face}")
    for facet in mesh.facets:
        test.assertEqual(len(cells_with(mesh, facet)), 1, f"facet {facet}")


class Split(unittest.TestCase):

    def test_interior_segment_keeps_its_tips(self):
        # From (1, 2) to (3, 2): (2, 2) = node 12 doubled, its ends shared.
        mesh = square({"fault": segment((1, 2), (2, 2), (3, 2))})
        boundary = mesh.facets[:16].copy()
        [fault] = split_along_faults(mesh, [FaultRequest("fault", (0.0, 1.0, 0.0))], PREFIX)
        self.assertEqual(fault.name, "fault")
        self.assertEqual(len(mesh.cells), 32)
        self.assertEqual(len(mesh.x), 26)
        np.testing.assert_array_equal(fault.pairs, [[25, 12]])
        np.testing.assert_array_equal(fault.tips, [11, 13])
        np.testing.assert_array_equal(fault.plus_facets, [[11, 25], [25, 13]])
        np.testing.assert_array_equal(fault.minus_facets, [[11, 12], [12, 13]])
        np.testing.assert_array_equal(fault.normals, [[0, 1, 0], [0, 1, 0]])
        # The + side's cells around (2, 2) took the new node, the others kept it.
        self.assertEqual(cells_with(mesh, [25]), [18, 20, 21])
        self.assertEqual(cells_with(mesh, [12]), [10, 11, 13])
        # The fault's facets left the groups; the boundary's are unchanged.
        np.testing.assert_array_equal(mesh.facets, boundary)
        np.testing.assert_array_equal(mesh.facet_group, [0] * 4 + [1] * 4 + [2] * 4 + [3] * 4)
        self.assertEqual(mesh.names, ["bottom", "right", "top", "left", "fault"])
        self.assertEqual(pieces(mesh), 1)
        check_split(self, mesh, fault)

    def test_segment_from_the_boundary_splits_it(self):
        # From (0, 2) on the left edge to (2, 2): nodes 10 and 11 doubled, the
        # left edge's facet above (0, 2) renumbered to the + side's node.
        mesh = square({"fault": segment((0, 2), (1, 2), (2, 2))})
        boundary = mesh.facets[:16].copy()
        [fault] = split_along_faults(mesh, [FaultRequest("fault", (0.0, 1.0, 0.0))], PREFIX)
        self.assertEqual(len(mesh.x), 27)
        np.testing.assert_array_equal(fault.pairs, [[25, 10], [26, 11]])
        np.testing.assert_array_equal(fault.tips, [12])
        np.testing.assert_array_equal(fault.plus_facets, [[25, 26], [26, 12]])
        np.testing.assert_array_equal(fault.minus_facets, [[10, 11], [11, 12]])
        boundary[14] = [25, 15]
        np.testing.assert_array_equal(mesh.facets, boundary)
        self.assertEqual(pieces(mesh), 1)
        check_split(self, mesh, fault)

    def test_segment_across_cuts_the_body_in_two(self):
        mesh = square({"fault": segment((0, 2), (1, 2), (2, 2), (3, 2), (4, 2))})
        boundary = mesh.facets[:16].copy()
        [fault] = split_along_faults(mesh, [FaultRequest("fault", (0.0, -2.0, 0.0))], PREFIX)
        # The hint points down: the lower half is the + side.
        np.testing.assert_array_equal(fault.pairs, [[25, 10], [26, 11], [27, 12], [28, 13], [29, 14]])
        self.assertEqual(len(fault.tips), 0)
        np.testing.assert_array_equal(fault.normals[:, 1], [-1] * 4)
        boundary[5] = [9, 29]
        boundary[13] = [5, 25]
        np.testing.assert_array_equal(mesh.facets, boundary)
        self.assertEqual(pieces(mesh), 2)
        self.assertEqual(len(set(mesh.cells[:16].ravel()) & set(mesh.cells[16:].ravel())), 0)
        check_split(self, mesh, fault)

    def test_interior_patch_in_3d_keeps_its_rim(self):
        # The square [1, 3]^2 of the plane z = 2: (2, 2, 2) = node 62 doubled,
        # the 8 rim nodes shared; the 2 triangles with every node on the rim
        # (57 58 63 and 61 66 67) stay shared.
        mesh = box({"patch": patch(1, 3)})
        [fault] = split_along_faults(mesh, [FaultRequest("patch", (0.0, 0.0, 1.0))], PREFIX)
        self.assertEqual(len(mesh.cells), 384)
        self.assertEqual(len(mesh.x), 126)
        np.testing.assert_array_equal(fault.pairs, [[125, 62]])
        np.testing.assert_array_equal(fault.tips, [56, 57, 58, 61, 63, 66, 67, 68])
        np.testing.assert_array_equal(fault.minus_facets, patch(1, 3))
        np.testing.assert_array_equal(fault.plus_facets, np.where(np.array(patch(1, 3)) == 62, 125, patch(1, 3)))
        np.testing.assert_array_equal(fault.normals, [[0, 0, 1]] * 8)
        self.assertEqual(len(mesh.facets), 0)
        self.assertEqual(pieces(mesh), 1)
        check_split(self, mesh, fault)

    def test_plane_across_the_box_cuts_it_in_two(self):
        mesh = box({"plane": patch(0, 4)})
        [fault] = split_along_faults(mesh, [FaultRequest("plane", (0.0, 0.0, 1.0))], PREFIX)
        np.testing.assert_array_equal(fault.pairs, [[125 + v, 50 + v] for v in range(25)])
        self.assertEqual(len(fault.tips), 0)
        self.assertEqual(pieces(mesh), 2)
        check_split(self, mesh, fault)


class Refusals(unittest.TestCase):
    def refused(self, mesh, faults):
        with self.assertRaises(SceneError) as caught:
            split_along_faults(mesh, faults, PREFIX)
        message = str(caught.exception)
        self.assertNotIn("\n", message)
        return message

    def test_a_group_on_the_outer_boundary(self):
        self.assertEqual(self.refused(square({}), [FaultRequest("left", (1.0, 0.0, 0.0))]),
                         "scene.toml: fault.left: the group left lies on the outer boundary at (0, 0.5) "
                         "(a fault is inside the body)")

    def test_a_missing_or_empty_group(self):
        self.assertEqual(self.refused(square({"empty": []}), [FaultRequest("empty", (0.0, 1.0, 0.0))]),
                         "scene.toml: fault.empty: the group empty has no facets")
        self.assertEqual(self.refused(square({}), [FaultRequest("main", (0.0, 1.0, 0.0))]),
                         "scene.toml: fault.main: the mesh has no group main (its facet groups: bottom, right, "
                         "top, left)")

    def test_a_branching_fault(self):
        mesh = square({"t": segment((1, 2), (2, 2), (3, 2)) + segment((2, 2), (2, 3))})
        self.assertEqual(self.refused(mesh, [FaultRequest("t", (1.0, 1.0, 0.0))]),
                         "scene.toml: fault.t: the fault branches or crosses itself at (2, 2) (3 pieces meet "
                         "there): give each branch a fault (a physical group) of its own")

    def test_a_hint_parallel_to_the_fault(self):
        mesh = square({"h": segment((1, 2), (2, 2), (3, 2))})
        self.assertEqual(self.refused(mesh, [FaultRequest("h", (1.0, 0.0, 0.0))]),
                         "scene.toml: fault.h.normal: the hint is parallel to the fault at (1.5, 2): give a normal "
                         "that crosses it")

    def test_a_hint_that_orients_a_turning_fault_both_ways(self):
        # An L: left of (2, 2) along y, then up along x. The hint (1, 1) puts
        # the + side above the first leg and right of the second: the + and -
        # sides swap at the corner. (1, -1) puts both on the outside.
        mesh = square({"l": segment((1, 2), (2, 2), (2, 3))})
        self.assertEqual(self.refused(mesh, [FaultRequest("l", (1.0, 1.0, 0.0))]),
                         "scene.toml: fault.l: the normal hint orients the fault inconsistently at (2, 2) (the "
                         "fault turns past the hint there: give a hint that crosses all of it the same way)")
        [fault] = split_along_faults(mesh, [FaultRequest("l", (1.0, -1.0, 0.0))], PREFIX)
        np.testing.assert_array_equal(fault.pairs, [[25, 12]])
        np.testing.assert_array_equal(fault.tips, [11, 17])


class Intersections(unittest.TestCase):
    """Faults that cross (X) or end on one another (T) in the square: the
    node where they meet, (2, 2) = 12, gets one node per piece around it,
    12 kept by the piece below the first fault's first facet, the others
    new (25, 26, 27) in the order of their first cells; each fault pairs,
    facet by facet, the nodes of its + and - pieces."""

    def test_crossing_faults(self):
        mesh = square({"h": segment((1, 2), (2, 2), (3, 2)), "v": segment((2, 1), (2, 2), (2, 3))})
        h, v = split_along_faults(mesh, [FaultRequest("h", (0.0, 1.0, 0.0)), FaultRequest("v", (1.0, 0.0, 0.0))],
                                  PREFIX)
        self.assertEqual(len(mesh.x), 28)
        np.testing.assert_array_equal(mesh.x[25:], [[2, 2]] * 3)
        # pieces SW (cells 10, 11: keeps 12), SE (13: 25), NW (18: 26), NE (20, 21: 27)
        self.assertEqual([cells_with(mesh, [n]) for n in (12, 25, 26, 27)], [[10, 11], [13], [18], [20, 21]])
        np.testing.assert_array_equal(h.pairs, [[26, 12], [27, 25]])
        np.testing.assert_array_equal(v.pairs, [[25, 12], [27, 26]])
        np.testing.assert_array_equal(h.tips, [node(1, 2), node(3, 2)])
        np.testing.assert_array_equal(v.tips, [node(2, 1), node(2, 3)])
        np.testing.assert_array_equal(h.meets, [[12, 1]])
        np.testing.assert_array_equal(v.meets, [[12, 0]])
        self.assertEqual(pieces(mesh), 1)  # the tips hold the pieces together

    def test_a_fault_ending_on_another(self):
        mesh = square({"h": segment((1, 2), (2, 2), (3, 2)), "s": segment((2, 2), (2, 3))})
        h, t = split_along_faults(mesh, [FaultRequest("h", (0.0, 1.0, 0.0)), FaultRequest("s", (1.0, 0.0, 0.0))],
                                  PREFIX)
        self.assertEqual(len(mesh.x), 27)
        # pieces below h (cells 10, 11, 13: keeps 12), NW (18: 25), NE (20, 21: 26)
        self.assertEqual([cells_with(mesh, [n]) for n in (12, 25, 26)], [[10, 11, 13], [18], [20, 21]])
        np.testing.assert_array_equal(h.pairs, [[25, 12], [26, 12]])
        np.testing.assert_array_equal(t.pairs, [[26, 25]])
        np.testing.assert_array_equal(t.tips, [node(2, 3)])
        np.testing.assert_array_equal(h.meets, [[12, 1]])
        np.testing.assert_array_equal(t.meets, [[12, 0]])

    def test_a_rim_crossing_another_fault(self):
        # In 3D a fault's rim may cross another fault: the wall x = 2 over
        # [1, 3]^2 in (y, z) crosses the plane z = 2 that cuts the box, and
        # its rim edges y = 1 and y = 3 cross the plane at (2, 1, 2) and
        # (2, 3, 2). There the wall's sides stay joined on each side of the
        # plane (two copies, the plane's); the wall's centre (2, 2, 2) gets
        # one copy per sector (4).
        mesh = box({"plane": patch(0, 4), "wall": wall(1, 3)})
        faults = split_along_faults(mesh, [FaultRequest("plane", (0.0, 0.0, 1.0)),
                                           FaultRequest("wall", (1.0, 0.0, 0.0))], PREFIX)
        self.assertEqual(len(mesh.x), 125 + 25 + 2)
        self.assertEqual(pieces(mesh), 2)
        self.assertAlmostEqual(volume(mesh), 64.0, delta=1e-12)
        self.assertEqual(len(faults[1].pairs), 2)  # (2, 2, 2) above and below the plane
        self.assertEqual(len(faults[1].tips), 8 + 2)  # the rim, and the plane's copies where it crosses
        self.assertEqual({tuple(mesh.x[v]) for v in faults[1].tips},
                         {(2, 1, 1), (2, 2, 1), (2, 3, 1), (2, 1, 2), (2, 3, 2), (2, 1, 3), (2, 2, 3), (2, 3, 3)})
        for fault in faults:
            check_split(self, mesh, fault)
            # each is cut along the other over y in [1, 3]: two edges, two cut links
            self.assertEqual(len(fault_cells(mesh, fault).cut.measures), 2)


class Network(unittest.TestCase):
    """The network of the faults' cells (domain/fault_cells.py,
    fault_network): where faults meet, the cells with an edge there are one
    junction's members, and a link of one fault there joins the junction."""

    def test_crossing_faults_meet_at_one_junction_of_four_cells(self):
        mesh = square({"h": segment((1, 2), (2, 2), (3, 2)), "v": segment((2, 1), (2, 2), (2, 3))})
        h, v = (fault_cells(mesh, f) for f in split_along_faults(
            mesh, [FaultRequest("h", (0.0, 1.0, 0.0)), FaultRequest("v", (1.0, 0.0, 0.0))], PREFIX))
        self.assertEqual(len(h.links.measures) + len(v.links.measures), 0)  # the crossing separates each fault's cells
        self.assertEqual(len(h.inner.measures), 4)  # two tips, two edges at the crossing
        for f in (h, v):  # ... and the two edges at the crossing are one cut link of its plane
            np.testing.assert_array_equal(f.cut.cells, [[0, 1]])
            np.testing.assert_array_equal(f.cut.points, [[2, 2, 0]])
        network = fault_network([h, v])
        self.assertEqual(len(network.junctions), 1)  # the tips meet nothing
        j = network.junctions[0]
        np.testing.assert_array_equal(j.point, [2, 2, 0])
        self.assertEqual((j.measure, j.faults, j.cells, j.distances), (1.0, [0, 0, 1, 1], [0, 1, 0, 1], [0.5] * 4))

    def test_a_link_at_a_junction_joins_it(self):
        # A T: s ends on h from above. With h's + side above, the stem
        # separates h's cells (two inner edges at (2, 2)); with it below they
        # keep their link there, which leaves h's links for the junction.
        for side in (1.0, -1.0):
            mesh = square({"h": segment((1, 2), (2, 2), (3, 2)), "s": segment((2, 2), (2, 3))})
            h, s = (fault_cells(mesh, f) for f in split_along_faults(
                mesh, [FaultRequest("h", (0.0, side, 0.0)), FaultRequest("s", (1.0, 0.0, 0.0))], PREFIX))
            self.assertEqual(len(h.links.measures), 0 if side > 0 else 1)
            # the separated link, cut; the stem's end is a tip
            self.assertEqual((len(h.cut.measures), len(s.cut.measures)), (1 if side > 0 else 0, 0))
            network = fault_network([h, s])
            self.assertEqual(len(network.links[0].measures) + len(network.links[1].measures), 0)
            self.assertEqual(len(network.junctions), 1)
            self.assertEqual((network.junctions[0].faults, network.junctions[0].cells), ([0, 0, 1], [0, 1, 0]))
            # h alone (s no conduit) keeps its link, or its two cells meet at
            # a junction of two where s separates them: one conduit through s
            alone = fault_network([h])
            np.testing.assert_array_equal(alone.links[0].cells, h.links.cells)
            self.assertEqual(len(alone.junctions), 1 if side > 0 else 0)


# The rectangle [0, 4] x [0, 2] with a segment embedded: inside, from (1, 0.8)
# to (3, 1.3); across, from (0, 0.8) to (4, 1.3), whose ends are points of
# the outline (so that the outline's mesh has them).
INSIDE = """
h = 0.25;
Point(1) = {0, 0, 0, h}; Point(2) = {4, 0, 0, h}; Point(3) = {4, 2, 0, h}; Point(4) = {0, 2, 0, h};
Point(5) = {1, 0.8, 0, h}; Point(6) = {3, 1.3, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1}; Line(5) = {5, 6};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve{5} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("right") = {2}; Physical Curve("top") = {3};
Physical Curve("left") = {4}; Physical Curve("fault") = {5}; Physical Surface("rock") = {1};
"""
ACROSS = """
h = 0.25;
Point(1) = {0, 0, 0, h}; Point(2) = {4, 0, 0, h}; Point(3) = {4, 2, 0, h}; Point(4) = {0, 2, 0, h};
Point(5) = {0, 0.8, 0, h}; Point(6) = {4, 1.3, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 6}; Line(3) = {6, 3}; Line(4) = {3, 4}; Line(6) = {4, 5}; Line(7) = {5, 1};
Line(5) = {5, 6};
Curve Loop(1) = {1, 2, 3, 4, 6, 7}; Plane Surface(1) = {1};
Curve{5} In Surface{1};
Physical Curve("bottom") = {1}; Physical Curve("right") = {2, 3}; Physical Curve("top") = {4};
Physical Curve("left") = {6, 7}; Physical Curve("fault") = {5}; Physical Surface("rock") = {1};
"""


def gmsh_mesh(geo):
    """The mesh gmsh makes of `geo`, as the reader reads it (the nodes of
    the cells only, in their order)."""
    import gmsh
    with tempfile.TemporaryDirectory() as directory:
        file = os.path.join(directory, "fault.geo")
        with open(file, "w") as f:
            f.write(geo)
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        try:
            gmsh.open(file)
            gmsh.model.mesh.generate(2)
            tags, coords, _ = gmsh.model.mesh.getNodes(-1, -1, False, False)
            index = {int(t): i for i, t in enumerate(tags)}
            _, node_tags = gmsh.model.mesh.getElementsByType(2)
            cells = [index[int(t)] for t in node_tags]
            groups = {}
            for dim, tag in gmsh.model.getPhysicalGroups(1):
                nodes = groups.setdefault(gmsh.model.getPhysicalName(dim, tag), [])
                for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                    nodes += [index[int(t)] for t in gmsh.model.mesh.getElementsByType(1, entity)[1]]
        finally:
            gmsh.finalize()
    used = np.unique(cells)
    renumber = np.full(len(tags), -1)
    renumber[used] = np.arange(len(used))
    x = np.asarray(coords).reshape(-1, 3)[used, :2]
    return input_mesh(2, x, renumber[np.reshape(cells, (-1, 3))],
                      {name: renumber[nodes].reshape(-1, 2).tolist() for name, nodes in groups.items()})


class GmshMeshes(unittest.TestCase):
    def split(self, geo):
        mesh = gmsh_mesh(geo)
        area = volume(mesh)
        cells, nodes = len(mesh.cells), len(mesh.x)
        [fault] = split_along_faults(mesh, [FaultRequest("fault", (-0.2, 1.0, 0.0))], PREFIX)
        self.assertEqual(len(mesh.cells), cells)
        self.assertAlmostEqual(volume(mesh), area, delta=1e-12 * area)
        self.assertAlmostEqual(area, 8.0, delta=1e-12)
        self.assertEqual(len(mesh.x), nodes + len(fault.pairs))
        check_split(self, mesh, fault)
        return mesh, fault

    def test_interior_curve(self):
        mesh, fault = self.split(INSIDE)
        self.assertEqual(sorted(map(tuple, mesh.x[fault.tips].tolist())), [(1.0, 0.8), (3.0, 1.3)])
        self.assertEqual(len(fault.pairs), len(fault.normals) - 1)
        self.assertEqual(pieces(mesh), 1)

    def test_curve_across(self):
        mesh, fault = self.split(ACROSS)
        self.assertEqual(len(fault.tips), 0)
        self.assertEqual(len(fault.pairs), len(fault.normals) + 1)
        self.assertEqual(pieces(mesh), 2)


class Cells(unittest.TestCase):
    def test_cells_of_the_fault_across(self):
        mesh = square({"fault": segment((0, 2), (1, 2), (2, 2), (3, 2), (4, 2))})
        [fault] = split_along_faults(mesh, [FaultRequest("fault", (0.0, -2.0, 0.0))], PREFIX)
        cells = fault_cells(mesh, fault)
        np.testing.assert_array_equal(cells.keys, [[25, 26], [26, 27], [27, 28], [28, 29]])
        # Each key's twin is the input node it was doubled from, on the -
        # face; the normal points into the + side, along the hint.
        np.testing.assert_array_equal(cells.twins, [[10, 11], [11, 12], [12, 13], [13, 14]])
        np.testing.assert_array_equal(cells.normals, [[0.0, -1.0, 0.0]] * 4)
        np.testing.assert_array_equal(cells.measures, [1.0] * 4)
        np.testing.assert_array_equal(cells.centroids, [[i + 0.5, 2.0, 0.0] for i in range(4)])
        np.testing.assert_array_equal(cells.links.cells, [[0, 1], [1, 2], [2, 3]])
        np.testing.assert_array_equal(cells.links.measures, [1.0] * 3)
        np.testing.assert_array_equal(cells.links.distances, [[0.5, 0.5]] * 3)
        np.testing.assert_array_equal(cells.ends.cells, [[0], [3]])
        self.assertEqual(cells.end_groups, ["left", "right"])
        np.testing.assert_array_equal(cells.ends.distances, [[0.5], [0.5]])
        np.testing.assert_array_equal(cells.ends.points, [[0.0, 2.0, 0.0], [4.0, 2.0, 0.0]])

        def well(x, y):
            return well_cells(cells, WellSpec([x, y], None))
        for (x, y), hit, shares in (((2.0, 2.0), [1, 2], [0.5, 0.5]), ((2.5, 2.0), [2], [1.0]), ((2.0, 3.0), [], [])):
            found, share = well(x, y)
            np.testing.assert_array_equal(found, hit)
            np.testing.assert_array_equal(share, shares)

    def test_transmissibility(self):
        edges = FaultEdges(np.array([[0, 1]]), np.array([2.0]), np.array([[0.5, 1.5]]), np.zeros((1, 3)))
        # |e| / (d_0/t_0 + d_1/t_1) = 2 / (0.5/1 + 1.5/3)
        np.testing.assert_array_equal(transmissibilities(np.array([1.0, 3.0]), edges), [2.0])

    def test_transmissibility_slopes(self):
        # dT/dw of a link (width 2) and of an end (width 1) against central
        # differences of transmissibilities, with the cubic law's t = w^3.
        links = FaultEdges(np.array([[0, 1]]), np.array([2.0]), np.array([[0.5, 1.5]]), np.zeros((1, 3)))
        ends = FaultEdges(np.array([[1]]), np.array([0.7]), np.array([[0.25]]), np.zeros((1, 3)))
        w = np.array([1.3, 0.6])
        for edges in (links, ends):
            dT = transmissibility_slopes(w ** 3, 3 * w ** 2, edges)
            for i, k in enumerate(edges.cells[0]):
                up, down = w.copy(), w.copy()
                up[k] += 1e-6
                down[k] -= 1e-6
                fd = (transmissibilities(up ** 3, edges)[0] - transmissibilities(down ** 3, edges)[0]) / 2e-6
                self.assertAlmostEqual(dT[0, i], fd, delta=1e-7 * abs(fd))

    def test_junction_star_derivative(self):
        # dN_a/dh_c of three members against central differences of N_a =
        # -h_a (p_a - p_j); the fluxes into the junction sum to zero for every
        # h, so each column sums to zero.
        h, p = np.array([2.0, 0.5, 1.25]), np.array([3.0, -1.0, 0.5])

        def N(g):
            return -g * (p - g @ p / g.sum())
        dN = star_flux_derivative(h, p)
        for c in range(3):
            up, down = h.copy(), h.copy()
            up[c] += 1e-6
            down[c] -= 1e-6
            np.testing.assert_allclose(dN[:, c], (N(up) - N(down)) / 2e-6, rtol=0, atol=1e-8)
            self.assertAlmostEqual(dN[:, c].sum(), 0.0, delta=1e-14)

    def test_history_value(self):
        # y = t^2 at t = 0, 1, 3: the step dt = 2 after dt = 1 (w = 2) has
        # c = (5/3, 3, 4/3), dt/c0 = 1.2, and c0 (y - y*)/dt = y'(3) = 6
        # exactly (BDF2 is exact for quadratics); backward Euler's y* is y_n.
        bdf2 = FineStep(3.0, 1.2, 1, 1, (5.0 / 3, 3.0, 4.0 / 3))
        self.assertAlmostEqual((9.0 - history_value(bdf2, [1.0], [0.0])[0]) / bdf2.dt, 6.0, delta=1e-14)
        np.testing.assert_array_equal(history_value(FineStep(3.0, 2.0), [1.0], [0.0]), [1.0])

    def test_open_patches(self):
        # A chain of 6 cells, 0-1-2-3-4-5, and a 7th linked to 0: open 0, 1,
        # 3, 4, 6 make the patches {0, 1, 6} and {3, 4}; 2 and 5 are closed.
        links = FaultEdges(np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [6, 0]]), np.ones(6),
                           np.ones((6, 2)), np.zeros((6, 3)))
        is_open = np.array([1, 1, 0, 1, 1, 0, 1], dtype=bool)
        np.testing.assert_array_equal(open_patches([links], is_open), [0, 0, -1, 1, 1, -1, 0])
        np.testing.assert_array_equal(open_patches([links], np.zeros(7, dtype=bool)), [-1] * 7)
        # A link cut at another fault, 1-4, joins the two patches.
        cut = FaultEdges(np.array([[1, 4]]), np.ones(1), np.ones((1, 2)), np.zeros((1, 3)))
        np.testing.assert_array_equal(open_patches([links, cut], is_open), [0, 0, -1, 0, 0, -1, 0])

    def test_patch_compliance(self):
        # Sneddon's mean openings per unit pressure: pi a/E' (2D, length
        # 2a), 16 a/(3 pi E') (a penny of area pi a^2).
        self.assertAlmostEqual(patch_compliance(2.0, 1.0e10, 2) * 1e10, np.pi, places=14)
        self.assertAlmostEqual(patch_compliance(np.pi * 4.0, 1.0e10, 3) * 1e10, 32 / (3 * np.pi), places=14)

    def test_barton_bandis_closure(self):
        # V_m = 1e-4 m, K_ni = 1e10 Pa/m: K_ni V_m = 1e6 Pa.
        closure = ClosureSpec(V_m=1.0e-4, K_ni=1.0e10)
        self.assertEqual(closure_aperture(closure, 0.0), 1.0e-4)  # unstressed: the largest closure is all there
        self.assertEqual(closure_aperture(closure, -5.0e5), 1.0e-4)  # tension counts as 0
        self.assertAlmostEqual(closure_aperture(closure, 1.0e6) / 5.0e-5, 1.0, places=14)  # s_n = K_ni V_m halves it
        self.assertAlmostEqual(closure_aperture(closure, 1.0e12) / (1.0e-4 * 1.0e6 / (1.0e6 + 1.0e12)), 1.0,
                               places=14)
        # K_ni is the initial stiffness: the compliance at s_n = 0 is 1/K_ni;
        # and everywhere minus the derivative of the aperture (central
        # differences).
        self.assertAlmostEqual(closure_compliance(closure, 0.0) * 1e10, 1.0, places=14)
        for s in (1.0e5, 1.0e6, 3.0e7):
            h = 1e-4 * s
            slope = (closure_aperture(closure, s - h) - closure_aperture(closure, s + h)) / (2 * h)
            self.assertAlmostEqual(closure_compliance(closure, s) / slope, 1.0, places=7, msg=f"s_n = {s}")


if __name__ == "__main__":
    unittest.main()
