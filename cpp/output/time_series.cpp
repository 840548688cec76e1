#include "output/time_series.h"

#include "output/write_failure.h"
#include "scene/scene.h"

#include <dolfinx/common/IndexMap.h>
#include <dolfinx/fem/DofMap.h>
#include <dolfinx/fem/FiniteElement.h>
#include <dolfinx/fem/FunctionSpace.h>
#include <dolfinx/io/HDF5Interface.h>
#include <dolfinx/io/cells.h>
#include <algorithm>
#include <cerrno>
#include <fcntl.h>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// Writes all of `text` at `offset`; false when the system refused.
bool write_at(int fd, const std::string& text, off_t offset)
{
  for (std::size_t done = 0; done < text.size();)
  {
    const ssize_t n = pwrite(fd, text.data() + done, text.size() - done, offset + static_cast<off_t>(done));
    if (n <= 0)
      return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

std::string full_precision(double v)
{
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}

std::string topology_type(mesh::CellType type)
{
  switch (type)
  {
  case mesh::CellType::triangle:
    return "Triangle";
  case mesh::CellType::quadrilateral:
    return "Quadrilateral";
  case mesh::CellType::tetrahedron:
    return "Tetrahedron";
  case mesh::CellType::hexahedron:
    return "Hexahedron";
  default:
    throw std::runtime_error("XDMF output: unsupported cell type");
  }
}

std::string data_item(const std::string& dimensions, const std::string& type, const std::string& h5,
                      const std::string& dataset)
{
  return "<DataItem Dimensions=\"" + dimensions + "\" NumberType=\"" + type + "\" Precision=\"8\" Format=\"HDF\">"
         + h5 + ":" + dataset + "</DataItem>";
}

const std::string tail = "    </Grid>\n  </Domain>\n</Xdmf>\n";

template <typename T>
MPI_Datatype mpi_type();
template <>
MPI_Datatype mpi_type<double>() { return MPI_DOUBLE; }
template <>
MPI_Datatype mpi_type<std::int64_t>() { return MPI_INT64_T; }
} // namespace

InputOrder::InputOrder(MPI_Comm comm, std::span<const std::int64_t> rows, std::int64_t total) : _comm(comm)
{
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  std::vector<std::int64_t> start(size + 1);
  for (int r = 0; r <= size; ++r)
    start[r] = total * r / size;
  _range = {start[rank], start[rank + 1]};
  std::vector<int> destination(rows.size());
  _send_counts.assign(size, 0);
  for (std::size_t i = 0; i < rows.size(); ++i)
  {
    if (rows[i] < 0 or rows[i] >= total)
      throw std::runtime_error("XDMF output: the mesh's input numbering is not 0 .. " + std::to_string(total - 1));
    destination[i] = static_cast<int>(std::upper_bound(start.begin(), start.end(), rows[i]) - start.begin()) - 1;
    ++_send_counts[destination[i]];
  }
  _order.resize(rows.size());
  std::iota(_order.begin(), _order.end(), 0);
  std::stable_sort(_order.begin(), _order.end(), [&](auto a, auto b) { return destination[a] < destination[b]; });
  _recv_counts.resize(size);
  MPI_Alltoall(_send_counts.data(), 1, MPI_INT, _recv_counts.data(), 1, MPI_INT, comm);
  _send_offsets.assign(size, 0);
  _recv_offsets.assign(size, 0);
  for (int r = 1; r < size; ++r)
  {
    _send_offsets[r] = _send_offsets[r - 1] + _send_counts[r - 1];
    _recv_offsets[r] = _recv_offsets[r - 1] + _recv_counts[r - 1];
  }
  std::vector<std::int64_t> sorted(rows.size());
  for (std::size_t i = 0; i < _order.size(); ++i)
    sorted[i] = rows[_order[i]];
  _received_rows = exchange(std::span<const std::int64_t>(sorted), 1);
  if (static_cast<std::int64_t>(_received_rows.size()) != _range[1] - _range[0])
    throw std::runtime_error("XDMF output: the mesh's input numbering has gaps or repeats");
}

template <typename T>
std::vector<T> InputOrder::exchange(std::span<const T> packed, int width) const
{
  const std::size_t size = _send_counts.size();
  std::vector<int> sc(size), so(size), rc(size), ro(size);
  for (std::size_t r = 0; r < size; ++r)
    sc[r] = _send_counts[r] * width, so[r] = _send_offsets[r] * width, rc[r] = _recv_counts[r] * width,
    ro[r] = _recv_offsets[r] * width;
  std::vector<T> received(static_cast<std::size_t>(ro.back() + rc.back()));
  MPI_Alltoallv(packed.data(), sc.data(), so.data(), mpi_type<T>(), received.data(), rc.data(), ro.data(),
                mpi_type<T>(), _comm);
  return received;
}

template <typename T>
std::vector<T> InputOrder::send(std::span<const T> values, int width) const
{
  std::vector<T> packed(_order.size() * width);
  for (std::size_t i = 0; i < _order.size(); ++i)
    std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(_order[i]) * width, width, packed.begin() + i * width);
  const std::vector<T> received = exchange(std::span<const T>(packed), width);
  std::vector<T> block(received.size());
  for (std::size_t i = 0; i < _received_rows.size(); ++i)
    std::copy_n(received.begin() + i * width, width, block.begin() + (_received_rows[i] - _range[0]) * width);
  return block;
}

