#!/usr/bin/env bash
# The machine's own stalls, without ParaView or the plugin: bench_cpu_gaps spins one thread a
# core for 60 s and records every gap over 2 ms in its clock reads. Writes
# bench/results/cpu_gaps.{md,json}. Run it on an idle machine, as the view benchmark is.
#
#   bench/run_cpu_gaps_bench.sh     # about 1 minute
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
build="${BUILD_DIR:-$repo/build}"
seconds="${SECONDS_TO_RUN:-60}"
cmake --build "$build" --target bench_cpu_gaps
commit="$(git -C "$repo" rev-parse --short HEAD)"
cpu="$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
"$build/bin/bench_cpu_gaps" "$seconds" > "$here/results/cpu_gaps.json"
python3 - "$here/results/cpu_gaps.json" "$here/results/cpu_gaps.md" "$commit" "$cpu" "$(nproc)" <<'PY'
import glob, json, os, statistics, sys, time
data = json.load(open(sys.argv[1]))
commit, cpu, cores = sys.argv[3], sys.argv[4], sys.argv[5]
bursts = data["bursts"]
large = [b for b in bursts if b["lost_ms"] >= 20]
intervals = data["large_burst_intervals_s"]
with open(sys.argv[2], "w") as out:
    out.write("# The machine's own stalls (no ParaView, no plugin)\n\n")
    out.write(f"`bench/run_cpu_gaps_bench.sh` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, commit {commit}, "
              f"{cpu}, {cores} cores. {data['threads']} threads (one a core) read the monotonic clock in a tight "
              f"loop for {data['seconds']:.0f} s; every gap over {data['threshold_ms']:.0f} ms is time the machine "
              "took the core away. Gaps within 100 ms of each other on any thread make one burst.\n\n")
    out.write(f"- Gaps: {data['gaps']} in {len(bursts)} bursts.\n")
    if large:
        out.write(f"- Bursts losing 20 ms or more (summed over threads): {len(large)}, "
                  f"lost {min(b['lost_ms'] for b in large):.0f}-{max(b['lost_ms'] for b in large):.0f} ms each over "
                  f"{min(b['span_ms'] for b in large):.0f}-{max(b['span_ms'] for b in large):.0f} ms, "
                  f"longest single gap {max(b['longest_ms'] for b in large):.1f} ms.\n")
    if intervals:
        out.write(f"- Interval between them: median {statistics.median(intervals):.2f} s "
                  f"(min {min(intervals):.2f}, max {max(intervals):.2f}).\n")
    out.write("\nA frame of the view benchmark (run_view_bench.py) that meets such a burst takes the lost time "
              "on top of its own, as llvmpipe renders on every core. Its frames follow one another at 60-100 ms, "
              "so a burst every 5 s meets about one frame in 50-80: 12-20 frames of a 1,000-frame path, where a "
              "99th percentile within the target allows 10 over it. Those frames stay within 100 ms only if "
              "they would take about 50 ms without the burst.\n\n")
    # What the guest kernel runs periodically: DAMON's proactive reclaim shows as these bursts.
    for kd in sorted(glob.glob("/sys/kernel/mm/damon/admin/kdamonds/[0-9]*")):
        def read(rel):
            try:
                return open(os.path.join(kd, rel)).read().strip()
            except OSError:
                return "?"
        pid = read("pid")
        cpu_s = "?"
        try:
            fields = open(f"/proc/{pid}/stat").read().split(")")[1].split()
            uptime = float(open("/proc/uptime").read().split()[0])
            cpu_s = (f"{(int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK'):.0f} s of CPU in "
                     f"{uptime / 3600:.1f} h of uptime")
        except (OSError, ValueError, IndexError):
            pass
        def seconds(rel):
            value = read(rel)
            return f"{int(value) / 1e6:g} s" if value.isdigit() else value
        out.write(f"The kernel runs DAMON (kdamond, pid {pid}, state {read('state')}): sampling every "
                  f"{seconds('contexts/0/monitoring_attrs/intervals/sample_us')}, aggregating every "
                  f"{seconds('contexts/0/monitoring_attrs/intervals/aggr_us')}, scheme action "
                  f"'{read('contexts/0/schemes/0/action')}' on '{read('contexts/0/operations')}'; it has used "
                  f"{cpu_s}. Sampling its CPU time every 20 ms (2026-11-22) showed 50-60 ms spent in bursts "
                  "about 5.2 s apart, the period of the bursts below. This is the machine's configuration, "
                  "outside the project.\n\n")
    out.write("| burst start s | span ms | gaps | lost ms (all threads) | longest gap ms |\n|---|---:|---:|---:|---:|\n")
    for b in large:
        out.write(f"| {b['start_s']:.3f} | {b['span_ms']:.1f} | {b['gaps']} | {b['lost_ms']:.1f} | {b['longest_ms']:.1f} |\n")
PY
cat "$here/results/cpu_gaps.md"
