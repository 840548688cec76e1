// The fields written at each output time: the unknowns and what is derived
// from them (cell-averaged flux, volumetric stress sigma_v, contact).
#pragma once

#include "assembly/problem.h"
#include "coupling/scheme.h"
#include "output/fault_series.h"
#include "output/output.h"

#include <dolfinx/fem/Function.h>
#include <memory>

namespace biotcontact
{

/// @brief Writes the scheme's fields into the output at a time; names them
/// as ParaView shows them.
class OutputFields
{
public:
  /// With faults and XDMF output, the faults' fields go to fault.xdmf (kept
  /// up to `resume_time` after a restart).
  OutputFields(const Problem& problem, Scheme& scheme, Output& output, const double* resume_time);

  /// The pressure and the flux (nothing without flow).
  void write_flow(double t);
  /// The displacement, sigma_v and the contact fields; also updates
  /// `contact`.
  void write_mechanics(double t);

  /// The scheme whose fields are written from now on: the run's, or
  /// coupling.fallback's for the step it solved.
  void read_from(Scheme& scheme);
  /// `contact` from the scheme, where its fields are not written.
  void read_contact() { contact = _scheme->contact_state(); }

  ContactState contact; // at the last mechanics output

private:
  const Problem& _problem;
  Scheme* _scheme = nullptr;
  Output& _output;
  std::shared_ptr<dolfinx::fem::Function<double>> _flux, _sigma_v, _zero_pressure;
  std::unique_ptr<FaultSeries> _faults;
  std::vector<double> _fault_flow; // the conduit faults' cell fields at the last flow output
};

} // namespace biotcontact
