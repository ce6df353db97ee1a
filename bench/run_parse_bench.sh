#!/usr/bin/env bash
# GRDECL parse benchmark: resmr vs. OPM (python3-opm-common), resdata and xtgeo (PyPI), all
# on the same >= 1 GB tiled deck in one run. Writes bench/results/grdecl_parse.{md,json}.
#
#   bench/run_parse_bench.sh            # build, make the deck if absent, run everything
#
# Environment (all optional):
#   BUILD_DIR   build folder (default /tmp/resmr-bench-build; configured Release if new)
#   DECK        deck path (default bench/scratch/tiled_reek.grdecl, generated if absent)
#   RUNS        resmr runs (default 3; peers run once)
#   TIMEOUT     per-tool wall-clock cap in seconds (default 900)
#   MEM_GB      per-tool address-space cap in GB (default 20)
#   SKIP        peers to leave out, e.g. "xtgeo resdata"
#   NO_VENV=1   do not create bench/scratch/venv (resdata, xtgeo) if it is missing
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
build="${BUILD_DIR:-/tmp/resmr-bench-build}"
deck="${DECK:-$here/scratch/tiled_reek.grdecl}"
venv="$here/scratch/venv"
sys_python=/usr/bin/python3   # Debian's: has numpy and python3-opm-common
mkdir -p "$here/scratch"

# 1. Build (Release) only the benchmark executable and the core library.
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON
fi
cmake --build "$build" --target bench_grdecl_parse
exe="$build/bin/bench_grdecl_parse"

# 2. Deck (>= 1 GB), generated from the Reek grid if absent.
if [ ! -f "$deck" ]; then
  "$sys_python" "$here/make_tiled_deck.py" "$deck"
fi

# 3. Peers from PyPI in a private venv (git-ignored).
if [ ! -x "$venv/bin/python" ] && [ "${NO_VENV:-0}" != 1 ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --upgrade pip
  "$venv/bin/pip" install --quiet xtgeo resdata six   # resdata 6.3 imports six
fi

# 4. Run everything (warm page cache, same caps for every tool) and write the report.
# shellcheck disable=SC2086
"$sys_python" "$here/run_parse_bench.py" --deck "$deck" --bench-exe "$exe" \
  --build-dir "$build" --venv-python "$venv/bin/python" --runs "${RUNS:-3}" \
  --timeout "${TIMEOUT:-900}" --mem-limit-gb "${MEM_GB:-20}" --skip ${SKIP:-} \
  --out-dir "$here/results"
