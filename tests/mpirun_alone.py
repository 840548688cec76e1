"""mpirun, one job at a time across the test suite: waits for an exclusive
lock on a file the suite's tests share ($BIOTCONTACT_MPI_LOCK), then
becomes mpirun (exec, the same process, so signals reach it) holding the
lock until it exits; Open MPI closes the file in the ranks it starts. Two
2-rank jobs at once put four busy-polling ranks on two cores: a run of
1.2 s alone took 24.6 s so (docs/performance.md, fifteenth session)."""
import fcntl
import os
import sys
import tempfile

path = os.environ.get("BIOTCONTACT_MPI_LOCK", os.path.join(tempfile.gettempdir(), "biotcontact-mpirun.lock"))
lock = os.open(path, os.O_CREAT | os.O_RDWR, 0o666)
fcntl.flock(lock, fcntl.LOCK_EX)
os.set_inheritable(lock, True)
os.execvp("mpirun", ["mpirun", *sys.argv[1:]])
