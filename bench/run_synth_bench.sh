#!/usr/bin/env bash
# `resmr synth` write benchmark: synthetic reservoirs of 1M, 10M and 100M cells streamed to
# EGRID + INIT (+ UNRST), peak RSS against nz, the cost of report steps and the disk's
# sequential write bandwidth. Writes bench/results/synth.{md,json}; scratch files go to
# bench/scratch/synth/ (git-ignored) and are deleted after each run (the 100M case needs
# ~6.5 GB free while it runs).
#
#   bench/run_synth_bench.sh            # build resmr if needed, run everything (~7 min)
#
# Environment (all optional):
#   BUILD_DIR   build folder (default build/, configured Release if new)
#   REPEATS     runs of the 1M and 10M cases (default 3)
#   REPEATS_100M runs of the 100M case (default 2)
#   NO_100M=1   skip the 100M case
# Extra arguments are passed to run_synth_bench.py (see --help).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
build="${BUILD_DIR:-$repo/build}"
mkdir -p "$here/scratch/synth"

if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
cmake --build "$build" --target resmr

extra=()
if [ "${NO_100M:-0}" = 1 ]; then extra+=(--no-100m); fi
python3 "$here/run_synth_bench.py" --resmr "$build/bin/resmr" --build-dir "$build" \
  --repeats "${REPEATS:-3}" --repeats-100m "${REPEATS_100M:-2}" --out-dir "$here/results" \
  "${extra[@]}" "$@"
