#!/usr/bin/env bash
# EGRID + INIT open and restart step switch benchmark: resmr vs. OPM EclIO
# (python3-opm-common) and resdata (PyPI), all on the same files in one run: a >= 1 GB tiled
# EGRID + INIT + UNRST and the largest real runs in ../shared/data. Writes
# bench/results/egrid_load.{md,json}.
#
#   bench/run_egrid_bench.sh            # build, make the tiled set if absent, run everything
#
# Environment (all optional):
#   BUILD_DIR    build folder (default /tmp/resmr-egrid-bench-build; configured Release,
#                without tests, if new)
#   TILED_DIR    folder of the tiled set (default bench/scratch/egrid, generated if absent)
#   RUNS         loads per process on the tiled set (default 5)
#   RUNS_SMALL   loads per process on the real models (default 20)
#   SWITCHES     step switches per process, at most steps - 1 per model (default 6)
#   TIMEOUT      per-tool wall-clock cap in seconds (default 900)
#   MEM_GB       per-tool address-space cap in GB (default 20)
#   SKIP         peers to leave out, e.g. "resdata"
#   NO_REAL=1    the tiled set only
#   NO_PROFILE=1 skip the perf profile and the huge-page run of resmr on the tiled set
#   NO_VENV=1    do not create bench/scratch/venv (resdata) if it is missing
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
build="${BUILD_DIR:-/tmp/resmr-egrid-bench-build}"
tiled_dir="${TILED_DIR:-$here/scratch/egrid}"
tiled="$tiled_dir/TILED_REEK.EGRID"
venv="$here/scratch/venv"
sys_python=/usr/bin/python3   # Debian's: has numpy and python3-opm-common
mkdir -p "$here/scratch"

# 1. Build (Release) only the benchmark executable and the core library.
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON \
    -DBUILD_TESTING=OFF
fi
cmake --build "$build" --target bench_egrid_load
exe="$build/bin/bench_egrid_load"

# 2. Tiled set (EGRID >= 1 GB, INIT, UNRST), generated from the Reek run if absent.
if [ ! -f "$tiled" ] || [ ! -f "${tiled%.EGRID}.INIT" ] || [ ! -f "${tiled%.EGRID}.UNRST" ]; then
  "$sys_python" "$here/make_tiled_egrid.py" "$tiled_dir"
fi

# 3. resdata from PyPI in a private venv (git-ignored), shared with run_parse_bench.sh.
if [ ! -x "$venv/bin/python" ] && [ "${NO_VENV:-0}" != 1 ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --upgrade pip
  "$venv/bin/pip" install --quiet xtgeo resdata six   # resdata 6.3 imports six
fi

# 4. Run everything (warm page cache, same caps for every tool) and write the report.
extra=()
if [ "${NO_REAL:-0}" = 1 ]; then extra+=(--no-real); fi
if [ "${NO_PROFILE:-0}" = 1 ]; then extra+=(--no-profile); fi
# shellcheck disable=SC2086
"$sys_python" "$here/run_egrid_bench.py" --tiled "$tiled" --bench-exe "$exe" \
  --build-dir "$build" --venv-python "$venv/bin/python" --runs "${RUNS:-5}" \
  --runs-small "${RUNS_SMALL:-20}" --switches "${SWITCHES:-6}" --timeout "${TIMEOUT:-900}" \
  --mem-limit-gb "${MEM_GB:-20}" --skip ${SKIP:-} "${extra[@]}" --out-dir "$here/results"
