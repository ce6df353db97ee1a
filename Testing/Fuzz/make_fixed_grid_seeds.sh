#!/usr/bin/env bash
# Writes the fixed-grid seeds of FuzzEclipseOutput into seeds/eclipse: inputs whose empty
# part 0 stands for the harness's fixed grid (resmr synth 6 5 3, seed 1), with the INIT and
# restarts resmr synth writes for it: whole, as per-step files, and cut short.
#
#   Testing/Fuzz/make_fixed_grid_seeds.sh RESMR_BINARY [SEEDS_DIR]
set -euo pipefail
resmr="$1"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
seeds="${2:-${here}/seeds/eclipse}"
work="$(mktemp -d)"
trap 'rm -rf "${work}"' EXIT
"${resmr}" synth 6 5 3 --steps 2 -o "${work}/FIXED.EGRID" > /dev/null
sep=$'%RESMR%\n'
init="${work}/FIXED.INIT"
unrst="${work}/FIXED.UNRST"
size=$(stat -c %s "${unrst}")
half=$((size / 2))
# The second step starts at the second SEQNUM header (24 bytes: marker, name, count, type, marker).
second=$(grep -obUaP 'SEQNUM  ' "${unrst}" | sed -n '2s/:.*//p')
second=$((second - 4))
{ printf '%s' "${sep}"; cat "${init}"; printf '%s' "${sep}"; cat "${unrst}"; } > "${seeds}/fixed_grid_init_unrst.bin"
{ printf '%s' "${sep}"; cat "${init}"; printf '%s' "${sep}"; head -c "$((size - 7))" "${unrst}"; } > "${seeds}/fixed_grid_unrst_cut_in_last_step.bin"
{ printf '%s' "${sep}"; printf '%s' "${sep}"; head -c "$((half + 10))" "${unrst}"; } > "${seeds}/fixed_grid_no_init_unrst_cut_in_second_seqnum.bin"
{ printf '%s' "${sep}"; head -c 100 "${init}"; printf '%s' "${sep}"; head -c "${second}" "${unrst}"; printf '%s' "${sep}";
  tail -c "+$((second + 1))" "${unrst}" | head -c "$((size - second - 30))"; printf '%s' "${sep}"; } > "${seeds}/fixed_grid_cut_init_per_step_cut.bin"
ls -la "${seeds}"/fixed_grid_*.bin
