#!/usr/bin/env bash
# Writing an EGRID of 1M and 10M cells with the tools engineers use (xtgeo, resdata: a plain
# box, no geology, no fsync) next to `resmr synth` (the faulted model, EGRID + INIT, fsync).
# Needs bench/scratch/venv with xtgeo and resdata (pip). Writes bench/results/synth_peers.md.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
py="$here/scratch/venv/bin/python"
out="$here/scratch/synth"
mkdir -p "$out"
md="$here/results/synth_peers.md"
{
  echo "# Writing EGRIDs: resmr synth next to xtgeo and resdata"
  echo
  echo "\`bench/run_synth_peers.sh\` on $(date -u '+%Y-%m-%d %H:%M UTC'), commit $(git -C "$repo" rev-parse --short HEAD),"
  echo "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores. One process a run."
  echo "xtgeo (create_box_grid, to_file egrid, PORO to GRDECL) and resdata (create_rectangular,"
  echo "save_EGRID) write a plain box with no geology and do not fsync; imports are not timed."
  echo "resmr synth writes the faulted model (EGRID + INIT with 10 arrays) and fsyncs every file."
  echo
  echo "| tool | dims | seconds | cells/min | peak RSS MB |"
  echo "|---|---|---:|---:|---:|"
} > "$md"
row() {
  python3 -c 'import json, sys
d = json.loads(sys.argv[2])
print("| %s | %s | %.2f | %.1f M | %.0f |" % (sys.argv[1], sys.argv[3], d["seconds"], d["cells_per_minute"] / 1e6, d["peak_rss_mb"]))' "$@"
}
for dims in "100 100 100" "500 200 100"; do
  set -- $dims
  line="$("$repo/build/bin/resmr" synth $dims --quiet -o "$out/peer.EGRID")"
  row "resmr synth" "$line" "$1x$2x$3" >> "$md"
  rm -f "$out"/peer*
  for tool in xtgeo resdata; do
    line="$("$py" "$here/peers/synth_write_peers.py" $tool $dims "$out/peer.EGRID")"
    row "$tool" "$line" "$1x$2x$3" >> "$md"
    rm -f "$out"/peer*
  done
done
cat "$md"
