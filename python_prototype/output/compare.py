"""Compare two runs (e.g. C++ and prototype) output by output:

- every field at every output time: max |a - b| relative to the field's
  largest |a| over the run, nodes and cells matched by their coordinates (so
  runs partitioned or numbered differently compare);
- the coupling iterations of every step (iterations.csv);
- the active contact set at every output time (contact_active).

Returns 1 if a difference exceeds the tolerance or counts/sets differ."""
import csv
import os

import numpy as np

from ..output.time_series import Fields


def steps(directory):
    """Coupling iterations per step, from iterations.csv."""
    with open(os.path.join(directory, "iterations.csv")) as f:
        counts = {}
        for row in csv.DictReader(f):
            counts[int(row["step"])] = int(row["iteration"])
    return [counts[k] for k in sorted(counts)]


def compare(dir_a, dir_b, tolerance=1e-8, out=print):
    a, b = Fields(dir_a), Fields(dir_b)
    failures = []
    out(f"comparing {dir_a} (a) with {dir_b} (b), tolerance {tolerance:g}")
    names = sorted(set(a.series) | set(b.series))
    for name in names:
        if name not in a.series or name not in b.series:
            failures.append(f"{name}: only in {'a' if name in a.series else 'b'}")
            continue
        times = a.times(name)
        if times != b.times(name):
            failures.append(f"{name}: output times differ ({len(times)} against {len(b.times(name))})")
            continue
        values = {t: (a.sorted(name, t), b.sorted(name, t)) for t in times}
        if any(va[1].shape != vb[1].shape or not np.allclose(va[1], vb[1], rtol=0, atol=1e-10)
               for va, vb in values.values()):
            failures.append(f"{name}: the meshes differ")
            continue
        scale = max(max(np.abs(va[0]).max(initial=0.0) for va, _ in values.values()), 1e-300)
        worst = {t: np.abs(va[0] - vb[0]).max(initial=0.0) / scale for t, (va, vb) in values.items()}
        t_worst = max(worst, key=worst.get)
        ok = worst[t_worst] <= tolerance
        out(f"  {name:17s} {len(times):4d} times  max relative difference {worst[t_worst]:.3e}"
            f" (t = {t_worst:g})  {'ok' if ok else 'FAIL'}")
        if not ok:
            failures.append(f"{name}: relative difference {worst[t_worst]:.3e} at t = {t_worst:g}")
        if name == "contact_active":
            changed = [t for t, (va, vb) in values.items() if not np.array_equal(va[0] > 0.5, vb[0] > 0.5)]
            sizes = [int((values[t][0][0] > 0.5).sum()) for t in times]
            out(f"  active sets       {'identical' if not changed else 'DIFFER'} at all {len(times)} times"
                f" (sizes {sizes[0]} -> {sizes[-1]}, max {max(sizes)})")
            if changed:
                failures.append(f"active contact sets differ at t = {', '.join(f'{t:g}' for t in changed[:5])}")

    ia, ib = steps(dir_a), steps(dir_b)
    if ia == ib:
        out(f"  coupling iterations identical in all {len(ia)} steps (total {sum(ia)})")
    else:
        diff = [k + 1 for k in range(min(len(ia), len(ib))) if ia[k] != ib[k]]
        out(f"  coupling iterations DIFFER: {len(ia)} against {len(ib)} steps, total {sum(ia)} against "
            f"{sum(ib)}, first differing steps {diff[:10]}")
        failures.append("coupling iterations differ")

    out("FAIL: " + "; ".join(failures) if failures else "agree")
    return 1 if failures else 0
