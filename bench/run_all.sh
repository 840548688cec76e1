#!/bin/bash
# All benchmarks, then the report: bench/results/*.csv, docs/performance.md
# and docs/performance/*.png. Run from anywhere:
#
#     bash bench/run_all.sh
#
# Environment: REPEAT (default 3) runs per case; LARGEST=1 adds [640,64] to
# the size sweep; BIOTCONTACT chooses the solver binary (default
# build/biotcontact); SCALING=1 also runs bench/scaling.py (direct
# against iterative, 2D and 3D, 1 and 2 ranks, with the largest meshes:
# about 45 minutes at one repetition, so it runs with REPEAT_SCALING,
# default 1); MONOLITHIC=1 also runs bench/monolithic.py (the monolithic
# system's factorisation against its Krylov method and the iterative
# split, about 8 minutes at REPEAT_MONOLITHIC, default 1); RANKS=1 also runs
# bench/ranks.py and bench/auto.py (every case on 1 and 2 ranks with the
# defaults, and auto against direct and iterative on the shipped 3D scenes,
# about an hour at REPEAT). Each step prints
# the commands it runs. The targets table is in docs/performance.md
# ("Targets") and nowhere else: no other page is rewritten.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=/usr/bin/python3
REPEAT=${REPEAT:-3}
sweep_extra=()
[ "${LARGEST:-0}" = 1 ] && sweep_extra+=(--largest)

start=$SECONDS
step() {
  local t0=$SECONDS
  echo "== $*"
  "$@"
  echo "== done in $((SECONDS - t0)) s"
}
step $PY bench/size_sweep.py --repeat "$REPEAT" "${sweep_extra[@]}"
step $PY bench/mandel.py --repeat "$REPEAT"
step $PY bench/prototype.py --repeat "$REPEAT"
if [ "${SCALING:-0}" = 1 ]; then
  step $PY bench/scaling.py --largest --repeat "${REPEAT_SCALING:-1}"
fi
if [ "${RANKS:-0}" = 1 ]; then
  step $PY bench/ranks.py --repeat "$REPEAT"
  step $PY bench/auto.py --repeat "$REPEAT"
fi
if [ "${MONOLITHIC:-0}" = 1 ]; then
  step $PY bench/monolithic.py --repeat "${REPEAT_MONOLITHIC:-1}"
fi
step $PY bench/report.py
echo "all benchmarks in $((SECONDS - start)) s"
