"""The XDMF time series of a run (cpp/output/time_series.h): one temporal collection
whose every output time is one grid on the one mesh (geometry and topology
written once), every field an attribute in 64-bit precision: P1 fields as
node data, cell-wise constant fields as cell data, vectors padded to three
components. A field not written at a time repeats its last written state
(the attribute points at the same dataset). Each write is on disk when it
returns: the HDF5 file is flushed, then the XML is rewritten from the start
of the current time's grid.

The prototype gathers every field to rank 0, which writes both files with
serial h5py; `read_time_series` reads either solver's output."""
import os
import xml.etree.ElementTree as ET

import h5py
import numpy as np

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
        mode = "a" if resume is not None else "w"
        self.h5 = h5py.File(os.path.splitext(xdmf_path)[0] + ".h5", mode) if comm.rank == 0 else None
        self.fields = {}  # name -> [center, components, writes, dataset]
        self.time, self.grid_start, self.grids_end = None, None, len(HEAD)
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
            self.xml = open(xdmf_path, "r+" if resume is not None else "w")
            self.xml.seek(self.grids_end if resume is not None else 0)
            self.xml.write(TAIL if resume is not None else HEAD + TAIL)
            self.xml.truncate()
            self.xml.flush()

    def position(self):
        """Where the series stands, for a checkpoint (this rank's view)."""
        lines = [f"{self.grid_start if self.grid_start is not None else -1} {self.grids_end} "
                 f"{self.time if self.time is not None else 0.0!r} {int(self.time is not None)}"]
        lines += [f"{n} {c} {k} {w} {d}" for n, (c, k, w, d) in self.fields.items()]
        return "\n".join(lines) + "\n"

    def _gather(self, local):
        """The owned rows of every rank, in rank order (= global order), on rank 0."""
        parts = self.comm.gather(local, root=0)
        return np.concatenate(parts) if self.comm.rank == 0 else None

    def _dataset(self, path, data):
        if self.comm.rank == 0:
            if path in self.h5:  # a resumed run writes again what its first run wrote after the checkpoint
                del self.h5[path]
            self.h5.create_dataset(path, data=data)
            self.h5.flush()

    def _write_mesh(self, mesh, write=True):
        gdim, tdim = mesh.geometry.dim, mesh.topology.dim
        node_map = mesh.geometry.index_map()
        owned_nodes = node_map.size_local
        self.num_nodes = node_map.size_global
        if write:
            self._dataset("/Mesh/geometry", self._gather(mesh.geometry.x[:owned_nodes, :gdim]))
        owned_cells = mesh.topology.index_map(tdim).size_local
        self.num_cells = mesh.topology.index_map(tdim).size_global
        nodes = mesh.geometry.dofmap.array.reshape(-1, mesh.geometry.dofmap.links(0).size)
        per_cell = nodes.shape[1]
        from dolfinx.cpp.io import perm_vtk  # here: the reader below needs no dolfinx
        vtk = np.argsort(perm_vtk(mesh.topology.cell_type, per_cell))  # the transpose of the permutation
        local = nodes[:owned_cells][:, vtk]
        topology = node_map.local_to_global(local.ravel()).reshape(local.shape).astype(np.int64)
        if write:
            self._dataset("/Mesh/topology", self._gather(topology))
        self.mesh_xml = (
            f'        <Topology TopologyType="{TOPOLOGY[mesh.topology.cell_type.name]}" '
            f'NumberOfElements="{self.num_cells}" NodesPerElement="{per_cell}">\n'
            f'          {_data_item(f"{self.num_cells} {per_cell}", "Int", self.h5_name, "/Mesh/topology")}\n'
            "        </Topology>\n"
            f'        <Geometry GeometryType="{"XYZ" if gdim == 3 else "XY"}">\n'
            f'          {_data_item(f"{self.num_nodes} {gdim}", "Float", self.h5_name, "/Mesh/geometry")}\n'
            "        </Geometry>\n")

    def write(self, f, t):
        """Adds the values of f (P1 or cell-wise constant) at time t (collective)."""
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
        self._dataset(field[3], self._gather(data))
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
        self.xml.seek(self.grid_start)
        self.xml.write(g + TAIL)
        self.xml.truncate()
        self.xml.flush()
        self.grids_end = self.grid_start + len(g)

    def close(self):
        if self.comm.rank == 0:
            self.xml.close()
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