TimeSeries::TimeSeries(MPI_Comm comm, const std::string& xdmf_path, const mesh::Mesh& mesh,
                       const std::string* resume)
    : _comm(comm), _xdmf_path(xdmf_path)
{
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  _parallel = size > 1;
  _rank0 = rank == 0;
  std::filesystem::path h5 = std::filesystem::path(xdmf_path).replace_extension(".h5");
  _h5_path = h5.string();
  _h5_name = h5.filename().string();
  hdf5_stage([&] { _h5 = io::HDF5Interface::open_file(comm, h5, resume ? "a" : "w", _parallel); });
  describe_mesh(mesh, !resume);
  const std::string head = "<?xml version=\"1.0\"?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
                           "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
                           "  <Domain>\n"
                           "    <Grid Name=\"solution\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  _grids_end = static_cast<long>(head.size());
  if (resume)
  {
    std::istringstream in(*resume);
    int any = 0;
    in >> _grid_start >> _grids_end >> _time >> any;
    _any_time = any;
    for (Field f; in >> f.name >> f.center >> f.components >> f.writes >> f.dataset;)
      _fields.push_back(f);
  }
  std::string failed;
  if (_rank0)
  {
    _xml = open(xdmf_path.c_str(), O_RDWR | O_CREAT | (resume ? 0 : O_TRUNC), 0644);
    // Fresh: the empty collection; resumed: the grids up to the state,
    // closed again (what came after it is dropped).
    const std::string text = resume ? tail : head + tail;
    if (_xml < 0 or !write_at(_xml, text, resume ? _grids_end : 0)
        or ftruncate(_xml, _grids_end + static_cast<off_t>(tail.size())) != 0)
      failed = cannot_write(xdmf_path);
  }
  // Every rank throws or none: a constructor that throws runs no destructor,
  // so rank 0 alone throwing left the others closing the HDF5 file
  // collectively for ever. They close it together here.
  if (failed = agreed_error(failed, comm); !failed.empty())
  {
    if (_xml >= 0)
      close(_xml);
    H5Fclose(_h5);
    throw OutputError(failed);
  }
}

std::string TimeSeries::position() const
{
  std::ostringstream s;
  s << std::setprecision(17) << _grid_start << ' ' << _grids_end << ' ' << _time << ' ' << _any_time << '\n';
  for (const Field& f : _fields)
    s << f.name << ' ' << f.center << ' ' << f.components << ' ' << f.writes << ' ' << f.dataset << '\n';
  return s.str();
}

TimeSeries::~TimeSeries()
{
  if (_xml >= 0)
    close(_xml);
  // Every write was flushed. After a failed one the ranks' views of the
  // file differ and a collective close could wait forever: the file is
  // left as the last flush made it (HDF5 does not close it at exit either:
  // silence_hdf5_errors).
  if (_h5 >= 0 and !_failed)
    H5Fclose(_h5);
}

