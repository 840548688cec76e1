"""fault.xdmf (+ fault.h5): the faults' fields on their + faces at every
output time, for ParaView and meshio (cpp/output/fault_series.h). One grid
per time on the faces' mesh (segments in 2D, triangles in 3D; the nodes of
the + faces, a tip being one node of both faces): with mechanics the node
data opening, slip, slip_increment, traction, tangential_traction, state
and cohesion; the cell data fault (its index) and pressure, and with a conduit fault hydraulic_aperture,
exchange and flux (FaultSeries says what each holds). Rank 0 writes it with
h5py, from the pairs each rank gathers to it (a fault holds few nodes of the
mesh): the same XML text and datasets as the C++. Each write is complete on
disk when it returns, as solution.xdmf's; a restart keeps the times up to
its checkpoint's."""
import math
import os
import re

import h5py
import numpy as np

from ..contact.contact_law import PairStatus
from ..scene.input import FaultFlow
from ..domain.domain import vertex_input_indices
from .write_failure import OutputError, agree_on_output_error, write_dataset, write_failure_reason


def _gather_to_root(values, comm):
    """All ranks' rows of `values` on rank 0, in rank order (None elsewhere;
    collective)."""
    parts = comm.gather(values, root=0)
    return np.concatenate(parts) if comm.rank == 0 else None


def _listed_times(xdmf):
    """The times of an earlier run's fault.xdmf, in order; OutputError naming
    the file where it is missing or a time is no number (a damaged file)."""
    try:
        with open(xdmf) as f:
            values = re.findall(r'<Time Value="([^"]*)"', f.read())
    except OSError as e:
        raise OutputError(f"cannot resume {xdmf}: {e.strerror}") from None
    times = []
    for value in values:
        try:
            times.append(float(value))
        except ValueError:
            times.append(math.nan)
        if not math.isfinite(times[-1]):
            raise OutputError(f'cannot resume {xdmf}: its time "{value}" is no number')
    return times


def _write_rows(h5, name, values, width):
    """Writes `values` (rows x width) as the dataset `name`, replacing it."""
    write_dataset(h5, name, np.reshape(values, (-1, width)))


