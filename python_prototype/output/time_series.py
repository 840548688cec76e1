"""The XDMF time series of a run (cpp/output/time_series.h): one temporal
collection whose every output time is one grid on the one mesh (geometry
and topology written once), every field an attribute in 64-bit precision:
P1 fields as node data, cell-wise constant fields as cell data, vectors
padded to three components. A field not written at a time repeats its last
written state (the attribute points at the same dataset). Each write is on
disk when it returns (TimeSeries.write).

Rows are in the mesh's input order (nodes by input index, cells by input
cell index), so the files do not depend on the partition. The prototype
gathers every field to rank 0, which writes both files with serial h5py;
`read_time_series` reads either solver's output."""
import os
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from .write_failure import OutputError, agree_on_output_error, write_dataset, write_failure_reason

TAIL = "    </Grid>\n  </Domain>\n</Xdmf>\n"
HEAD = ('<?xml version="1.0"?>\n<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>\n'
        '<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude">\n'
        '  <Domain>\n'
        '    <Grid Name="solution" GridType="Collection" CollectionType="Temporal">\n')
TOPOLOGY = {"triangle": "Triangle", "quadrilateral": "Quadrilateral", "tetrahedron": "Tetrahedron",
            "hexahedron": "Hexahedron"}


def _data_item(dimensions, number_type, h5, dataset):
    return (f'<DataItem Dimensions="{dimensions}" NumberType="{number_type}" Precision="8" Format="HDF">'
            f"{h5}:{dataset}</DataItem>")


