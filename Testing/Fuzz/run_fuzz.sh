#!/usr/bin/env bash
# Builds a libFuzzer target (clang, ASan + UBSan) and fuzzes it on one core.
#
#   Testing/Fuzz/run_fuzz.sh [SECONDS] [TARGET]     default 60 FuzzGrdeclParser
#
# TARGET: FuzzGrdeclParser   GRDECL decks (grdecl.dict; corpus-work/corpus, artifacts)
#         FuzzEclipseOutput  EGRID/INIT/UNRST keyword files (eclipse.dict; corpus-work/eclipse/)
#         FuzzResmrFile      .resmr files and their regions (resmr.dict; corpus-work/resmr/)
#         FuzzResmrpFile     .resmrp property files (resmr.dict; corpus-work/resmrp/)
#
# Environment:
#   FUZZ_BUILD_DIR   where the fuzzer binary goes          (default /tmp/resmr-fuzz-build)
#   RESMR_DATA_DIR   real decks to seed the run from       (default <repo>/../shared/data)
#   FUZZ_FORK=1      keep going after a crash/timeout/OOM (libFuzzer -fork=1 -ignore_*=1)
#   FUZZ_EXTRA       extra libFuzzer flags, e.g. "-seed=1 -only_ascii=1"
#   CXX              clang++ with libFuzzer                (default clang++)
#
# Needs clang's libFuzzer runtime (Debian: apt-get install clang libclang-rt-14-dev).
# The working corpus, crash artifacts and logs go under Testing/Fuzz/corpus-work/ (ignored
# by git); real decks are copied there, never into the repository. Findings worth keeping
# are copied by hand into Testing/Fuzz/findings/ and described in Testing/Fuzz/README.md.
set -euo pipefail

seconds="${1:-60}"
target="${2:-FuzzGrdeclParser}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "${here}/../.." && pwd)"
build="${FUZZ_BUILD_DIR:-/tmp/resmr-fuzz-build}"
data="${RESMR_DATA_DIR:-${repo}/../shared/data}"
cxx="${CXX:-clang++}"
case "${target}" in
  FuzzGrdeclParser)
    work="${here}/corpus-work"
    max_len=65536
    dict="${here}/grdecl.dict"
    seeds="${here}/seeds"
    ;;
  FuzzEclipseOutput)
    work="${here}/corpus-work/eclipse"
    max_len=131072 # a small grid + INIT + restart in one input
    dict="${here}/eclipse.dict"
    seeds="${here}/seeds/eclipse"
    ;;
  FuzzResmrFile)
    work="${here}/corpus-work/resmr"
    max_len=65536
    dict="${here}/resmr.dict"
    seeds="${here}/seeds/resmr"
    ;;
  FuzzResmrpFile)
    work="${here}/corpus-work/resmrp"
    max_len=65536
    dict="${here}/resmr.dict"
    seeds="${here}/seeds/resmrp"
    ;;
  *)
    echo "run_fuzz.sh: unknown target '${target}' (FuzzGrdeclParser, FuzzEclipseOutput, FuzzResmrFile or FuzzResmrpFile)" >&2
    exit 2
    ;;
esac

mkdir -p "${build}" "${work}/corpus" "${work}/artifacts"

