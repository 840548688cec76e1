// Checkpoint and restart: the state a run needs to continue after its last
// completed step (every N steps with output.checkpoint_every = N, and when
// it is interrupted), so that `biotcontact run SCENE --restart DIR` goes on
// in the same files and ends as the uninterrupted run would.
//
// The state does not depend on the partition: every unknown is stored under
// a name taken from the mesh's input numbering (output/keyed_values.h), so that a
// run may be restarted on any partition and any number of ranks. A restart
// needs the same scene (compared by its fingerprint, restart_fingerprint)
// and a mesh that holds every stored name; otherwise it is refused in one
// line. The files and how one replaces the last: write_checkpoint.
#pragma once

#include "coupling/scheme.h"
#include "output/keyed_values.h"

#include <cstdint>
#include <dolfinx/mesh/Mesh.h>
#include <map>
#include <mpi.h>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

struct Checkpoint
{
  int steps = 0;   // completed mechanics steps (windows)
  double time = 0; // their last time
  std::map<std::string, std::vector<double>> arrays; // the same on every rank (the time grid)
  std::map<std::string, KeyedValues> fields;          // every rank's entries after read_checkpoint
  std::map<std::string, double> numbers;              // counters and scales
  std::string output;                                 // Output::position()
};

/// @brief The parts of a run a checkpoint keeps and a restart restores:
/// the scheme's unknowns, time-scheme memory and solver counts, the report,
/// the controllers' state and the time grid (as retries left it).
struct RunState
{
  Scheme& scheme;
  const dolfinx::mesh::Mesh& mesh;
  CouplingReport& report;
  ControllerState& state;
  TimeGrid& grid;
};

/// The checkpoint of `run` after `steps` completed steps ending at `time`,
/// with the output's position (collective).
Checkpoint capture_checkpoint(const RunState& run, int steps, double time, const std::string& output);

/// Loads a checkpoint into `run`, whatever the partition; refuses one of
/// another mesh, or one that lacks any of the unknowns, naming `directory`
/// (collective). Solver counts stored by system name, or by the position of
/// the layout before names (flow, mechanics, monolithic, second pass), are
/// both read.
void restore_checkpoint(const Checkpoint& c, const RunState& run, MPI_Comm comm, const std::string& directory);

/// What restore_checkpoint loads but the solver counts: the unknowns, the
/// time grid, the report and the controllers' state; for a scheme that
/// goes on from another's state in the same run (coupling.fallback), whose
/// systems keep counting their own solves.
void restore_run_state(const Checkpoint& c, const RunState& run, MPI_Comm comm, const std::string& directory);

/// Writes the checkpoint of a run into `directory` (collective); throws
/// OutputError on every rank when a file could not be written, leaving the
/// previous checkpoint as it was. Layout of DIR/checkpoint: state.bin (rank
/// 0: the step, the time, the counters, the time grid, the output position,
/// the number of value files) and values.<step>.<rank>.bin (each rank's
/// owned unknowns with their names). A checkpoint replaces the previous one
/// when its state.bin is renamed into place, after every value file is
/// complete; the files of other steps are removed after that.
void write_checkpoint(MPI_Comm comm, const std::string& directory, const std::string& fingerprint,
                      const Checkpoint& checkpoint);

/// The fingerprint a checkpoint is written and read with: the scene file's
/// `text` and its --set `overrides`, but those of the keys a restart may
/// change (restart_keys: how the coupling is solved, not what), and the
/// scheme's time stepping: "fixed-stress" and "monolithic" take the same
/// steps and may replace each other, a multirate scheme is another scene.
std::string restart_fingerprint(const std::string& text, const std::vector<std::string>& overrides,
                                const Scene& scene);

/// The --set of the restart that takes what `failure` proposes, where it
/// proposes the monolithic scheme: coupling.scheme between the single-rate
/// split and it (restart_fingerprint), a multirate run's coupling.fallback
/// (none where it had it); otherwise empty.
std::string restart_proposal(const std::string& failure, const Scene& scene);

/// Reads it back with every rank's values; throws SceneError when there is
/// none, or it belongs to another scene, or is damaged (collective).
Checkpoint read_checkpoint(MPI_Comm comm, const std::string& directory, const std::string& fingerprint);

} // namespace biotcontact
