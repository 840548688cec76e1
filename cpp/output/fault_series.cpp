#include "output/fault_series.h"

#include "domain/domain.h"
#include "output/write_failure.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <dolfinx/io/HDF5Interface.h>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace biotcontact
{
using namespace dolfinx;

namespace
{
/// All ranks' `values` on rank 0, in rank order (collective).
template <typename T>
std::vector<T> gather_to_root(const std::vector<T>& values, MPI_Datatype type, MPI_Comm comm)
{
  int size = 0, rank = 0, count = static_cast<int>(values.size());
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  std::vector<int> counts(size), offsets(size + 1, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  for (int r = 0; r < size; ++r)
    offsets[r + 1] = offsets[r] + counts[r];
  std::vector<T> all(rank == 0 ? offsets[size] : 0);
  MPI_Gatherv(values.data(), count, type, all.data(), counts.data(), offsets.data(), type, 0, comm);
  return all;
}

/// The times of an earlier run's fault.xdmf, in order; OutputError naming
/// the file where it is missing or a time is no number (a damaged file).
std::vector<double> listed_times(const std::string& xdmf)
{
  std::ifstream in(xdmf);
  if (!in)
    throw OutputError("cannot resume " + xdmf + ": " + std::strerror(errno));
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str(), tag = "<Time Value=\"";
  std::vector<double> times;
  for (std::size_t at = s.find(tag); at != std::string::npos; at = s.find(tag, at + 1))
  {
    const std::string value = s.substr(at + tag.size(), s.find('"', at + tag.size()) - at - tag.size());
    char* end = nullptr;
    times.push_back(std::strtod(value.c_str(), &end));
    if (value.empty() or *end != '\0' or !std::isfinite(times.back()))
      throw OutputError("cannot resume " + xdmf + ": its time \"" + value + "\" is no number");
  }
  return times;
}

/// Writes `values` (rows x width) as the dataset `name`, replacing it.
void write_rows(hid_t h5, const std::string& name, const std::vector<double>& values, int width)
{
  if (H5Lexists(h5, name.c_str(), H5P_DEFAULT) > 0)
    H5Ldelete(h5, name.c_str(), H5P_DEFAULT);
  const auto rows = static_cast<std::int64_t>(values.size() / width);
  io::HDF5Interface::write_dataset(h5, name, values.data(), {0, rows}, {rows, width}, false, false);
}
} // namespace

FaultSeries::FaultSeries(MPI_Comm comm, const std::string& directory, const Problem& problem,
                         const double* resume_time)
    : _comm(comm), _xdmf(directory + "/fault.xdmf"), _h5_path(directory + "/fault.h5"), _scene(problem.scene),
      _dim(problem.domain.dim())
{
  MPI_Comm_rank(comm, &_rank);
  for (const auto& [name, fault] : _scene.faults)
    _fault_names.push_back(name);
  gather_surface(problem);
  written_by_rank0([&] { resume_time ? go_on(*resume_time) : begin(); });
}

void FaultSeries::begin()
{
  _h5 = io::HDF5Interface::open_file(MPI_COMM_SELF, _h5_path, "w", false);
  write_rows(_h5, "/Mesh/geometry", _x, 3);
  const auto rows = static_cast<std::int64_t>(_facets.size() / _dim);
  io::HDF5Interface::write_dataset(_h5, "/Mesh/topology", _facets.data(), {0, rows}, {rows, _dim}, false, false);
  write_fault_ids();
  io::HDF5Interface::flush_file(_h5);
  write_xml();
}

void FaultSeries::go_on(double resume_time)
{
  for (double t : listed_times(_xdmf))
    if (t <= resume_time)
      _times.push_back(t);
  _h5 = io::HDF5Interface::open_file(MPI_COMM_SELF, _h5_path, "a", false);
  if (!io::HDF5Interface::has_dataset(_h5, "/Mesh/fault")) // a run that an older version began
    write_fault_ids();
  write_xml();
}

void FaultSeries::written_by_rank0(const std::function<void()>& write)
{
  std::string failure;
  if (_rank == 0)
  {
    errno = 0;
    try
    {
      write();
    }
    catch (const OutputError& e) // fault.xdmf
    {
      failure = e.what();
    }
    catch (const std::runtime_error&) // HDF5's
    {
      failure = "cannot write " + _h5_path + ": "
                + write_failure_reason(std::filesystem::path(_h5_path).parent_path().string());
    }
  }
  agree_on_output_error(failure, _comm);
}

void FaultSeries::write_fault_ids() const
{
  write_rows(_h5, "/Mesh/fault", std::vector<double>(_facet_fault.begin(), _facet_fault.end()), 1);
}

FaultSeries::~FaultSeries()
{
  if (_h5 >= 0)
    H5Fclose(_h5);
}

std::int64_t FaultSeries::node_key(std::int64_t node, std::int64_t fault) const
{
  return node * static_cast<std::int64_t>(_fault_names.size()) + fault;
}

/// The + faces' owned facets of every rank on rank 0: their nodes by input
/// index (numbered in ascending order there), coordinates and fault.
void FaultSeries::gather_surface(const Problem& problem)
{
  const mesh::Mesh& mesh = *problem.domain.mesh;
  const int d = _dim;
  mesh.topology_mutable().create_connectivity(d - 1, 0);
  const auto f_to_v = mesh.topology().connectivity(d - 1, 0);
  const std::int32_t owned = mesh.topology().index_map(d - 1)->size_local();
  const std::vector<std::int64_t> input = vertex_input_indices(mesh);
  std::vector<double> coordinates(3 * input.size());
  const auto c_to_v = mesh.topology().connectivity(d, 0);
  for (std::int32_t c = 0; c < c_to_v->num_nodes(); ++c)
    for (std::size_t k = 0; k < c_to_v->links(c).size(); ++k)
      std::copy_n(&mesh.geometry().x()[3 * mesh.geometry().dofmap().links(c)[k]], 3,
                  &coordinates[3 * c_to_v->links(c)[k]]);
  std::vector<std::int64_t> facets; // fault, then d input indices
  std::vector<double> x;            // 3 d coordinates
  for (std::size_t f = 0; f < _fault_names.size(); ++f)
    for (std::int32_t facet : problem.domain.faults.at(_fault_names[f]).plus_facets)
      if (facet < owned)
      {
        facets.push_back(static_cast<std::int64_t>(f));
        for (std::int32_t v : f_to_v->links(facet))
        {
          facets.push_back(input[v]);
          x.insert(x.end(), &coordinates[3 * v], &coordinates[3 * v + 3]);
        }
      }
  const std::vector<std::int64_t> all_facets = gather_to_root(facets, MPI_INT64_T, _comm);
  const std::vector<double> all_x = gather_to_root(x, MPI_DOUBLE, _comm);
  // A node of two faults' faces (where they meet) is a node of each.
  std::map<std::int64_t, std::size_t> position;
  for (std::size_t k = 0; k < all_facets.size(); k += d + 1)
    for (int i = 0; i < d; ++i)
      position.emplace(node_key(all_facets[k + 1 + i], all_facets[k]), 0);
  std::size_t next = 0;
  for (auto& [node, p] : position)
  {
    p = next++;
    _nodes.push_back(node);
  }
  _x.resize(3 * _nodes.size());
  _fault.resize(_nodes.size());
  for (std::size_t k = 0, j = 0; k < all_facets.size(); k += d + 1, ++j)
  {
    _facet_fault.push_back(static_cast<int>(all_facets[k]));
    for (int i = 0; i < d; ++i)
    {
      const std::size_t p = position[node_key(all_facets[k + 1 + i], all_facets[k])];
      _facets.push_back(static_cast<std::int64_t>(p));
      _fault[p] = static_cast<int>(all_facets[k]);
      std::copy_n(&all_x[3 * (d * j + i)], 3, &_x[3 * p]);
    }
  }
  conduit_rows(problem, all_facets);
}

void FaultSeries::conduit_rows(const Problem& problem, const std::vector<std::int64_t>& all_facets)
{
  const int d = _dim;
  std::map<std::vector<std::int64_t>, std::int64_t> rows;
  std::int64_t offset = 0;
  for (const auto& [name, f] : _scene.faults)
    if (f.flow == FaultFlow::conduit)
    {
      const FaultCells& cells = problem.domain.faults.at(name).cells;
      for (std::size_t k = 0; k < cells.size(); ++k)
        rows[{cells.keys.begin() + d * k, cells.keys.begin() + d * (k + 1)}] = offset + static_cast<std::int64_t>(k);
      offset += static_cast<std::int64_t>(cells.size());
    }
  _conduits = offset > 0;
  for (std::size_t k = 0; k < all_facets.size(); k += d + 1)
  {
    std::vector<std::int64_t> key(all_facets.begin() + k + 1, all_facets.begin() + k + 1 + d);
    std::sort(key.begin(), key.end());
    _conduit_row.push_back(rows.count(key) ? rows.at(key) : -1);
  }
}

std::vector<FaultSeries::Field> FaultSeries::node_fields(const ContactState& contact) const
{
  // Per pair: opening, traction, state, slip (3), tangential traction (3),
  // slip increment (3), cohesion.
  constexpr int width = 13;
  std::vector<std::int64_t> nodes;
  std::vector<double> values;
  for (const PairState& p : contact.pairs)
  {
    const std::string& fault = std::get<0>(contact.boundaries[p.fault]);
    nodes.push_back(node_key(p.node, std::lower_bound(_fault_names.begin(), _fault_names.end(), fault)
                                         - _fault_names.begin()));
    values.insert(values.end(), {p.opening, p.traction, static_cast<double>(p.status)});
    values.insert(values.end(), p.slip.begin(), p.slip.end());
    values.insert(values.end(), p.tangential_traction.begin(), p.tangential_traction.end());
    values.insert(values.end(), p.slip_increment.begin(), p.slip_increment.end());
    values.push_back(p.cohesion);
  }
  const std::vector<std::int64_t> all_nodes = gather_to_root(nodes, MPI_INT64_T, _comm);
  const std::vector<double> all_values = gather_to_root(values, MPI_DOUBLE, _comm);
  if (_rank != 0)
    return {};
  const std::size_t n = _nodes.size();
  std::vector<double> opening(n, 0.0), traction(n, 0.0), slip(3 * n, 0.0), tangential(3 * n, 0.0);
  std::vector<double> increment(3 * n, 0.0), cohesion(n, 0.0);
  // A node without a pair is a tip: the faces are one node there.
  std::vector<double> state(n, static_cast<double>(PairStatus::stick));
  for (std::size_t k = 0; k < all_nodes.size(); ++k)
  {
    const std::size_t p = std::lower_bound(_nodes.begin(), _nodes.end(), all_nodes[k]) - _nodes.begin();
    const double* v = &all_values[width * k];
    opening[p] = v[0];
    traction[p] = v[1];
    state[p] = v[2];
    std::copy_n(v + 3, 3, &slip[3 * p]);
    std::copy_n(v + 6, 3, &tangential[3 * p]);
    std::copy_n(v + 9, 3, &increment[3 * p]);
    cohesion[p] = v[12];
  }
  return {{"opening", opening, 1},          {"traction", traction, 1},
          {"slip", slip, 3},                {"slip_increment", increment, 3},
          {"tangential_traction", tangential, 3}, {"state", state, 1},
          {"cohesion", cohesion, 1}};
}

std::vector<FaultSeries::Field> FaultSeries::cell_fields(std::span<const double> cells, double t) const
{
  const std::size_t n = _facet_fault.size();
  std::vector<double> pressure(n, 0.0);
  for (std::size_t c = 0; c < n; ++c)
    if (const auto& given = _scene.faults.at(_fault_names[_facet_fault[c]]).pressure)
    {
      std::array<double, 3> centroid{0, 0, 0};
      for (int i = 0; i < _dim; ++i)
        for (int j = 0; j < 3; ++j)
          centroid[j] += _x[3 * _facets[_dim * c + i] + j];
      for (double& x : centroid)
        x /= _dim;
      pressure[c] = (*given)(centroid.data(), t);
    }
  if (!_conduits)
    return {{"pressure", pressure, 1}};
  std::vector<double> aperture(n, 0.0), exchange(n, 0.0), flux(3 * n, 0.0);
  for (std::size_t c = 0; c < n; ++c)
    if (const std::int64_t r = _conduit_row[c]; r >= 0)
    {
      pressure[c] = cells[6 * r], aperture[c] = cells[6 * r + 1], exchange[c] = cells[6 * r + 2];
      std::copy_n(&cells[6 * r + 3], 3, &flux[3 * c]);
    }
  return {{"pressure", pressure, 1}, {"hydraulic_aperture", aperture, 1}, {"exchange", exchange, 1},
          {"flux", flux, 3}};
}

void FaultSeries::write(const ContactState& contact, std::span<const double> cells, double t)
{
  std::vector<Field> fields;
  if (_scene.mechanics)
    fields = node_fields(contact);
  written_by_rank0(
      [&]
      {
        for (Field& f : cell_fields(cells, t))
          fields.push_back(std::move(f));
        const std::string index = std::to_string(_times.size());
        for (const Field& f : fields)
          write_rows(_h5, "/" + f.name + "/" + index, f.values, f.width);
        io::HDF5Interface::flush_file(_h5);
        _times.push_back(t);
        write_xml();
      });
}

std::vector<std::pair<std::string, std::string>> FaultSeries::attributes() const
{
  std::vector<std::pair<std::string, std::string>> a;
  a.emplace_back("fault", "Cell");
  if (_scene.mechanics)
    for (const char* name :
         {"opening", "slip", "slip_increment", "traction", "tangential_traction", "state", "cohesion"})
      a.emplace_back(name, "Node");
  a.emplace_back("pressure", "Cell");
  if (_conduits)
    for (const char* name : {"hydraulic_aperture", "exchange", "flux"})
      a.emplace_back(name, "Cell");
  return a;
}

void FaultSeries::write_xml() const
{
  const std::string h5 = std::filesystem::path(_h5_path).filename().string();
  const std::size_t n = _nodes.size(), cells = _facets.size() / _dim;
  auto item = [&](const std::string& dataset, const std::string& shape, const char* type)
  {
    return "<DataItem Dimensions=\"" + shape + "\" NumberType=\"" + type + "\" Precision=\"8\" Format=\"HDF\">" + h5
           + ":" + dataset + "</DataItem>";
  };
  std::ostringstream xml;
  xml.precision(17);
  xml << "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
      << "  <Grid Name=\"faults\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t k = 0; k < _times.size(); ++k)
  {
    xml << "   <Grid Name=\"faults\" GridType=\"Uniform\">\n    <Time Value=\"" << _times[k] << "\"/>\n"
        << "    <Topology TopologyType=\"" << (_dim == 2 ? "Polyline" : "Triangle") << "\" NumberOfElements=\""
        << cells << "\" NodesPerElement=\"" << _dim << "\">"
        << item("/Mesh/topology", std::to_string(cells) + " " + std::to_string(_dim), "Int") << "</Topology>\n"
        << "    <Geometry GeometryType=\"XYZ\">" << item("/Mesh/geometry", std::to_string(n) + " 3", "Float")
        << "</Geometry>\n";
    for (const auto& [name, center] : attributes())
    {
      const bool vector = name == "slip" or name == "slip_increment" or name == "tangential_traction"
                          or name == "flux";
      const std::size_t rows = center == "Node" ? n : cells;
      // The fault ids do not change: one dataset for every time.
      const std::string dataset = name == "fault" ? "/Mesh/fault" : "/" + name + "/" + std::to_string(k);
      xml << "    <Attribute Name=\"" << name << "\" AttributeType=\"" << (vector ? "Vector" : "Scalar")
          << "\" Center=\"" << center << "\">"
          << item(dataset, std::to_string(rows) + (vector ? " 3" : " 1"), "Float")
          << "</Attribute>\n";
    }
    xml << "   </Grid>\n";
  }
  xml << "  </Grid>\n </Domain>\n</Xdmf>\n";
  // Written beside and renamed over the last one: a write that fails (a
  // full disk) leaves the last, whole.
  const std::string next = _xdmf + ".next";
  std::ofstream out(next, std::ios::trunc);
  out << xml.str();
  out.close();
  std::error_code renamed;
  if (out.fail() or (std::filesystem::rename(next, _xdmf, renamed), renamed))
  {
    std::filesystem::remove(next, renamed);
    throw OutputError("cannot write " + _xdmf + ": "
                      + write_failure_reason(std::filesystem::path(_xdmf).parent_path().string()));
  }
}

} // namespace biotcontact