class FaultSeries:
    """fault.xdmf and fault.h5 of a run with faults (rank 0 holds the files).
    Node data:
    - opening: [u].n + g0 (0 at the tips, where the faces meet);
    - slip: the tangential jump [u] - ([u].n) n, a vector (three components);
    - traction: the contact traction, >= 0, zero where the fault is open;
    - slip_increment: its change since the start of the step (the one a
      friction law decides on), a vector;
    - tangential_traction: the tangential contact traction, a vector (three
      components; along the slip increment where the pair slips; on a
      frictionless fault the solve's error: round-off with a factorisation);
    - state: the pair's state (contact_law.py): 0 open, 1 stick, 2 slip; 1 at
      the tips, where the faces are one node and neither open nor slide;
    - cohesion: the cohesion the pair's law holds, the fault's until its
      bond breaks (contact_law.py), 0 then and at the tips;
    - fault (cell data): the index of the cell's fault among the scene's
      faults in the alphabetical order of their names (as summary.json lists
      them), 0, 1, ...: one field for a network, to colour or threshold by;
    - pressure (cell data): the fluid pressure in the fault, p_f of a conduit
      fault, fault.NAME.pressure at the cell's centroid, 0 for a fault loaded
      by the pore pressure beside it, which solution.xdmf holds.
    With a conduit fault, cell data also (0 on other faults):
    - hydraulic_aperture: w_h, the aperture of the cubic law;
    - exchange: the rock's volume rate per area into the fault;
    - flux: the mean flux along the fault (volume rate per length, a vector).
    A scene without mechanics has only the cell data."""

    def __init__(self, comm, directory, problem, resume_time=None):
        """Creates directory/fault.xdmf and .h5 with the faces' mesh; or, after
        a restart at `resume_time`, goes on in them (collective)."""
        self._comm, self._scene = comm, problem.scene
        self._xdmf = os.path.join(directory, "fault.xdmf")
        self._h5_path = os.path.join(directory, "fault.h5")
        self._dim = problem.domain.dim
        self._fault_names = sorted(self._scene.faults)  # as the C++'s std::map orders them
        # Rank 0: the faces' nodes (_node_key, ascending), their
        # coordinates and fault, the facets (d node positions each) and the
        # times written.
        self._nodes = self._x = self._fault = self._facets = None
        self._times, self._h5 = [], None
        self._gather_surface(problem)
        self._written_by_rank0(lambda: self._begin() if resume_time is None else self._go_on(resume_time))

    def _begin(self):
        """Rank 0: the new files with the faces' mesh."""
        self._h5 = h5py.File(self._h5_path, "w")
        _write_rows(self._h5, "/Mesh/geometry", self._x, 3)
        _write_rows(self._h5, "/Mesh/topology", self._facets, self._dim)
        self._write_fault_ids()
        self._h5.flush()
        self._write_xml()

    def _go_on(self, resume_time):
        """Rank 0, after a restart at `resume_time`: on in the files with
        the times up to it."""
        self._times = [t for t in _listed_times(self._xdmf) if t <= resume_time]
        self._h5 = h5py.File(self._h5_path, "a")
        if "/Mesh/fault" not in self._h5:  # a run that an older version began
            self._write_fault_ids()
        self._write_xml()

    def _written_by_rank0(self, write):
        """Rank 0's writes `write` of the files; a failure (a full disk)
        stops every rank with OutputError naming the file (collective)."""
        failure = ""
        if self._comm.rank == 0:
            try:
                write()
            except OutputError as e:  # fault.xdmf
                failure = str(e)
            except (OSError, RuntimeError) as e:  # HDF5's
                failure = f"cannot write {self._h5_path}: {write_failure_reason(os.path.dirname(self._h5_path), e)}"
        agree_on_output_error(failure, self._comm)

    def _write_fault_ids(self):
        """/Mesh/fault: each cell's fault (rank 0)."""
        _write_rows(self._h5, "/Mesh/fault", np.asarray(self._facet_fault, dtype=np.float64), 1)

    def close(self):
        """Closes fault.h5 (every write is on disk already)."""
        if self._h5 is not None:
            self._h5.close()
            self._h5 = None

    def _gather_surface(self, problem):
        """The + faces' owned facets of every rank on rank 0: their nodes by
        input index (numbered in ascending order there), coordinates and fault."""
        mesh, d = problem.domain.mesh, self._dim
        mesh.topology.create_connectivity(d - 1, 0)
        f_to_v = mesh.topology.connectivity(d - 1, 0)
        owned = mesh.topology.index_map(d - 1).size_local
        input_index = vertex_input_indices(mesh)
        # Vertex k of a cell is its geometry node k on a P1 mesh.
        coordinates = np.empty((len(input_index), 3))
        coordinates[mesh.topology.connectivity(d, 0).array] = mesh.geometry.x[mesh.geometry.dofmap.array]
        facets, x = [np.zeros((0, d + 1), dtype=np.int64)], [np.zeros((0, 3))]  # fault, then d input indices
        for f, name in enumerate(self._fault_names):
            plus = problem.domain.faults[name].plus_facets
            vertices = f_to_v.array.reshape(-1, d)[plus[plus < owned]]  # a simplex's facet has d vertices
            facets.append(np.column_stack([np.full(len(vertices), f), input_index[vertices]]))
            x.append(coordinates[vertices.reshape(-1)])
        all_facets = _gather_to_root(np.concatenate(facets), self._comm)
        all_x = _gather_to_root(np.concatenate(x), self._comm)
        if self._comm.rank != 0:
            return
        # A node of two faults' faces (where they meet) is a node of each.
        keys = self._node_key(all_facets[:, 1:], all_facets[:, :1])
        self._nodes = np.unique(keys)
        self._facets = np.searchsorted(self._nodes, keys).astype(np.int64)
        self._x = np.empty((len(self._nodes), 3))
        self._fault = np.empty(len(self._nodes), dtype=np.int64)
        self._x[self._facets.reshape(-1)] = all_x
        self._fault[self._facets] = all_facets[:, :1]
        self._facet_fault = all_facets[:, 0]
        self._conduit_row = self._conduit_rows(problem, all_facets[:, 1:])

    def _node_key(self, node, fault):
        """The key of a faces' node in _nodes: its input index and its
        fault's position in _fault_names (where faults meet, a node is on
        several)."""
        return node * len(self._fault_names) + fault

    def _conduit_rows(self, problem, keys):
        """Per facet of the faces' mesh (its sorted input indices `keys`), its
        row in the conduit cells' fields (ConduitFaults.cell_values), -1 on
        other faults."""
        rows, offset = {}, 0
        for name, f in sorted(self._scene.faults.items()):  # the order of the C++ std::map
            if f.flow == FaultFlow.conduit:
                cells = problem.domain.faults[name].cells
                rows.update({tuple(key): offset + k for k, key in enumerate(cells.keys.tolist())})
                offset += len(cells.measures)
        self._conduits = offset > 0
        return np.array([rows.get(tuple(sorted(key)), -1) for key in keys.tolist()], dtype=np.int64)

    def _cell_fields(self, cells, t):
        """The cell data at time t: pressure, and with conduits their fields."""
        pressure = np.zeros(len(self._facets))
        centroids = self._x[self._facets].mean(axis=1)
        for f, name in enumerate(self._fault_names):
            given, on = self._scene.faults[name].pressure, self._facet_fault == f
            if given is not None:
                pressure[on] = given(centroids[on, 0], centroids[on, 1], centroids[on, 2], t)
        fields = [("pressure", pressure, 1)]
        if not self._conduits:
            return fields
        values = np.zeros((len(self._facets), 6))
        conduit = self._conduit_row >= 0
        values[conduit] = cells[self._conduit_row[conduit]]
        pressure[conduit] = values[conduit, 0]
        return fields + [("hydraulic_aperture", values[:, 1], 1), ("exchange", values[:, 2], 1),
                         ("flux", values[:, 3:], 3)]

    def write(self, contact, cells, t):
        """Adds the state of the faults at time t (collective): the contact
        state `contact`, and the conduit faults' `cells`
        (ConduitFaults.cell_values, rank 0's; None without conduits)."""
        nodes = np.array([self._node_key(p.node, self._fault_names.index(contact.boundaries[p.fault][0]))
                          for p in contact.pairs], dtype=np.int64)
        # Per pair: opening, traction, state, slip (3), tangential traction
        # (3), slip increment (3), cohesion.
        values = np.array([[p.opening, p.traction, float(p.status), *p.slip, *p.tangential_traction,
                            *p.slip_increment, p.cohesion] for p in contact.pairs]).reshape(-1, 13)
        all_nodes = _gather_to_root(nodes, self._comm)
        all_values = _gather_to_root(values, self._comm)
        self._written_by_rank0(lambda: self._write_time(all_nodes, all_values, cells, t))

    def _write_time(self, all_nodes, all_values, cells, t):
        """Rank 0: the fields of time t from every rank's pairs
        (`all_nodes`, `all_values`) and the conduits' `cells`."""
        n = len(self._nodes)
        opening, traction, cohesion = np.zeros(n), np.zeros(n), np.zeros(n)
        slip, tangential, increment = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
        state = np.full(n, float(PairStatus.stick))  # a node without a pair is a tip: the faces are one node there
        p = np.searchsorted(self._nodes, all_nodes)
        opening[p], traction[p], state[p] = all_values[:, 0], all_values[:, 1], all_values[:, 2]
        slip[p], tangential[p], increment[p] = all_values[:, 3:6], all_values[:, 6:9], all_values[:, 9:12]
        cohesion[p] = all_values[:, 12]
        index = len(self._times)
        node_fields = [("opening", opening, 1), ("traction", traction, 1), ("slip", slip, 3),
                       ("slip_increment", increment, 3), ("tangential_traction", tangential, 3), ("state", state, 1),
                       ("cohesion", cohesion, 1)]
        for name, data, width in (node_fields if self._scene.mechanics else []) + self._cell_fields(cells, t):
            _write_rows(self._h5, f"/{name}/{index}", data, width)
        self._times.append(t)
        self._write_xml()

    def _attributes(self):
        """The fields of each time: (name, "Node" or "Cell")."""
        nodes = ["opening", "slip", "slip_increment", "traction", "tangential_traction", "state", "cohesion"]
        cells = ["pressure"] + (["hydraulic_aperture", "exchange", "flux"] if self._conduits else [])
        return ([("fault", "Cell")] + [(name, "Node") for name in (nodes if self._scene.mechanics else [])]
                + [(c, "Cell") for c in cells])

    def _write_xml(self):
        """The whole XML, every time written (rank 0; OutputError when it
        cannot)."""
        h5 = os.path.basename(self._h5_path)
        n, cells, d = len(self._nodes), len(self._facets), self._dim

        def item(dataset, shape, number_type):
            return (f'<DataItem Dimensions="{shape}" NumberType="{number_type}" Precision="8" Format="HDF">{h5}:'
                    f"{dataset}</DataItem>")
        xml = ('<?xml version="1.0"?>\n<Xdmf Version="3.0">\n <Domain>\n'
               '  <Grid Name="faults" GridType="Collection" CollectionType="Temporal">\n')
        for k, t in enumerate(self._times):
            # 17 significant digits, as C++'s stream at precision(17).
            xml += (f'   <Grid Name="faults" GridType="Uniform">\n    <Time Value="{t:.17g}"/>\n'
                    f'    <Topology TopologyType="{"Polyline" if d == 2 else "Triangle"}" NumberOfElements="{cells}" '
                    f'NodesPerElement="{d}">{item("/Mesh/topology", f"{cells} {d}", "Int")}</Topology>\n'
                    f'    <Geometry GeometryType="XYZ">{item("/Mesh/geometry", f"{n} 3", "Float")}</Geometry>\n')
            for name, center in self._attributes():
                vector = name in ("slip", "slip_increment", "tangential_traction", "flux")
                rows = n if center == "Node" else cells
                # the fault ids do not change: one dataset for every time
                dataset = "/Mesh/fault" if name == "fault" else f"/{name}/{k}"
                xml += (f'    <Attribute Name="{name}" AttributeType="{"Vector" if vector else "Scalar"}" '
                        f'Center="{center}">{item(dataset, f"{rows} 3" if vector else f"{rows} 1", "Float")}'
                        "</Attribute>\n")
            xml += "   </Grid>\n"
        xml += "  </Grid>\n </Domain>\n</Xdmf>\n"
        # written beside and renamed over the last one: a write that fails (a
        # full disk) leaves the last, whole
        following = self._xdmf + ".next"
        try:
            with open(following, "w") as f:
                f.write(xml)
            os.replace(following, self._xdmf)
        except OSError as e:
            if os.path.isfile(following):
                os.remove(following)
            raise OutputError(f"cannot write {self._xdmf}: {write_failure_reason(os.path.dirname(self._xdmf), e)}") from None