void TimeSeries::describe_mesh(const mesh::Mesh& mesh, bool write)
{
  // Geometry: the owned nodes, gdim coordinates each, in input order.
  const int gdim = mesh.geometry().dim();
  const auto& node_map = mesh.geometry().index_map();
  const std::int32_t owned_nodes = node_map->size_local();
  const std::vector<std::int64_t>& input = mesh.geometry().input_global_indices();
  _num_nodes = node_map->size_global();
  _nodes = InputOrder(_comm, std::span(input.data(), owned_nodes), _num_nodes);
  std::vector<double> x(owned_nodes * gdim);
  std::span<const double> coordinates = mesh.geometry().x();
  for (std::int32_t i = 0; i < owned_nodes; ++i)
    for (int j = 0; j < gdim; ++j)
      x[i * gdim + j] = coordinates[3 * i + j];
  if (write)
  {
    const std::vector<double> rows = _nodes.send<double>(x, gdim);
    hdf5_stage([&] { io::HDF5Interface::write_dataset(_h5, "/Mesh/geometry", rows.data(), _nodes.range(),
                                                      {_num_nodes, gdim}, _parallel, false); });
  }

  // Topology: the owned cells in input order, their nodes by input index in
  // the order of VTK (which XDMF readers follow).
  const int tdim = mesh.topology().dim();
  const auto& cell_map = mesh.topology().index_map(tdim);
  const std::int32_t owned_cells = cell_map->size_local();
  _num_cells = cell_map->size_global();
  _cells = InputOrder(_comm, std::span(mesh.topology().original_cell_index.data(), owned_cells), _num_cells);
  const auto& dofmap = mesh.geometry().dofmap();
  const int nodes_per_cell = dofmap.num_links(0);
  const std::vector<std::uint8_t> vtk
      = io::cells::transpose(io::cells::perm_vtk(mesh.topology().cell_type(), nodes_per_cell));
  std::vector<std::int64_t> topology(owned_cells * nodes_per_cell);
  for (std::int32_t c = 0; c < owned_cells; ++c)
  {
    auto nodes = dofmap.links(c);
    for (int k = 0; k < nodes_per_cell; ++k)
      topology[c * nodes_per_cell + k] = input[nodes[vtk[k]]];
  }
  if (write)
  {
    const std::vector<std::int64_t> rows = _cells.send<std::int64_t>(topology, nodes_per_cell);
    hdf5_stage([&] { io::HDF5Interface::write_dataset(_h5, "/Mesh/topology", rows.data(), _cells.range(),
                                                      {_num_cells, nodes_per_cell}, _parallel, false); });
    hdf5_stage([&] { io::HDF5Interface::flush_file(_h5); });
  }

  const std::string n = std::to_string(_num_nodes), e = std::to_string(_num_cells);
  _mesh_xml = "        <Topology TopologyType=\"" + topology_type(mesh.topology().cell_type())
              + "\" NumberOfElements=\"" + e + "\" NodesPerElement=\"" + std::to_string(nodes_per_cell) + "\">\n"
              + "          " + data_item(e + " " + std::to_string(nodes_per_cell), "Int", _h5_name, "/Mesh/topology")
              + "\n        </Topology>\n"
              + "        <Geometry GeometryType=\"" + (gdim == 3 ? "XYZ" : "XY") + "\">\n"
              + "          " + data_item(n + " " + std::to_string(gdim), "Float", _h5_name, "/Mesh/geometry")
              + "\n        </Geometry>\n";
}

