"""Helpers shared by the benchmark scripts in bench/: the machine header,
one timed solver run with its peak memory, CSV files with `# key: value`
header lines, and medians over repetitions.

Every bench script takes the options of `add_arguments`, prints the machine
header and every command it runs, and rewrites its CSV after each run, so
that an interrupted benchmark keeps what it finished.
"""
import csv
import datetime
import json
import os
import re
import shlex
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PYTHON = "/usr/bin/python3"
DEFAULT_BINARY = os.environ.get("BIOTCONTACT", os.path.join(ROOT, "build", "biotcontact"))
RESULTS = os.path.join(ROOT, "bench", "results")
# One OpenMP thread per process unless the caller chose (the user guide's
# advice for MPI runs, and the tests' setting): hypre's threads on the
# cores the ranks already use (docs/performance.md, "thirty-second
# session"). The header records it.
os.environ.setdefault("OMP_NUM_THREADS", "1")


class BenchError(Exception):
    """A failure reported in one line (a run that failed, a bad option)."""


# --- machine header -------------------------------------------------------

def _output(command, cwd=ROOT, timeout=60):
    """Stripped stdout of a short command, or "" if it cannot run."""
    try:
        p = subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    return p.stdout.strip() if p.returncode == 0 else ""


def _cpu_model():
    """The first `model name` of /proc/cpuinfo."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def _memory_gb():
    """Total memory (MemTotal of /proc/meminfo) in GB."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemTotal:"):
                    return f"{int(line.split()[1]) / 1024 ** 2:.1f} GB"
    except OSError:
        pass
    return "unknown"


def _git_state():
    """(short commit, dirty) of the repository; dirty means tracked files
    other than the benchmark results and docs/performance* are modified."""
    commit = _output(["git", "rev-parse", "--short", "HEAD"]) or "unknown"
    status = _output(["git", "status", "--porcelain", "--untracked-files=no", "--", ".",
                      ":(exclude)bench/results", ":(exclude)docs/performance.md", ":(exclude)docs/performance"])
    changed = len(status.splitlines())
    return commit, f"yes ({changed} tracked files modified)" if changed else "no"


def _build_type(binary):
    """CMAKE_BUILD_TYPE and release flags from the CMakeCache.txt next to the binary."""
    values = {}
    try:
        with open(os.path.join(os.path.dirname(os.path.abspath(binary)), "CMakeCache.txt")) as f:
            for line in f:
                m = re.match(r"(CMAKE_BUILD_TYPE|CMAKE_CXX_FLAGS_RELEASE):\w+=(.*)", line)
                if m:
                    values[m.group(1)] = m.group(2).strip()
    except OSError:
        return "unknown"
    return f"{values.get('CMAKE_BUILD_TYPE', '?')} ({values.get('CMAKE_CXX_FLAGS_RELEASE', '')})"


def _blas(binary):
    """The BLAS the binary loads (the library behind Debian's libblas.so.3
    alternative: reference or OpenBLAS)."""
    for line in _output(["ldd", binary]).splitlines():
        if line.strip().startswith("libblas.so"):
            return os.path.realpath(line.split("=>")[1].split("(")[0].strip())
    return "unknown"


def machine_header(binary, command=None):
    """The header every CSV starts with, as an ordered dict: machine, date,
    commit, versions and the bench command line."""
    commit, dirty = _git_state()
    python_versions = _output([PYTHON, "-c", "import dolfinx, petsc4py.PETSc as P; "
                               "print('dolfinx', dolfinx.__version__ + ', PETSc', "
                               "'.'.join(map(str, P.Sys.getVersion())))"])
    header = {
        "host": socket.gethostname(),
        "cores": str(len(os.sched_getaffinity(0))),  # not nproc, which OMP_NUM_THREADS changes
        "cpu": _cpu_model(),
        "memory": _memory_gb(),
        "date": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
        "commit": commit,
        "dirty": dirty,
        "solver": _output([binary, "--version"]) or f"{binary}: --version failed",
        "build": _build_type(binary),
        "blas": _blas(binary),
        "python": python_versions or "dolfinx/petsc4py not importable",
    }
    threads = {k: os.environ[k] for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "OPENBLAS_CORETYPE") if k in os.environ}
    if threads:
        header["environment"] = " ".join(f"{k}={v}" for k, v in threads.items())
    header["command"] = command or shlex.join([PYTHON] + [os.path.relpath(sys.argv[0], ROOT)] + sys.argv[1:])
    return header


def print_header(header):
    """Prints the header as `key: value` lines."""
    for key, value in header.items():
        print(f"{key}: {value}")
    print(flush=True)


# --- runs -----------------------------------------------------------------

