// biotcontact: coupled flow and geomechanics with frictionless contact.
//
//   biotcontact run SCENE.toml [--out DIR] [--set key.path=value ...] [PETSc options]
//   biotcontact check SCENE.toml [--set ...]
//
// Exit status: 0 success, 2 bad input (scene, options), 3 a solver or the
// coupling did not converge (what was finished is written), 1 anything else.
#include "assembly/materials.h"
#include "assembly/petsc_error.h"
#include "contact/contact.h"
#include "domain/create_domain.h"
#include "domain/mesh_checks.h"
#include "domain/working_ranks.h"
#include "output/checkpoint.h"
#include "output/interruption.h"
#include "output/write_failure.h"
#include "scene/scene.h"
#include "simulation.h"
#include "solvers/solver.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <dolfinx/common/log.h>
#include <filesystem>
#include <omp.h>
#include <petscsys.h>
#include <optional>
#include <string>
#include <vector>

namespace
{

const char* usage = R"(usage:
  biotcontact run SCENE.toml [--out DIR | --restart DIR] [--set key.path=value ...] [PETSc options]
  biotcontact check SCENE.toml [--set key.path=value ...]
  biotcontact --help | --version

run     simulate the scene; writes DIR/solution.xdmf (+ .h5), DIR/iterations.csv
        and DIR/summary.json (DIR defaults to results/<scene name>)
check   validate the scene and exit
--set   override a scene value, e.g. --set coupling.L=kdr --set time.dt=0.5
--restart DIR  continue the run in DIR from its checkpoint (same scene and
        --set values; output.checkpoint_every = N writes one every N steps
        and when the run is interrupted)

The scene's [solver] table picks "direct", "iterative" or "auto" (by size)
per system; PETSc options with the system's prefix override it: flow_,
mechanics_ (and its contact solve), monolithic_, e.g.
  -flow_ksp_type gmres -flow_pc_type hypre -mechanics_snes_monitor
The contact solver is SNES vinewtonrsls with bounds on the contact DOFs.
)";

/// The command line: our own arguments, and the rest for PETSc.
struct Arguments
{
  std::string command, scene, out, restart;
  std::vector<std::string> overrides;
  std::vector<char*> petsc; // argv[0] and the PETSc options
  std::string bad;          // what was wrong with the command line
};

int fail(const std::string& message, int rank)
{
  if (rank == 0)
    std::fprintf(stderr, "biotcontact: error: %s\n", message.c_str());
  return 2;
}

/// An error of no kind the program expects (a defect, status 1). On
/// several ranks this one cannot know whether the others met it too or
/// wait for it in a collective, which would hang the run for ever: it says
/// the error itself and stops every rank.
int unexpected_error(const char* what, int rank)
{
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (ranks == 1)
  {
    std::fprintf(stderr, "biotcontact: error: %s\n", what);
    return 1;
  }
  std::fprintf(stderr, "biotcontact: error on rank %d: %s (every rank stopped)\n", rank, what);
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, 1);
  return 1;
}

/// Our own arguments are read first; an option with one dash goes to PETSc
/// (with its value, if the next word is not an option).
Arguments parse_arguments(int argc, char* argv[])
{
  Arguments args;
  args.petsc = {argv[0]};
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "--help" or a == "-h")
      args.command = "help";
    else if (a == "--version")
      args.command = "version";
    else if (a == "--out" or a == "--set" or a == "--restart")
    {
      if (i + 1 >= argc)
        args.bad = a + " needs a value";
      else if (a == "--out")
        args.out = argv[++i];
      else if (a == "--restart")
        args.restart = argv[++i];
      else
        args.overrides.push_back(argv[++i]);
    }
    else if (args.command.empty() and (a == "run" or a == "check"))
      args.command = a;
    else if (args.scene.empty() and !args.command.empty() and a[0] != '-')
      args.scene = a;
    else if (a.rfind("--", 0) == 0)
      args.bad = "unknown option '" + a + "' (PETSc options take one dash)";
    else if (a[0] == '-')
    {
      args.petsc.push_back(argv[i]);
      if (i + 1 < argc and argv[i + 1][0] != '-')
        args.petsc.push_back(argv[++i]);
    }
    else
      args.bad = "unexpected argument '" + a + "'";
  }
  return args;
}

