#include "output/interruption.h"

#include "assembly/petsc_error.h"

#include <csignal>
#include <petscsys.h>

namespace biotcontact
{

namespace
{
volatile std::sig_atomic_t received = 0;

// A second signal stops the run at once by the signal's default action
// (signal and raise are async-signal-safe): the step being computed is
// lost, the finished ones are on disk (each flushed as it is written).
extern "C" void record(int signal)
{
  if (received != 0)
  {
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  received = signal;
}
} // namespace

void install_interruption_handlers()
{
  // PETSc's default handler prints a stack trace and aborts on SIGTERM.
  check_petsc(PetscPopSignalHandler(), "the interruption handlers: PetscPopSignalHandler");
  struct sigaction action = {};
  action.sa_handler = record;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int interruption_signal(MPI_Comm comm)
{
  // mpirun forwards the signal to every rank, but not at the same instant:
  // the ranks agree on it so that all stop after the same step.
  int local = received, global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_INT, MPI_MAX, comm);
  return global;
}

} // namespace biotcontact