def run_process(command, log_path, cwd=ROOT):
    """Runs `command` as a child, stdout and stderr to `log_path`; returns
    (exit status, wall seconds including start-up, peak RSS in MB of that
    child and its waited-for descendants, from os.wait4)."""
    with open(log_path, "w") as log:
        start = time.perf_counter()
        child = subprocess.Popen(command, cwd=cwd, stdout=log, stderr=subprocess.STDOUT)
        _, status, usage = os.wait4(child.pid, 0)
        wall = time.perf_counter() - start
    child.returncode = os.waitstatus_to_exitcode(status)  # Popen must not wait again
    return child.returncode, wall, usage.ru_maxrss / 1024.0  # ru_maxrss is in kB on Linux


def _last_line(path):
    try:
        with open(path) as f:
            lines = [line.strip() for line in f if line.strip()]
    except OSError:
        return ""
    return lines[-1] if lines else ""


def short_path(path):
    """`path` relative to the repository root if it is inside it (runs start
    there), else unchanged; options and module names pass through."""
    if not os.path.isabs(path):
        return path
    relative = os.path.relpath(path, ROOT)
    if relative.startswith(".."):
        return path
    return relative if os.sep in relative else os.path.join(".", relative)


def on_ranks(binary, ranks):
    """The command prefix that runs `binary` on `ranks` MPI ranks."""
    return ([] if ranks == 1 else ["mpirun", "-n", str(ranks)]) + [binary]


def run_case(command_prefix, scene, sets, petsc_options, out):
    """One run of `command_prefix run SCENE --out OUT --set ... PETSC...`
    (command_prefix: [binary] or [python, -m, python_prototype]). Prints the
    command; returns a dict with the parsed summary.json (`summary`), the
    process wall time (`process_wall_s`), the peak RSS (`peak_rss_mb`) and
    the command (`command`). Raises BenchError on failure."""
    os.makedirs(out, exist_ok=True)
    command = [short_path(c) for c in command_prefix] + ["run", short_path(scene), "--out", out]
    for s in sets:
        command += ["--set", s]
    command += list(petsc_options)
    text = shlex.join(command)
    print(f"$ {text}", flush=True)
    log = os.path.join(out, "run.log")
    status, wall, rss = run_process(command, log)
    summary_path = os.path.join(out, "summary.json")
    if status != 0 or not os.path.exists(summary_path):
        raise BenchError(f"exit {status}: {text}: {_last_line(log) or 'no output'}")
    with open(summary_path) as f:
        summary = json.load(f)
    return {"summary": summary, "process_wall_s": wall, "peak_rss_mb": rss, "command": text}


# --- CSV files ------------------------------------------------------------

def write_csv(path, rows, columns, header):
    """Writes `# key: value` header lines, then the rows (dicts) under
    `columns`; floats keep 6 significant digits."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        for key, value in header.items():
            f.write(f"# {key}: {value}\n")
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})
    os.replace(tmp, path)


def read_csv(path):
    """(header dict, rows as dicts of strings) of a CSV written by write_csv."""
    header, lines = {}, []
    with open(path, newline="") as f:
        for line in f:
            if line.startswith("# ") and not lines:
                key, _, value = line[2:].rstrip("\n").partition(": ")
                header[key] = value
            else:
                lines.append(line)
    return header, list(csv.DictReader(lines))


def number(value):
    """A CSV cell as float (empty or unparsable -> nan)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


def medians(rows, keys, fields):
    """Groups rows by the `keys` columns (first-seen order) and returns one
    dict per group: the key values, `repetitions`, and the median of each of
    `fields` (as float; nan if absent)."""
    groups = {}
    for row in rows:
        groups.setdefault(tuple(row[k] for k in keys), []).append(row)
    result = []
    for key, members in groups.items():
        entry = dict(zip(keys, key))
        entry["repetitions"] = len(members)
        for name in fields:
            values = [number(m.get(name)) for m in members]
            values = [v for v in values if v == v]
            entry[name] = statistics.median(values) if values else float("nan")
        result.append(entry)
    return result


# --- command-line conventions ------------------------------------------------

def parse_variants(text, known):
    """The comma-separated variants of --variants, each one of `known`."""
    variants = [v.strip() for v in text.split(",") if v.strip()]
    unknown = [v for v in variants if v not in known]
    if unknown or not variants:
        raise BenchError(f"--variants: unknown {', '.join(unknown) or '(none given)'}; "
                         f"choose from {', '.join(known)}")
    return variants


def parse_cells(text):
    """Cell counts from "[40,4]", "[40,4],[80,8]", "[16,8,4]" or "40x4 80x8"."""
    found = re.findall(r"\[\s*(\d+(?:\s*,\s*\d+)+)\s*\]|(\d+(?:x\d+)+)", text)
    cells = [tuple(int(n) for n in re.split(r"[\s,x]+", bracket or crossed) if n) for bracket, crossed in found]
    if not cells:
        raise BenchError(f"--cells {text!r}: expected e.g. \"[40,4]\" or \"[40,4],[80,8]\"")
    return cells


def cells_text(cells):
    """(40, 4) -> "[40,4]", as the scene's mesh.cells value."""
    return "[" + ",".join(str(n) for n in cells) + "]"