/// A run started without mpirun is one process: Open MPI need not start its
/// runtime daemon nor probe the network for peers, which costs 0.4 s of every
/// start (0.49 -> 0.08 s for MPI_Init, docs/performance.md), nor have hwloc
/// read every PCI device's configuration to place network devices it will
/// not use (0.016 s). Isolated, every such process takes job family 0 and so
/// one session directory, /tmp/ompi.HOST.UID/jf.0, which a run removes as it
/// ends while another one creates it: MPI_Init then fails (2 of 800 starts
/// of two runs at once); a process alone needs no session directory. A
/// user's own setting wins; under mpirun nothing changes.
void start_mpi_alone()
{
  if (std::getenv("OMPI_COMM_WORLD_SIZE") or std::getenv("PMIX_RANK"))
    return;
  setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
  if (std::string(std::getenv("OMPI_MCA_ess_singleton_isolated")) == "1")
    setenv("OMPI_MCA_orte_create_session_dirs", "0", 0);
  setenv("OMPI_MCA_pml", "ob1", 0);
  setenv("HWLOC_COMPONENTS", "-pci,-linuxio", 0);
}

/// PT-Scotch 7, which partitions the mesh over the ranks, splits its work
/// over threads by default and then returns another partition at each run
/// (its seed is fixed): the DOFs' order, so the iterative solves' round-off
/// and the coupling's iteration counts, changed from run to run of one
/// command on 2 ranks (docs/performance.md, "thirty-third session"). One
/// thread makes the partition a function of the mesh; a user's own setting
/// wins. Scotch reads the variable when it first partitions.
void partition_reproducibly() { setenv("SCOTCH_PTHREAD_NUMBER", "1", 0); }

/// One OpenMP thread per process unless OMP_NUM_THREADS says otherwise
/// (read by the OpenMP runtime as it loads, before main): hypre, MUMPS and
/// CHOLMOD give the same fields bit for bit with two threads, ranks on one
/// node would fight over its cores, and SuperLU_DIST solves wrongly with
/// more than one (threaded_superlu, solvers/options.h).
void one_openmp_thread()
{
  if (!std::getenv("OMP_NUM_THREADS"))
    omp_set_num_threads(1);
}

/// The error for options that name SuperLU_DIST with several OpenMP
/// threads or give a relative tolerance outside [0, 1) ("" when there is
/// none), from every PETSc option however given (command line,
/// PETSC_OPTIONS, a file).
std::string refused_options()
{
  char* all = nullptr;
  biotcontact::check_petsc(PetscOptionsGetAll(nullptr, &all), "reading the PETSc options: PetscOptionsGetAll");
  std::string error = biotcontact::threaded_superlu(all ? all : "", omp_get_max_threads());
  if (error.empty())
    error = biotcontact::relative_tolerance_out_of_range(all ? all : "");
  biotcontact::check_petsc(PetscFree(all), "reading the PETSc options: PetscFree");
  return error;
}

/// PETSc, MPI, the interruption handlers and the logs.
void initialize(std::vector<char*> petsc, char* argv[])
{
  biotcontact::silence_hdf5_errors(); // before any HDF5 call
  start_mpi_alone();
  partition_reproducibly();
  one_openmp_thread();
  int petsc_argc = static_cast<int>(petsc.size());
  petsc.push_back(nullptr); // MPI_Init reads argv up to its terminator
  char** petsc_args = petsc.data();
  biotcontact::check_petsc(PetscInitialize(&petsc_argc, &petsc_args, nullptr, nullptr),
                           "starting PETSc: PetscInitialize");
  // Errors are reported by our messages, never by PETSc stack traces.
  biotcontact::check_petsc(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr),
                           "starting PETSc: PetscPushErrorHandler");
  biotcontact::install_interruption_handlers();
  // The solver statistics of summary.json are read from PETSc's event log
  // (solver.h); -log_view prints the same log by system.
  biotcontact::check_petsc(PetscLogDefaultBegin(), "starting PETSc: PetscLogDefaultBegin");
  dolfinx::init_logging(1, argv);
  loguru::g_stderr_verbosity = loguru::Verbosity_WARNING;
}

