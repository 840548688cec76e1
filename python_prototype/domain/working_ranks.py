"""The ranks a run works on (cpp/domain/working_ranks.h): a mesh too small
for the ranks it was started on is distributed over fewer of them, since
below some thousands of cells a rank (scene/schema.py,
default_cells_per_rank) a second rank costs more than its share of the
work saves (docs/performance.md, "nineteenth session"); the others wait
for the exit status (docs/user-guide.md, "Running in parallel")."""
import math
import time

from mpi4py import MPI


def working_ranks(cells, cells_per_rank, ranks):
    """How many of `ranks` work on a mesh of `cells` cells when each should
    hold at least `cells_per_rank` (solver.cells_per_rank; 0: every rank
    works): floor(cells / cells_per_rank), at least 1, at most `ranks`."""
    if cells_per_rank <= 0:
        return ranks
    return min(max(cells // cells_per_rank, 1), ranks)


def built_in_cells(mesh):
    """The cells of a built-in mesh: 4 crossed triangles per rectangle, 6
    tetrahedra per box."""
    return math.prod(mesh.cells) * (4 if mesh.dimension == 2 else 6)


def working_communicator(world, cells, cells_per_rank):
    """The first working_ranks(cells, ...) ranks of `world` as a
    communicator (collective on world); None on the ranks that wait."""
    works = world.rank < working_ranks(cells, cells_per_rank, world.size)
    comm = world.Split(0 if works else MPI.UNDEFINED, world.rank)
    return comm if comm != MPI.COMM_NULL else None


def wait_quietly(request):
    """Completes `request`, asleep between polls (2 ms) rather than
    spinning as a blocking MPI call does: a rank that waits for another
    (rank 0 reading a gmsh file, or the working ranks) leaves its core to
    it."""
    while not request.Test():
        time.sleep(0.002)


def working_ranks_line(world, mesh, cells_per_rank):
    """The log's line when fewer ranks of `world` work than were started
    (those that hold `mesh`), empty when all do."""
    working = mesh.comm.size
    if working == world.size:
        return ""
    cells = mesh.topology.index_map(mesh.topology.dim).size_global
    return (f"{working} of {world.size} ranks work{'s' if working == 1 else ''}: {cells} cells are fewer than "
            f"solver.cells_per_rank = {cells_per_rank} for each of {working + 1} (0: every rank works)")
