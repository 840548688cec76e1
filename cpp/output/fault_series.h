// fault.xdmf (+ fault.h5): the faults' fields on their + faces at every
// output time, for ParaView and meshio. One grid per time on the faces'
// mesh (segments in 2D, triangles in 3D; the nodes of the + faces, a tip
// being one node of both faces), node data:
// - opening: [u].n + g0 (0 at the tips, where the faces meet);
// - slip: the tangential jump [u] - ([u].n) n, a vector (three components);
// - slip_increment: its change since the start of the step (the one a
//   friction law decides on), a vector;
// - traction: the contact traction, >= 0, zero where the fault is open;
// - tangential_traction: the tangential contact traction, a vector (three
//   components; along the slip increment where the pair slips; on a
//   frictionless fault the solve's error: round-off with a factorisation);
// - state: the pair's state (contact_law.h): 0 open, 1 stick, 2 slip; 1 at
//   the tips, where the faces are one node and neither open nor slide;
// - pressure: the fluid pressure in the fault (fault.NAME.pressure; 0 for a
//   fault loaded by the pore pressure beside it, which solution.xdmf holds).
// Rank 0 writes it, from the pairs each rank gathers to it (a fault holds
// few nodes of the mesh). Each write is complete on disk when it returns,
// as solution.xdmf's; a restart keeps the times up to its checkpoint's.
#pragma once

#include "assembly/problem.h"
#include "contact/contact.h"

#include <hdf5.h>
#include <mpi.h>
#include <string>
#include <vector>

namespace biotcontact
{

class FaultSeries
{
public:
  /// Creates directory/fault.xdmf and .h5 with the faces' mesh; or, after
  /// a restart at `resume_time`, goes on in them (collective).
  FaultSeries(MPI_Comm comm, const std::string& directory, const Problem& problem, const double* resume_time);
  ~FaultSeries();
  FaultSeries(const FaultSeries&) = delete;
  FaultSeries& operator=(const FaultSeries&) = delete;

  /// Adds the state of the faults at time t (collective).
  void write(const ContactState& contact, double t);

private:
  void gather_surface(const Problem& problem);
  void write_xml() const;

  MPI_Comm _comm;
  int _rank = 0;
  std::string _xdmf, _h5_path;
  const Scene& _scene;
  // Rank 0: the faces' nodes (input indices, ascending), their coordinates
  // and fault, the facets (d node positions each) and the times written.
  std::vector<std::int64_t> _nodes;
  std::vector<double> _x;
  std::vector<int> _fault;
  std::vector<std::string> _fault_names;
  std::vector<std::int64_t> _facets;
  std::vector<double> _times;
  int _dim = 2;
  hid_t _h5 = -1;
};

} // namespace biotcontact