void TimeSeries::write(const fem::Function<double>& f, double t)
{
  const auto& V = *f.function_space();
  const auto& mesh = *V.mesh();
  const auto& dofmap = *V.dofmap();
  const int bs = dofmap.bs();
  const int tdim = mesh.topology().dim();
  const int per_cell = V.element()->space_dimension() / bs;
  const int components = bs == 1 ? 1 : 3;
  std::span<const double> values = f.x()->array();

  // Values at the owned nodes (P1) or owned cells (constant per cell).
  std::string center;
  std::vector<double> data;
  const InputOrder* order = nullptr;
  std::int64_t rows = 0;
  if (per_cell == 1)
  {
    center = "Cell";
    order = &_cells;
    rows = _num_cells;
    const std::int32_t owned = mesh.topology().index_map(tdim)->size_local();
    data.assign(owned * components, 0.0);
    for (std::int32_t c = 0; c < owned; ++c)
      for (int j = 0; j < bs; ++j)
        data[c * components + j] = values[dofmap.cell_dofs(c)[0] * bs + j];
  }
  else if (per_cell == mesh.geometry().dofmap().num_links(0))
  {
    // P1 on a P1 mesh: local DOF k of a cell sits at the cell's node k.
    center = "Node";
    order = &_nodes;
    rows = _num_nodes;
    const std::int32_t owned = mesh.geometry().index_map()->size_local();
    data.assign(owned * components, 0.0);
    const auto& nodes = mesh.geometry().dofmap();
    for (std::int32_t c = 0; c < nodes.num_nodes(); ++c)
    {
      auto cell_nodes = nodes.links(c);
      auto dofs = dofmap.cell_dofs(c);
      for (std::size_t k = 0; k < cell_nodes.size(); ++k)
        if (cell_nodes[k] < owned)
          for (int j = 0; j < bs; ++j)
            data[cell_nodes[k] * components + j] = values[dofs[k] * bs + j];
    }
  }
  else
    throw std::runtime_error("XDMF output: " + f.name + " is neither P1 nor constant per cell");

  auto field = std::find_if(_fields.begin(), _fields.end(), [&](const Field& x) { return x.name == f.name; });
  if (field == _fields.end())
    field = _fields.insert(_fields.end(), Field{f.name, center, components, 0, ""});
  field->dataset = "/Function/" + f.name + "/" + std::to_string(field->writes++);
  const std::vector<double> rows_in_order = order->send<double>(data, components);
  // A time whose fields could not all be written is not listed: the XML
  // ends before it again.
  const bool listed = _rank0 and _any_time and t == _time;
  hdf5_stage(
      [&]
      {
        // A resumed run writes again what its first run wrote after the
        // checkpoint: that dataset goes first.
        if (H5Lexists(_h5, "/Function", H5P_DEFAULT) > 0
            and H5Lexists(_h5, ("/Function/" + f.name).c_str(), H5P_DEFAULT) > 0
            and H5Lexists(_h5, field->dataset.c_str(), H5P_DEFAULT) > 0)
          H5Ldelete(_h5, field->dataset.c_str(), H5P_DEFAULT);
        io::HDF5Interface::write_dataset(_h5, field->dataset, rows_in_order.data(), order->range(),
                                         {rows, components}, _parallel, false);
      },
      listed);
  hdf5_stage([&] { io::HDF5Interface::flush_file(_h5); }, listed);

  const bool new_time = !_any_time or t != _time;
  _time = t;
  _any_time = true;
  if (_rank0)
    write_xml(t, new_time);
}

std::string TimeSeries::grid(double t) const
{
  std::string g = "      <Grid Name=\"mesh\" GridType=\"Uniform\">\n" + _mesh_xml + "        <Time Value=\""
                  + full_precision(t) + "\"/>\n";
  for (const Field& f : _fields)
  {
    const std::string rows = std::to_string(f.center == "Node" ? _num_nodes : _num_cells);
    g += "        <Attribute Name=\"" + f.name + "\" AttributeType=\"" + (f.components == 1 ? "Scalar" : "Vector")
         + "\" Center=\"" + f.center + "\">\n          "
         + data_item(rows + " " + std::to_string(f.components), "Float", _h5_name, f.dataset)
         + "\n        </Attribute>\n";
  }
  return g + "      </Grid>\n";
}

void TimeSeries::write_xml(double t, bool new_time)
{
  // A new time appends its grid; another field of the same time rewrites
  // that grid. The closing tags follow at once, so the file stays whole.
  if (new_time)
    _grid_start = _grids_end;
  const std::string g = grid(t);
  errno = 0;
  if (!write_at(_xml, g + tail, _grid_start))
  {
    end_before_current_time();
    throw OutputError(cannot_write(_xdmf_path));
  }
  _grids_end = _grid_start + static_cast<long>(g.size());
  if (ftruncate(_xml, _grids_end + static_cast<off_t>(tail.size())) != 0)
    throw OutputError(cannot_write(_xdmf_path));
}

void TimeSeries::hdf5_stage(const std::function<void()>& write, bool drop_current_time)
{
  std::string failure;
  errno = 0;
  try
  {
    write();
  }
  catch (const std::runtime_error&)
  {
    failure = cannot_write(_h5_path);
  }
  // Every rank learns of a failure before the next collective HDF5 call.
  failure = agreed_error(failure, _comm);
  if (failure.empty())
    return;
  if (drop_current_time)
    end_before_current_time();
  _failed = true;
  throw OutputError(failure);
}

void TimeSeries::end_before_current_time()
{
  // In bytes the file already had, so that this works on a full disk; the
  // errno of the failure that led here is kept.
  const int reason = errno;
  if (write_at(_xml, tail, _grid_start) and ftruncate(_xml, _grid_start + static_cast<off_t>(tail.size())) == 0)
    errno = reason;
}

std::string TimeSeries::cannot_write(const std::string& path) const
{
  return "cannot write " + path + ": "
         + write_failure_reason(std::filesystem::path(_xdmf_path).parent_path().string());
}

} // namespace biotcontact
