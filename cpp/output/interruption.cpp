#include "output/interruption.h"

#include "assembly/petsc_error.h"

#include <csignal>
#include <petscsys.h>

namespace biotcontact
{

namespace
{
volatile std::sig_atomic_t received = 0;

extern "C" void record(int signal) { received = signal; }
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
