// fault.xdmf (+ fault.h5): the faults' fields on their + faces at every
// output time, for ParaView and meshio. One grid per time on the faces'
// mesh (segments in 2D, triangles in 3D; the nodes of the + faces, a tip
// being one node of both faces): with mechanics the node data opening,
// slip, slip_increment, traction, tangential_traction, state and cohesion;
// the cell data fault (its index) and pressure, and with a conduit fault
// hydraulic_aperture, exchange and flux (FaultSeries says what each
// holds). Rank 0 writes it, from the pairs each rank gathers to it (a fault
// holds few nodes of the mesh). Each write is complete on disk when it
// returns, as solution.xdmf's; a restart keeps the times up to its
// checkpoint's.
#pragma once

#include "assembly/problem.h"
#include "contact/contact_state.h"

#include <functional>
#include <hdf5.h>
#include <mpi.h>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace biotcontact
{

/// @brief fault.xdmf and fault.h5 of a run with faults. Node data:
/// - opening: [u].n + g0 (0 at the tips, where the faces meet);
/// - slip: the tangential jump [u] - ([u].n) n, a vector (three components);
/// - slip_increment: its change since the start of the step (the one a
///   friction law decides on), a vector;
/// - traction: the contact traction, >= 0, zero where the fault is open;
/// - tangential_traction: the tangential contact traction, a vector (three
///   components; along the slip increment where the pair slips; on a
///   frictionless fault the solve's error: round-off with a factorisation);
/// - state: the pair's state (contact_law.h): 0 open, 1 stick, 2 slip; 1 at
///   the tips, where the faces are one node and neither open nor slide;
/// - cohesion: the cohesion the pair's law holds, the fault's until its
///   bond breaks (contact_law.h), 0 then and at the tips;
/// - fault (cell data): the index of the cell's fault among the scene's
///   faults in the alphabetical order of their names (as summary.json lists
///   them), 0, 1, ...: one field for a network, to colour or threshold by;
/// - pressure (cell data): the fluid pressure in the fault, p_f of a conduit
///   fault, fault.NAME.pressure at the cell's centroid, 0 for a fault loaded
///   by the pore pressure beside it, which solution.xdmf holds.
/// With a conduit fault, cell data also (0 on other faults):
/// - hydraulic_aperture: w_h, the aperture of the cubic law;
/// - exchange: the rock's volume rate per area into the fault;
/// - flux: the mean flux along the fault (volume rate per length, a vector).
/// A scene without mechanics has only the cell data.
class FaultSeries
{
public:
  /// Creates directory/fault.xdmf and .h5 with the faces' mesh; or, after
  /// a restart at `resume_time`, goes on in them (collective).
  FaultSeries(MPI_Comm comm, const std::string& directory, const Problem& problem, const double* resume_time);
  ~FaultSeries();
  FaultSeries(const FaultSeries&) = delete;
  FaultSeries& operator=(const FaultSeries&) = delete;

  /// Adds the state of the faults at time t (collective): the contact
  /// state `contact`, and the conduit faults' `cells`
  /// (ConduitFaults::cell_values, rank 0's; empty without conduits).
  void write(const ContactState& contact, std::span<const double> cells, double t);

private:
  /// One field of a time: its name, values and width.
  struct Field
  {
    std::string name;
    std::vector<double> values;
    int width;
  };
  void gather_surface(const Problem& problem);
  /// Rank 0: the new files with the faces' mesh; or, after a restart at
  /// `resume_time`, on in them with the times up to it.
  void begin();
  void go_on(double resume_time);
  /// Rank 0's writes `write` of the files; a failure (a full disk) stops
  /// every rank with OutputError naming the file (collective).
  void written_by_rank0(const std::function<void()>& write);
  /// Per facet of the faces' mesh (`all_facets`: fault, then d input
  /// indices each), its row in the conduit cells' fields, -1 on other faults.
  void conduit_rows(const Problem& problem, const std::vector<std::int64_t>& all_facets);
  /// /Mesh/fault: each cell's fault (rank 0).
  void write_fault_ids() const;
  /// The node data at time t (with mechanics).
  std::vector<Field> node_fields(const ContactState& contact) const;
  /// The cell data at time t: pressure, and with conduits their fields.
  std::vector<Field> cell_fields(std::span<const double> cells, double t) const;
  /// The fields of each time: (name, "Node" or "Cell").
  std::vector<std::pair<std::string, std::string>> attributes() const;
  /// fault.xdmf anew, listing _times (throws OutputError when it cannot).
  void write_xml() const;
  /// The key of a faces' node in _nodes: its input index and its fault's
  /// position in _fault_names (where faults meet, a node is on several).
  std::int64_t node_key(std::int64_t node, std::int64_t fault) const;

  MPI_Comm _comm;
  int _rank = 0;
  std::string _xdmf, _h5_path;
  const Scene& _scene;
  // Rank 0: the faces' nodes (node_key, ascending), their coordinates
  // and fault, the facets (d node positions each) and the times written.
  std::vector<std::int64_t> _nodes;
  std::vector<double> _x;
  std::vector<int> _fault;
  std::vector<std::string> _fault_names;
  std::vector<std::int64_t> _facets;
  std::vector<int> _facet_fault;            // per facet, its fault
  std::vector<std::int64_t> _conduit_row;   // per facet (conduit_rows)
  bool _conduits = false;
  std::vector<double> _times;
  int _dim = 2;
  hid_t _h5 = -1;
};

} // namespace biotcontact