# ---------------------------------------------------------------- build
fuzzer="${build}/${target}"
echo "== building ${fuzzer}"
# -fno-sanitize-recover: a UBSan report is a crash with an artifact, not a line in the log.
# Core's stages are folders, each on the include path (as Core/CMakeLists.txt does).
stages=(common eclipse synthetic simplify hierarchy format view)
includes=()
sources=()
for stage in "${stages[@]}"; do
  includes+=(-I "${repo}/Core/${stage}")
  sources+=("${repo}/Core/${stage}"/*.cpp)
done
"${cxx}" -std=c++17 -g -O1 -fno-omit-frame-pointer \
  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
  "${includes[@]}" "${sources[@]}" "${here}/${target}.cpp" -o "${fuzzer}" -llzo2

# ---------------------------------------------------------------- corpus
find "${seeds}" -maxdepth 1 -type f -exec cp -n {} "${work}/corpus/" \;
if [ "${target}" = FuzzEclipseOutput ]; then
  if [ -d "${data}" ]; then
    # Small simulator output files as they are (the head of bigger ones), and each small
    # grid joined with its INIT and restarts by the harness's separator (%RESMR%\n):
    # grid, INIT, UNRST or grid, INIT, Xnnnn..., "" (an empty last part: per-step files).
    sep=$'%RESMR%\n'
    n=0
    while IFS= read -r -d '' file; do
      name="data_$(echo "${file#"${data}"/}" | tr '/' '_')"
      if [ ! -e "${work}/corpus/${name}" ]; then
        head -c "${max_len}" "${file}" > "${work}/corpus/${name}"
        n=$((n + 1))
      fi
    done < <(find "${data}/format_variants" "${data}/spe1" "${data}/egg" -type f -size -200k \
               \( -iname '*.EGRID' -o -iname '*.FEGRID' -o -iname '*.INIT' -o -iname '*.FINIT' \
               -o -iname '*.UNRST' -o -iname '*.FUNRST' -o -iname '*.X[0-9][0-9][0-9][0-9]' \
               -o -iname '*.F[0-9][0-9][0-9][0-9]' \) -print0 2>/dev/null)
    while IFS= read -r -d '' grid; do
      stem="${grid%.*}"
      name="set_$(echo "${stem#"${data}"/}" | tr '/' '_')"
      [ -e "${work}/corpus/${name}" ] && continue
      init=$(ls "${stem}".INIT "${stem}".FINIT 2>/dev/null | head -n 1 || true)
      unrst=$(ls "${stem}".UNRST "${stem}".FUNRST 2>/dev/null | head -n 1 || true)
      steps=$(ls "${stem}".X[0-9][0-9][0-9][0-9] 2>/dev/null | head -n 4 || true)
      [ -z "${init}${unrst}${steps}" ] && continue
      # With the restarts if the whole set fits max_len, else grid and INIT only.
      for with_restarts in 1 0; do
        {
          cat "${grid}"; printf '%s' "${sep}"
          if [ -n "${init}" ]; then cat "${init}"; fi
          if [ "${with_restarts}" = 1 ]; then
            printf '%s' "${sep}"
            if [ -n "${unrst}" ]; then
              cat "${unrst}"
            else
              for step in ${steps}; do cat "${step}"; printf '%s' "${sep}"; done
            fi
          fi
        } > "${work}/corpus/${name}.tmp"
        if [ "$(stat -c %s "${work}/corpus/${name}.tmp")" -le "${max_len}" ]; then
          mv "${work}/corpus/${name}.tmp" "${work}/corpus/${name}"
          n=$((n + 1))
          break
        fi
        rm -f "${work}/corpus/${name}.tmp"
      done
    done < <(find "${data}/format_variants" "${data}/spe1" "${data}/egg" -type f -size -200k \
               \( -iname '*.EGRID' -o -iname '*.FEGRID' \) -print0 2>/dev/null)
    echo "== seeded ${n} new real files and grid sets from ${data}"
  else
    echo "== no data folder at ${data}: committed seeds only"
  fi
elif [ -d "${data}" ]; then
  n=0
  while IFS= read -r -d '' deck; do
    # libFuzzer would cut longer inputs to max_len anyway: keep the head of big decks.
    name="data_$(echo "${deck#"${data}"/}" | tr '/' '_')"
    if [ ! -e "${work}/corpus/${name}" ]; then
      head -c "${max_len}" "${deck}" > "${work}/corpus/${name}"
      n=$((n + 1))
    fi
  done < <(find "${data}/emerald" "${data}/format_variants/xtgeo_etc" \
             "${data}/spe9/opm-data_deck" "${data}/spe1" "${data}/reek/xtgeo_testdata" \
             -maxdepth 1 -type f \( -name '*.grdecl' -o -name '*.bgrdecl' -o -name 'SPE9.GRDECL' \
             -o -name 'SPE1*.DATA' -o -name 'reek_sim_faults.grdecl' \) -print0 2>/dev/null)
  echo "== seeded ${n} new real decks from ${data}"
else
  echo "== no data folder at ${data}: committed seeds only"
fi
echo "== corpus: $(ls "${work}/corpus" | wc -l) files"

# ---------------------------------------------------------------- fuzz
log="${work}/fuzz-$(date -u +%Y%m%dT%H%M%SZ).log"
flags=(-max_len=${max_len} -timeout=10 -rss_limit_mb=2048 -dict="${dict}"
  -max_total_time="${seconds}" -print_final_stats=1 -artifact_prefix="${work}/artifacts/")
if [ "${FUZZ_FORK:-0}" = 1 ]; then
  flags+=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
fi
# shellcheck disable=SC2206
flags+=(${FUZZ_EXTRA:-})
echo "== fuzzing for ${seconds} s on one core; log: ${log}"
# The target's private input folders go here: libFuzzer ends its (fork) processes without
# running destructors, so they are removed after the run.
scratch="${build}/tmp-${target}"
rm -rf "${scratch}" && mkdir -p "${scratch}"
set +e
# Run from an empty folder: a fuzzed INCLUDE with a relative name is looked up next to the
# input (a private temp folder), never in the repository.
(cd "${build}" && TMPDIR="${scratch}" "${fuzzer}" "${flags[@]}" "${work}/corpus") > "${log}" 2>&1
status=$?
set -e
rm -rf "${scratch}"
tail -n 12 "${log}"

# ---------------------------------------------------------------- summary
if grep -q '^stat::number_of_executed_units' "${log}"; then
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "${log}" | tail -n 1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "${log}" | tail -n 1)
else # fork mode: the last "#N: cov: ... time: Ts" line
  last=$(grep -E '^#[0-9]+: cov:' "${log}" | tail -n 1 || true)
  runs=$(echo "${last}" | sed -n 's/^#\([0-9]*\):.*/\1/p')
  fuzzed=$(echo "${last}" | sed -n 's/.* time: \([0-9]*\)s.*/\1/p')
  speed=$(( ${runs:-0} / (${fuzzed:-1} > 0 ? ${fuzzed:-1} : 1) ))
fi
echo "== summary: $(date -u +%Y-%m-%dT%H:%MZ) ${seconds} s, ${runs:-?} executions, ${speed:-?} exec/s," \
  "corpus $(ls "${work}/corpus" | wc -l) files ($(du -sk "${work}/corpus" | cut -f1) KiB)," \
  "crashes $(grep -c 'ERROR: libFuzzer: deadly signal\|ERROR: AddressSanitizer\|runtime error' "${log}" || true)," \
  "timeouts $(grep -c 'ERROR: libFuzzer: timeout' "${log}" || true)," \
  "ooms $(grep -c 'ERROR: libFuzzer: out-of-memory\|malloc limit' "${log}" || true)"
echo "== libFuzzer exit status ${status}; artifacts in ${work}/artifacts:"
ls -la "${work}/artifacts"
exit "${status}"