class TimeSeries:
    def __init__(self, comm, xdmf_path, mesh, resume=None):
        """Creates the files and writes the mesh; or, given the position()
        of an earlier run, goes on in its files, dropping what came after it."""
        self.comm, self.xdmf_path = comm, xdmf_path
        self.h5_name = os.path.splitext(os.path.basename(xdmf_path))[0] + ".h5"
        self.h5 = None
        h5_path, failed = os.path.splitext(xdmf_path)[0] + ".h5", ""
        if comm.rank == 0:
            try:
                self.h5 = h5py.File(h5_path, "a" if resume is not None else "w")
            except OSError as e:
                failed = f"cannot write {h5_path}: {write_failure_reason(os.path.dirname(h5_path), e)}"
        agree_on_output_error(failed, comm)
        self.fields = {}  # name -> [center, components, writes, dataset]
        self.time, self.grid_start, self.grids_end = None, None, len(HEAD)
        self.failed = False  # a write failed: the HDF5 file is left as it is, not closed
        self._write_mesh(mesh, write=resume is None)
        if resume is not None:
            lines = resume.splitlines()
            start, end, t, any_time = lines[0].split()
            self.grid_start, self.grids_end = int(start), int(end)
            self.time = float(t) if int(any_time) else None
            for line in lines[1:]:
                name, center, components, writes, dataset = line.split()
                self.fields[name] = [center, int(components), int(writes), dataset]
        if comm.rank == 0:
            # Unbuffered: a write that fails leaves nothing behind to be retried.
            try:
                self.xml = os.open(xdmf_path, os.O_RDWR | os.O_CREAT | (os.O_TRUNC if resume is None else 0), 0o644)
                if resume is None:
                    self._write_from(0, HEAD + TAIL)
                else:
                    self._write_from(self.grids_end, TAIL)
            except OSError as e:
                raise OutputError(f"cannot write {xdmf_path}: {write_failure_reason(os.path.dirname(xdmf_path), e)}") \
                    from None

    def position(self):
        """Where the series stands, for a checkpoint (this rank's view)."""
        lines = [f"{self.grid_start if self.grid_start is not None else -1} {self.grids_end} "
                 f"{self.time if self.time is not None else 0.0!r} {int(self.time is not None)}"]
        lines += [f"{n} {c} {k} {w} {d}" for n, (c, k, w, d) in self.fields.items()]
        return "\n".join(lines) + "\n"

    def _gather(self, local, index):
        """The owned rows of every rank on rank 0, row index[i] = local[i]
        (the input order)."""
        parts = self.comm.gather((np.asarray(index), local), root=0)
        if self.comm.rank != 0:
            return None
        rows = np.concatenate([i for i, _ in parts])
        data = np.empty((len(rows),) + local.shape[1:], dtype=local.dtype)
        data[rows] = np.concatenate([v for _, v in parts])
        return data

    def _dataset(self, path, data, t=None):
        """Rank 0 writes a dataset and flushes the file; OutputError when it
        cannot (the time being written taken out of the XML)."""
        if self.comm.rank != 0:
            return
        try:
            write_dataset(self.h5, path, data)
        except (OSError, RuntimeError) as e:
            self.failed = True
            self._end_before(t)
            h5_path = os.path.join(os.path.dirname(self.xdmf_path), self.h5_name)
            raise OutputError(f"cannot write {h5_path}: {write_failure_reason(os.path.dirname(h5_path), e)}") \
                from None

    def _end_before(self, t):
        """The XML ends before the grid of time t, the time being written
        (if any of its fields is in it)."""
        if t is not None and self.time == t:
            try:
                self._write_from(self.grid_start, TAIL)
            except OSError:
                pass  # the XML then still names a dataset that may be incomplete; nothing more can be done
            self.grids_end = self.grid_start

    def _write_mesh(self, mesh, write=True):
        gdim, tdim = mesh.geometry.dim, mesh.topology.dim
        node_map = mesh.geometry.index_map()
        owned_nodes = node_map.size_local
        self.num_nodes = node_map.size_global
        input_index = np.asarray(mesh.geometry.input_global_indices, dtype=np.int64)
        self.node_rows = input_index[:owned_nodes]
        geometry = self._gather(mesh.geometry.x[:owned_nodes, :gdim], self.node_rows) if write else None
        owned_cells = mesh.topology.index_map(tdim).size_local
        self.cell_rows = np.asarray(mesh.topology.original_cell_index[:owned_cells], dtype=np.int64)
        self.num_cells = mesh.topology.index_map(tdim).size_global
        nodes = mesh.geometry.dofmap.array.reshape(-1, mesh.geometry.dofmap.links(0).size)
        per_cell = nodes.shape[1]
        from dolfinx.cpp.io import perm_vtk  # here: the reader below needs no dolfinx
        vtk = np.argsort(perm_vtk(mesh.topology.cell_type, per_cell))  # the transpose of the permutation
        local = nodes[:owned_cells][:, vtk]
        if write:  # after both gathers: a rank 0 that fails leaves no rank waiting in one
            topology = self._gather(input_index[local], self.cell_rows)
            self._dataset("/Mesh/geometry", geometry)
            self._dataset("/Mesh/topology", topology)
        self.mesh_xml = (
            f'        <Topology TopologyType="{TOPOLOGY[mesh.topology.cell_type.name]}" '
            f'NumberOfElements="{self.num_cells}" NodesPerElement="{per_cell}">\n'
            f'          {_data_item(f"{self.num_cells} {per_cell}", "Int", self.h5_name, "/Mesh/topology")}\n'
            "        </Topology>\n"
            f'        <Geometry GeometryType="{"XYZ" if gdim == 3 else "XY"}">\n'
            f'          {_data_item(f"{self.num_nodes} {gdim}", "Float", self.h5_name, "/Mesh/geometry")}\n'
            "        </Geometry>\n")

    def write(self, f, t):
        """Adds the values of f (P1 or cell-wise constant) at time t (collective).
        On disk when it returns: the HDF5 file is flushed, then the XML is
        rewritten from the start of the current time's grid. A write that
        fails (a full disk) raises OutputError and takes the incomplete time
        out of the XML again, which then lists exactly the completed times."""
        V = f.function_space
        mesh = V.mesh
        bs = V.dofmap.index_map_bs
        per_cell = V.element.space_dimension // bs
        components = 1 if bs == 1 else 3
        values = f.x.array.reshape(-1, bs)
        cell_dofs = V.dofmap.list.array.reshape(-1, per_cell)
        if per_cell == 1:
            center = "Cell"
            owned = mesh.topology.index_map(mesh.topology.dim).size_local
            data = np.zeros((owned, components))
            data[:, :bs] = values[cell_dofs[:owned, 0]]
        else:
            # P1 on a P1 mesh: local DOF k of a cell sits at the cell's node k.
            center = "Node"
            owned = mesh.geometry.index_map().size_local
            nodes = mesh.geometry.dofmap.array.reshape(-1, per_cell)
            data = np.zeros((owned, components))
            mine = nodes < owned
            data[nodes[mine], :bs] = values[cell_dofs[mine]]
        field = self.fields.setdefault(f.name, [center, components, 0, None])
        field[3] = f"/Function/{f.name}/{field[2]}"
        field[2] += 1
        self._dataset(field[3], self._gather(data, self.cell_rows if center == "Cell" else self.node_rows), t)
        new_time = self.time is None or t != self.time
        self.time = t
        if self.comm.rank == 0:
            self._write_xml(t, new_time)

    def _grid(self, t):
        g = f'      <Grid Name="mesh" GridType="Uniform">\n{self.mesh_xml}        <Time Value="{t:.17g}"/>\n'
        for name, (center, components, _, dataset) in self.fields.items():
            rows = self.num_nodes if center == "Node" else self.num_cells
            g += (f'        <Attribute Name="{name}" AttributeType="{"Scalar" if components == 1 else "Vector"}" '
                  f'Center="{center}">\n'
                  f'          {_data_item(f"{rows} {components}", "Float", self.h5_name, dataset)}\n'
                  "        </Attribute>\n")
        return g + "      </Grid>\n"

    def _write_xml(self, t, new_time):
        """A new time appends its grid; another field of the same time
        rewrites that grid; the closing tags follow at once."""
        if new_time:
            self.grid_start = self.grids_end
        g = self._grid(t)
        try:
            self._write_from(self.grid_start, g + TAIL)
        except OSError as e:
            self.failed = True
            self._end_before(t)
            raise OutputError(f"cannot write {self.xdmf_path}: "
                              f"{write_failure_reason(os.path.dirname(self.xdmf_path), e)}") from None
        self.grids_end = self.grid_start + len(g)

    def _write_from(self, offset, text):
        """The XML from `offset` on replaced by `text`, on disk on return."""
        data = text.encode()
        if os.pwrite(self.xml, data, offset) != len(data):
            raise OSError(0, "")
        os.ftruncate(self.xml, offset + len(data))

    def close(self):
        """Closes the files; after a failed write the HDF5 file is left as
        the last flush made it (closing writes metadata that may not fit)."""
        if self.comm.rank == 0:
            os.close(self.xml)
            if not self.failed:
                self.h5.close()


