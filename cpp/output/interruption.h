// SIGINT and SIGTERM end a run cleanly: the handler only records the
// signal; the time loop checks it after each completed (and written) step,
// then stops, closes its files and writes summary.json with "status":
// "interrupted". The process then exits with the usual status of the
// signal (128 + signal number). A second signal stops it at once, as
// SIGKILL would: what protects such a run is that every output time is
// flushed as it is written.
#pragma once

#include <mpi.h>

namespace biotcontact
{

/// Replaces PETSc's handlers of SIGINT and SIGTERM (call after PetscInitialize).
void install_interruption_handlers();

/// The signal received by any rank so far, 0 if none (collective).
int interruption_signal(MPI_Comm comm);

} // namespace biotcontact
