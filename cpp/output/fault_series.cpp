#include "output/fault_series.h"

#include "domain/domain.h"

#include <algorithm>
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

/// The times of an earlier run's fault.xdmf, in order.
std::vector<double> listed_times(const std::string& xdmf)
{
  std::ifstream in(xdmf);
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str(), tag = "<Time Value=\"";
  std::vector<double> times;
  for (std::size_t at = s.find(tag); at != std::string::npos; at = s.find(tag, at + 1))
    times.push_back(std::stod(s.substr(at + tag.size())));
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
  if (_rank != 0)
    return;
  if (resume_time)
  {
    for (double t : listed_times(_xdmf))
      if (t <= *resume_time)
        _times.push_back(t);
    _h5 = io::HDF5Interface::open_file(MPI_COMM_SELF, _h5_path, "a", false);
    write_xml();
    return;
  }
  _h5 = io::HDF5Interface::open_file(MPI_COMM_SELF, _h5_path, "w", false);
  write_rows(_h5, "/Mesh/geometry", _x, 3);
  const auto rows = static_cast<std::int64_t>(_facets.size() / _dim);
  io::HDF5Interface::write_dataset(_h5, "/Mesh/topology", _facets.data(), {0, rows}, {rows, _dim}, false, false);
  io::HDF5Interface::flush_file(_h5);
  write_xml();
}

FaultSeries::~FaultSeries()
{
  if (_h5 >= 0)
    H5Fclose(_h5);
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
  std::map<std::int64_t, std::size_t> position;
  for (std::size_t k = 0; k < all_facets.size(); k += d + 1)
    for (int i = 0; i < d; ++i)
      position.emplace(all_facets[k + 1 + i], 0);
  std::size_t next = 0;
  for (auto& [node, p] : position)
  {
    p = next++;
    _nodes.push_back(node);
  }
  _x.resize(3 * _nodes.size());
  _fault.resize(_nodes.size());
  for (std::size_t k = 0, j = 0; k < all_facets.size(); k += d + 1, ++j)
    for (int i = 0; i < d; ++i)
    {
      const std::size_t p = position[all_facets[k + 1 + i]];
      _facets.push_back(static_cast<std::int64_t>(p));
      _fault[p] = static_cast<int>(all_facets[k]);
      std::copy_n(&all_x[3 * (d * j + i)], 3, &_x[3 * p]);
    }
}

void FaultSeries::write(const ContactState& contact, double t)
{
  // Per pair: opening, traction, state, slip (3), tangential traction (3),
  // slip increment (3).
  constexpr int width = 12;
  std::vector<std::int64_t> nodes;
  std::vector<double> values;
  for (const PairState& p : contact.pairs)
  {
    nodes.push_back(p.node);
    values.insert(values.end(), {p.opening, p.traction, static_cast<double>(p.status)});
    values.insert(values.end(), p.slip.begin(), p.slip.end());
    values.insert(values.end(), p.tangential_traction.begin(), p.tangential_traction.end());
    values.insert(values.end(), p.slip_increment.begin(), p.slip_increment.end());
  }
  const std::vector<std::int64_t> all_nodes = gather_to_root(nodes, MPI_INT64_T, _comm);
  const std::vector<double> all_values = gather_to_root(values, MPI_DOUBLE, _comm);
  if (_rank != 0)
    return;
  const std::size_t n = _nodes.size();
  std::vector<double> opening(n, 0.0), traction(n, 0.0), slip(3 * n, 0.0), tangential(3 * n, 0.0), pressure(n, 0.0);
  std::vector<double> increment(3 * n, 0.0);
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
  }
  for (std::size_t p = 0; p < n; ++p)
    if (const auto& given = _scene.faults.at(_fault_names[_fault[p]]).pressure)
      pressure[p] = (*given)(&_x[3 * p], t);
  const std::string index = std::to_string(_times.size());
  write_rows(_h5, "/opening/" + index, opening, 1);
  write_rows(_h5, "/traction/" + index, traction, 1);
  write_rows(_h5, "/slip/" + index, slip, 3);
  write_rows(_h5, "/slip_increment/" + index, increment, 3);
  write_rows(_h5, "/tangential_traction/" + index, tangential, 3);
  write_rows(_h5, "/state/" + index, state, 1);
  write_rows(_h5, "/pressure/" + index, pressure, 1);
  io::HDF5Interface::flush_file(_h5);
  _times.push_back(t);
  write_xml();
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
    for (const std::string name :
         {"opening", "slip", "slip_increment", "traction", "tangential_traction", "state", "pressure"})
    {
      const bool vector = name == "slip" or name == "slip_increment" or name == "tangential_traction";
      xml << "    <Attribute Name=\"" << name << "\" AttributeType=\"" << (vector ? "Vector" : "Scalar")
          << "\" Center=\"Node\">"
          << item("/" + name + "/" + std::to_string(k), std::to_string(n) + (vector ? " 3" : " 1"), "Float")
          << "</Attribute>\n";
    }
    xml << "   </Grid>\n";
  }
  xml << "  </Grid>\n </Domain>\n</Xdmf>\n";
  std::ofstream out(_xdmf, std::ios::trunc);
  out << xml.str();
}

} // namespace biotcontact
