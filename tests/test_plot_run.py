"""tools/plot_run.py writes valid PNGs into the run directory for a contact
run (contact, history, coupling) and for runs without contact (terzaghi:
history and coupling; darcy, flow only: history), and refuses a directory
that is no run with a one-line error."""
import os
import subprocess

import matplotlib.image
from support import ROOT, check, run, scene

PLOT = ["/usr/bin/python3", os.path.join(ROOT, "tools", "plot_run.py")]
SIGNATURE = b"\x89PNG\r\n\x1a\n"

for name, expected in (("default", {"contact.png", "history.png", "coupling.png"}),
                       ("terzaghi", {"history.png", "coupling.png"}),
                       ("darcy", {"history.png"})):
    out, _ = run(scene(name))
    p = subprocess.run(PLOT + [out], capture_output=True, text=True)
    check(p.returncode == 0, f"{name}: plot_run succeeds ({p.stderr.strip()})")
    written = {f for f in os.listdir(out) if f.endswith(".png")}
    check(written == expected, f"{name}: writes {sorted(written)}")
    for f in sorted(written):
        path = os.path.join(out, f)
        with open(path, "rb") as png:
            head = png.read(8)
        image = matplotlib.image.imread(path)
        check(head == SIGNATURE and image.ndim == 3 and min(image.shape[:2]) > 200 and image.std() > 0,
              f"{name}: {f} is a PNG of {image.shape[1]}x{image.shape[0]} pixels, not blank")

p = subprocess.run(PLOT + [ROOT], capture_output=True, text=True)
check(p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and "summary.json" in p.stderr,
      f"a directory that is no run: exit 2 and one line ({p.stderr.strip()})")
