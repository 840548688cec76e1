"""ParaView's default reader opens a run as one grid (no multiblock) with
every array of the XDMF at every output time, in double precision
(tools/paraview_view.py --check under xvfb-run), for a contact run and a
multirate run. ParaView is optional (not in tools/setup.sh): without
pvpython the test is skipped (exit 77, ctest reports it as skipped)."""
import shutil
import subprocess
import sys

from support import ROOT, check, run, scene

pvpython, xvfb = shutil.which("pvpython"), shutil.which("xvfb-run")
if not pvpython or not xvfb:
    print("SKIP: pvpython or xvfb-run not installed (apt-get install paraview xvfb xauth)")
    sys.exit(77)

for label, options in (("single rate", []), ("multirate", ["--set", "coupling.scheme=multirate",
                                                            "--set", "coupling.q=4"])):
    out, _ = run(scene("default"), *options)
    p = subprocess.run([xvfb, "-a", pvpython, f"{ROOT}/tools/paraview_view.py", out, "--check"],
                       capture_output=True, text=True, timeout=300)
    report = [line for line in p.stdout.splitlines() if line.startswith(("reader", "problem"))]
    check(p.returncode == 0, f"{label}: {'; '.join(report) or p.stderr.strip()[-300:]}")
