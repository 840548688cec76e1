// The XDMF time series of a run, laid out for ParaView and meshio: one
// temporal collection whose every output time is one grid on the one mesh
// (geometry and topology written once to the HDF5 file), carrying every
// field as an attribute in 64-bit precision:
// - P1 fields (displacement, contact pressure, contact flag) as node data,
//   the values at the mesh vertices exactly as in the solution vector;
// - cell-wise constant fields (pressure, flux, sigma_v) as cell data;
// - vectors padded to three components (what ParaView's warp filter takes).
// A field not written at a time (the mechanics at a fine multirate time)
// repeats its last written state: the attribute points at the same HDF5
// dataset, so every grid has every array. Each write is complete on disk
// when it returns (TimeSeries::write).
#pragma once

#include <dolfinx/fem/Function.h>
#include <dolfinx/mesh/Mesh.h>
#include <hdf5.h>
#include <array>
#include <functional>
#include <mpi.h>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The rows of a dataset in the mesh's input numbering, whatever
/// the partition: the rows this rank owns (each named by its input index)
/// go to the rank that writes them, rank r the contiguous block
/// [r N / size, (r + 1) N / size). So the files of a run are the same on
/// any partition and number of ranks, and a restart on another partition
/// goes on in them (collective).
class InputOrder
{
public:
  InputOrder(MPI_Comm comm, std::span<const std::int64_t> rows, std::int64_t total);
  InputOrder() = default;
  /// The rows this rank writes.
  std::array<std::int64_t, 2> range() const { return _range; }
  /// `width` values per owned row (in the order of `rows`) -> this rank's
  /// block of rows (collective).
  template <typename T>
  std::vector<T> send(std::span<const T> values, int width) const;

private:
  template <typename T>
  std::vector<T> exchange(std::span<const T> packed, int width) const;

  MPI_Comm _comm = MPI_COMM_NULL;
  std::array<std::int64_t, 2> _range{};
  std::vector<std::int32_t> _order; // owned rows by destination rank
  std::vector<int> _send_counts, _send_offsets, _recv_counts, _recv_offsets;
  std::vector<std::int64_t> _received_rows;
};

class TimeSeries
{
public:
  /// Creates `xdmf_path` and the .h5 next to it and writes the mesh; or,
  /// given the position() of an earlier run, goes on in its files from there,
  /// dropping what was written after that state (collective).
  TimeSeries(MPI_Comm comm, const std::string& xdmf_path, const dolfinx::mesh::Mesh& mesh,
             const std::string* resume = nullptr);
  ~TimeSeries();
  TimeSeries(const TimeSeries&) = delete;
  TimeSeries& operator=(const TimeSeries&) = delete;

  /// Adds the values of f (P1 or cell-wise constant) at time t (collective).
  /// Complete on disk when it returns: the dataset is written and the HDF5
  /// file flushed, then the XML is rewritten from the start of the current
  /// time's grid on, so that at any moment solution.xdmf lists exactly the
  /// data that solution.h5 holds.
  void write(const dolfinx::fem::Function<double>& f, double t);

  /// Where the series stands, for a checkpoint (this rank's view).
  std::string position() const;

private:
  /// A field of the series and the dataset of its last written state.
  struct Field
  {
    std::string name, center; // center "Node" or "Cell"
    int components = 1;       // 1 or 3
    int writes = 0;
    std::string dataset;
  };
  /// Ranges, sizes and the XML of the mesh; writes its datasets if `write`.
  void describe_mesh(const dolfinx::mesh::Mesh& mesh, bool write);
  /// The XML of the grid at time t with the last state of every field.
  std::string grid(double t) const;
  /// Rewrites the XML from the current grid on (rank 0).
  void write_xml(double t, bool new_time);
  /// Runs one collective HDF5 call; throws OutputError on every rank when
  /// it failed on any (after end_before_current_time if asked).
  void hdf5_stage(const std::function<void()>& write, bool drop_current_time = false);
  /// Closes the XML after the times before the current one (rank 0): a
  /// time whose fields could not all be written is not listed.
  void end_before_current_time();
  /// "cannot write PATH: " and the system's reason.
  std::string cannot_write(const std::string& path) const;

  MPI_Comm _comm;
  bool _parallel = false, _rank0 = false;
  std::string _xdmf_path, _h5_path, _h5_name;
  hid_t _h5 = -1;
  bool _failed = false; // a collective HDF5 call failed
  int _xml = -1; // rank 0's descriptor of the XML file
  std::vector<Field> _fields;
  std::string _mesh_xml; // topology and geometry of every grid
  long _grid_start = -1, _grids_end = -1; // positions in the XML file
  double _time = 0;
  bool _any_time = false;
  std::int64_t _num_nodes = 0, _num_cells = 0;
  InputOrder _nodes, _cells;
};

} // namespace biotcontact