def add_arguments(parser, name):
    """The options every bench script has. The CSV keeps every repetition
    (column `repetition`, 1..N); the documentation quotes their median. The
    work directory is removed at the end unless --keep-runs or a run failed;
    everything after `--` goes to every C++ run as PETSc options."""
    parser.add_argument("--repeat", type=int, default=3, help="runs per case (default 3; docs use the median)")
    parser.add_argument("--binary", default=DEFAULT_BINARY, help="solver (default $BIOTCONTACT or build/biotcontact)")
    parser.add_argument("--out-dir", default=RESULTS, help=f"where {name}.csv goes (default bench/results)")
    parser.add_argument("--work-dir", help="where the runs write (default a temporary directory)")
    parser.add_argument("--keep-runs", action="store_true", help="keep the run directories")
    parser.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                        help="extra scene override for every run (e.g. time.end=0.8 for a smoke run)")
    parser.add_argument("--update", action="store_true",
                        help=f"replace only the rerun cases' rows of an existing {name}.csv, keep the others")


def parse_arguments(parser, argv=None):
    """Parses the options; everything after `--` are PETSc options for every
    C++ run. Returns (args, petsc options). Raises BenchError on bad values."""
    argv = list(sys.argv[1:] if argv is None else argv)
    petsc = []
    if "--" in argv:
        at = argv.index("--")
        argv, petsc = argv[:at], argv[at + 1:]
    args = parser.parse_args(argv)
    if args.repeat < 1:
        raise BenchError("--repeat must be at least 1")
    if not os.access(args.binary, os.X_OK):
        raise BenchError(f"{args.binary}: solver binary not found or not executable (build it or set --binary)")
    args.binary = os.path.abspath(args.binary)
    return args, petsc


class Recorder:
    """The CSV of one benchmark: rewritten after every row, with the header
    (machine, command) plus `elapsed_s` and `status` (partial/complete).
    With `update`, the rows of an existing file whose case (the columns up
    to `repetition`) no rerun row has are kept, and the header records the
    update (the machine and commit of the kept rows are the file's own)."""

    def __init__(self, out_dir, name, columns, header, update=False):
        self.path = os.path.join(out_dir, name + ".csv")
        self.columns, self.header, self.rows = columns, dict(header), []
        self.case = columns[:columns.index("repetition") + 1]
        self.kept, self.elapsed_key = [], "elapsed_s"
        if update:
            if not os.path.exists(self.path):
                raise BenchError(f"--update: {self.path} does not exist")
            old_header, self.kept = read_csv(self.path)
            self.header = {**old_header, "updated": f"{header['date']} {header.get('commit', '')} (dirty: "
                                                    f"{header.get('dirty', '')}) {header.get('command', '')}"}
            self.elapsed_key = "updated_elapsed_s"
        self.start = time.perf_counter()

    def _key(self, row):
        return tuple(str(row[c]) for c in self.case)

    def _write(self, status):
        self.header[self.elapsed_key] = f"{time.perf_counter() - self.start:.1f}"
        self.header["status"] = status
        rerun = {self._key(r) for r in self.rows}
        write_csv(self.path, [r for r in self.kept if self._key(r) not in rerun] + self.rows, self.columns,
                  self.header)

    def add(self, row):
        """Appends a row and rewrites the file."""
        self.rows.append(row)
        self._write("partial")

    def finish(self):
        """Marks the file complete; prints where it is."""
        self._write("complete")
        print(f"wrote {self.path} ({len(self.rows)} rows, {self.header[self.elapsed_key]} s)")


def start_recorder(args, petsc, name, columns, scene):
    """The machine header of a benchmark of `scene` (what it runs), with the
    fixed --set values and PETSc options, printed; its Recorder."""
    header = machine_header(args.binary)
    header["scene"] = scene
    header["fixed_sets"] = " ".join(args.sets)
    header["petsc_options"] = " ".join(petsc)
    print_header(header)
    return Recorder(args.out_dir, name, columns, header, args.update)


class WorkDir:
    """The directory runs write to: the given one, or a temporary one removed
    on exit unless keep."""

    def __init__(self, path, keep):
        self.temporary = path is None
        self.path = path or tempfile.mkdtemp(prefix="biotcontact-bench-")
        self.keep = keep or not self.temporary
        os.makedirs(self.path, exist_ok=True)

    def run(self, *parts):
        """A fresh directory for one run (emptied if it exists)."""
        path = os.path.join(self.path, *parts)
        shutil.rmtree(path, ignore_errors=True)
        return path

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *_):
        if self.keep or exc_type is not None:  # after a failure the logs (run.log) are worth reading
            print(f"run directories kept in {self.path}", file=sys.stderr if exc_type else sys.stdout)
        else:
            shutil.rmtree(self.path, ignore_errors=True)


def main_wrapper(main):
    """Runs main(); a BenchError becomes one line on stderr and exit 1."""
    try:
        return main()
    except BenchError as e:
        print(f"{os.path.basename(sys.argv[0])}: error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"{os.path.basename(sys.argv[0])}: interrupted", file=sys.stderr)
        return 130
