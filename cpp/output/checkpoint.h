// Checkpoint and restart: the state a run needs to continue after its last
// completed step (every N steps with output.checkpoint_every = N, and when
// it is interrupted), so that `biotcontact run SCENE --restart DIR` goes on
// in the same files and ends as the uninterrupted run would.
//
// Each rank writes its own local arrays (ghosts included) to
// DIR/checkpoint/rank<r>.bin: a restart needs the same scene (compared by
// its fingerprint: the file's text and the --set overrides) and the same
// number of ranks, and then finds every array in the layout it left.
// A checkpoint replaces the previous one only once it is complete.
#pragma once

#include <map>
#include <mpi.h>
#include <string>
#include <vector>

namespace biotcontact
{

struct Checkpoint
{
  int steps = 0;     // completed mechanics steps (windows)
  double time = 0;   // their last time
  std::map<std::string, std::vector<double>> arrays; // this rank's, ghosts included
  std::map<std::string, double> numbers;             // counters and scales
  std::string output;                                // Output::position()
};

/// Writes the checkpoint of a run into `directory` (collective).
void write_checkpoint(MPI_Comm comm, const std::string& directory, const std::string& fingerprint,
                      const Checkpoint& checkpoint);

/// Reads it back; throws SceneError when there is none, or it belongs to
/// another scene or number of ranks (collective).
Checkpoint read_checkpoint(MPI_Comm comm, const std::string& directory, const std::string& fingerprint);

} // namespace biotcontact
