// A run of one scene: scene -> mesh and tags -> forms -> flow step /
// mechanics step -> coupling scheme -> output and diagnostics.
#pragma once

#include "output/progress.h"
#include "scene/scene.h"

#include <mpi.h>
#include <string>

namespace biotcontact
{

/// How a run is started.
struct RunControl
{
  /// The scene's text and --set overrides: a checkpoint is only taken up
  /// by a run of the same.
  std::string fingerprint;
  /// Go on from the checkpoint in the output directory (--restart).
  bool restart = false;
};

/// Runs `scene`, writing into `directory`; returns run_ok, or
/// run_not_converged after writing what was finished and the iteration log,
/// run_output_failed when a file could not be written (a full disk), or
/// 128 + the signal after an interruption.
int run(const Scene& scene, const std::string& directory, MPI_Comm comm, const RunControl& control);

} // namespace biotcontact