def read_time_series(directory, repeated=False):
    """The time series of a run in `directory`: (nodes, cells, series) with
    series[name][time] = (center, values), values of shape (rows,
    components); cells are the node indices of each cell. Reads
    solution.xdmf and the HDF5 datasets it points at. A field's state
    repeated at a time where it was not written (the mechanics at a fine
    multirate time) is left out unless `repeated`."""
    tree = ET.parse(os.path.join(directory, "solution.xdmf"))
    series, last = {}, {}
    with h5py.File(os.path.join(directory, "solution.h5"), "r") as h5:
        nodes, cells = h5["Mesh/geometry"][:], h5["Mesh/topology"][:]
        for grid in tree.iter("Grid"):
            time = grid.find("Time")
            if time is None:
                continue
            for attribute in grid.findall("Attribute"):
                name, path = attribute.get("Name"), attribute.find("DataItem").text.split(":")[1]
                if path == last.get(name) and not repeated:
                    continue
                last[name] = path
                series.setdefault(name, {})[float(time.get("Value"))] = (attribute.get("Center"), h5[path][:])
    return nodes, cells, series


class Fields:
    """A run's time series for comparisons: fields[name][time] -> values,
    with node and cell-centre coordinates, so that runs partitioned or
    numbered differently compare (tests/support.py, compare.py)."""

    def __init__(self, directory):
        self.nodes, self.topology, self.series = read_time_series(directory)
        self.cells = self.nodes[self.topology].mean(axis=1)

    def times(self, name):
        return sorted(self.series[name])

    def at(self, name, t):
        return self.series[name][t][1]

    def sorted(self, name, t):
        """Values and coordinates ordered by the coordinates (partition independent)."""
        center, values = self.series[name][t]
        x = self.nodes if center == "Node" else self.cells
        order = np.lexsort(np.round(x, 10).T[::-1])
        return values[order], x[order]

    def sorted_values(self, name, t):
        return self.sorted(name, t)[0]

    def along(self, name, t, a, b, n=400):
        """A cell field at n points of the segment from a to b, s = (k +
        1/2)/n of the way (the ends excluded): (s, values), each value the
        mean of the cells holding the point (several on a face or edge)."""
        values = np.asarray(self.at(name, t)).reshape(len(self.topology), -1)[:, 0]
        d = self.topology.shape[1] - 1
        v = self.nodes[self.topology][:, :, :d]
        inverse = np.linalg.inv(np.stack([v[:, i + 1] - v[:, 0] for i in range(d)], axis=2))
        s = (np.arange(n) + 0.5) / n
        found = []
        for x in np.asarray(a) + s[:, None] * (np.asarray(b) - np.asarray(a)):
            lam = np.einsum("cij,cj->ci", inverse, x - v[:, 0])
            inside = (lam >= -1e-12).all(axis=1) & (lam.sum(axis=1) <= 1 + 1e-12)
            found.append(values[inside].mean())
        return s, np.array(found)