/// `check`: the scene is read and its mesh built too, since a gmsh file's
/// boundary names are only known once it is read.
int check_scene(const biotcontact::Scene& scene, const Arguments& args, int rank)
{
  const biotcontact::Domain domain = biotcontact::create_domain(scene, MPI_COMM_WORLD);
  if (!domain.mesh)
    return 0; // this rank waits
  biotcontact::check_expressions(scene, domain, domain.mesh->comm());
  biotcontact::check_materials(scene, domain);
  if (scene.mechanics)
    biotcontact::check_contact(scene, domain);
  const std::string warning = biotcontact::gamma_warning(scene, biotcontact::largest_gamma_of(scene, domain.regions));
  if (rank == 0 and !warning.empty())
    std::printf("warning: %s\n", warning.c_str());
  if (rank == 0)
    std::printf("%s: ok (%s, %d steps)\n", args.scene.c_str(), scene.name.c_str(), scene.num_steps());
  return 0;
}

/// `run`: a restart goes on in the directory of the run it continues; the
/// scene text and the --set values are its fingerprint (restart_fingerprint).
int run_scene(const biotcontact::Scene& scene, const Arguments& args)
{
  const std::string out
      = !args.restart.empty() ? args.restart : args.out.empty() ? "results/" + scene.name : args.out;
  biotcontact::RunControl control;
  control.restart = !args.restart.empty();
  std::ifstream file(args.scene);
  const std::string text(std::istreambuf_iterator<char>(file), {});
  control.fingerprint = biotcontact::restart_fingerprint(text, args.overrides, scene);
  return biotcontact::run(scene, out, MPI_COMM_WORLD, control);
}

/// The command, with every error turned into one line and its exit status.
int execute(const Arguments& args, int rank)
{
  if (!args.bad.empty())
    return fail(args.bad + " (see --help)", rank);
  if (args.command.empty() or args.scene.empty())
    return fail("expected 'run SCENE.toml' or 'check SCENE.toml' (see --help)", rank);
  if (const std::string refused = refused_options(); !refused.empty())
    return fail(refused, rank);
  try
  {
    // Each rank reads the file: one that cannot (its node's file system or
    // memory) stops every rank, before any other collective call.
    std::optional<biotcontact::Scene> scene;
    std::string refused;
    try
    {
      scene.emplace(biotcontact::read_scene(args.scene, args.overrides));
    }
    catch (const biotcontact::SceneError& e)
    {
      refused = e.what();
    }
    biotcontact::agree_on_error(refused, MPI_COMM_WORLD);
    return args.command == "check" ? check_scene(*scene, args, rank) : run_scene(*scene, args);
  }
  catch (const biotcontact::SceneError& e)
  {
    return fail(e.what(), rank);
  }
  catch (const biotcontact::OptionsError& e)
  {
    return fail(e.what(), rank);
  }
  catch (const biotcontact::SolverError& e)
  {
    return fail(e.what(), rank) + 1;
  }
  catch (const std::exception& e)
  {
    return unexpected_error(e.what(), rank);
  }
}

/// Rank 0's exit status, on every rank. A rank that did not work
/// (domain/working_ranks.h) waits for it here, asleep.
int status_of_rank0(int status)
{
  MPI_Request request;
  MPI_Ibcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD, &request);
  biotcontact::wait_quietly(request);
  return status;
}

} // namespace

int main(int argc, char* argv[])
{
  const Arguments args = parse_arguments(argc, argv);
  if (args.command == "help")
  {
    std::printf("%s", usage);
    return 0;
  }
  if (args.command == "version")
  {
    std::printf("biotcontact %s (dolfinx 0.5, PETSc %d.%d.%d)\n", BIOTCONTACT_VERSION,
                PETSC_VERSION_MAJOR, PETSC_VERSION_MINOR, PETSC_VERSION_SUBMINOR);
    return 0;
  }
  try
  {
    initialize(args.petsc, argv);
  }
  catch (const biotcontact::SolverError& e) // before any rank is known: every rank says it
  {
    std::fprintf(stderr, "biotcontact: error: %s\n", e.what());
    return 1;
  }
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const int status = status_of_rank0(execute(args, rank));
  // The outputs and the exit status are final by now: a failed clean-up is only reported.
  biotcontact::warn_petsc(PetscFinalize(), "finishing PETSc: PetscFinalize");
  return status;
}
