"""Runs the prototype's command line many times in one process, for tests
that launch it on dozens of bad inputs (its imports cost 0.6 s a launch).

Reads one JSON request per line on stdin, {"argv": [...], "cwd": DIR}, and
answers each with one JSON line {"status": N, "stderr": TEXT} on stdout:
the exit status `python3 -m python_prototype ARGV` would have, and all it
wrote to file descriptor 2 (Python's and PETSc's alike). PETSc reads its
options once per process, so a request with PETSc options is refused:
launch those on their own (support.Prototype does)."""
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from python_prototype.__main__ import main, parse  # noqa: E402


def run_case(argv, cwd):
    """(exit status, standard error) of one command line, run here."""
    saved = os.dup(1), os.dup(2)
    with tempfile.TemporaryFile() as err, open(os.devnull, "w") as null:
        sys.stdout.flush(), sys.stderr.flush()
        os.dup2(null.fileno(), 1)
        os.dup2(err.fileno(), 2)
        here = os.getcwd()
        try:
            os.chdir(cwd)
            status = main(argv)
        except SystemExit as e:
            status = e.code if isinstance(e.code, int) else 1
        finally:
            sys.stdout.flush(), sys.stderr.flush()
            os.chdir(here)
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
        err.seek(0)
        return status, err.read().decode(errors="replace")


def serve():
    for line in sys.stdin:
        request = json.loads(line)
        if parse(request["argv"])[4]:
            raise SystemExit("prototype_worker: PETSc options need a process of their own")
        status, stderr = run_case(request["argv"], request["cwd"])
        print(json.dumps({"status": status, "stderr": stderr}), flush=True)


if __name__ == "__main__":
    serve()
