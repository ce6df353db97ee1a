#!/usr/bin/env python3
"""Runs the `resmr synth` write benchmark: synthetic reservoirs streamed to EGRID + INIT.

Called by bench/run_synth_bench.sh (which builds resmr if needed); can also be run alone.
Writes OUT_DIR/synth.json and OUT_DIR/synth.md.

Every run is its own `/usr/bin/time -v resmr synth NX NY NZ -o FILE.EGRID --quiet` process,
one after the other, writing into bench/scratch/synth/ (git-ignored); the files it wrote are
deleted after each run (and `sync` run) so the next one starts on an empty, clean disk.
resmr fsyncs every file before renaming it into place, so its seconds include getting the
bytes to the disk. Measured:
  - 1M, 10M and 100M cells (the issue's "done when" case: 1000 x 1000 x 100);
  - O(nx*ny) memory: the same columns with 10x the layers (1000x1000x10 vs x100,
    100x100x100 vs x1000), peak RSS compared (within 1.25x, or 8 MiB more: the generator's
    calibration sample has a fixed cap, and two tables hold 16 bytes a layer);
  - the cost of report steps: 10M cells with --steps 10 (UNRST), against the same model
    without steps;
  - this machine's sequential write bandwidth (dd from /dev/zero, with and without fsync).
Peak RSS is taken twice: resmr's own getrusage (peak_rss_mb in its JSON line) and
/usr/bin/time -v's "Maximum resident set size".
"""

import argparse
import datetime
import glob
import hashlib
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import run_parse_bench as common  # noqa: E402  (machine info, JSON lines)

TARGET_CELLS_PER_MINUTE = 50e6

# (key, label, dims, group); repeats come from the command line per group.
CASES = [
    ("1M", "1M", (100, 100, 100), "size"),
    ("10M", "10M", (500, 200, 100), "size"),
    ("100M", "100M", (1000, 1000, 100), "size_100m"),
    ("1000x1000x10", "10M, 1000x1000 columns", (1000, 1000, 10), "nz"),
    ("100x100x1000", "10M, 100x100 columns", (100, 100, 1000), "nz"),
]
STEPS_CASE = ("10M+steps10", "10M, --steps 10", (500, 200, 100), 10)
# Peak RSS against the layer count at fixed columns, one run each.
NZ_SWEEP = [(100, 100, 10), (100, 100, 100), (100, 100, 300), (100, 100, 1000),
            (100, 100, 2000), (10, 10, 10000)]


# ------------------------------------------------------------------------------- helpers
def git_commit(short=False):
    try:
        cmd = ["git", "-C", REPO, "rev-parse"] + (["--short"] if short else []) + ["HEAD"]
        return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def disk_info(path):
    try:
        out = subprocess.run(["findmnt", "-no", "SOURCE,FSTYPE", "-T", path], capture_output=True,
                             text=True).stdout.split()
    except OSError:
        out = []
    usage = shutil.disk_usage(path)
    return {"device": out[0] if out else "?", "fstype": out[1] if len(out) > 1 else "?",
            "free_gb_at_start": round(usage.free / 1e9, 1)}


def parse_time_v(text):
    """The fields of /usr/bin/time -v that matter here."""
    fields = {}
    for line in text.splitlines():
        if ":" not in line:
            continue
        key, _, value = line.strip().rpartition(": ")
        fields[key.strip()] = value.strip()

    def num(key, cast=int):
        try:
            return cast(fields[key].rstrip("%"))
        except (KeyError, ValueError):
            return None
    elapsed = fields.get("Elapsed (wall clock) time (h:mm:ss or m:ss)")
    wall = None
    if elapsed:
        parts = [float(p) for p in elapsed.split(":")]
        wall = sum(p * 60 ** i for i, p in enumerate(reversed(parts)))
    return {
        "max_rss_kib": num("Maximum resident set size (kbytes)"),
        "user_seconds": num("User time (seconds)", float),
        "system_seconds": num("System time (seconds)", float),
        "cpu_percent": num("Percent of CPU this job got"),
        "wall_seconds": wall,
        "major_faults": num("Major (requiring I/O) page faults"),
        "minor_faults": num("Minor (reclaiming a frame) page faults"),
        "voluntary_switches": num("Voluntary context switches"),
        "fs_outputs": num("File system outputs"),
        "exit_status": num("Exit status"),
    }


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def snapshot_binary(args):
    """Copies resmr into the scratch folder and runs the copy, so that a rebuild of the build
    folder during the benchmark (another session, an editor's build) cannot change or remove
    the binary between runs. Returns a dict describing the binary measured."""
    digest = sha256(args.resmr)
    copy = os.path.join(args.scratch, f"resmr-{digest[:12]}")
    shutil.copy2(args.resmr, copy)
    info = {"path": args.resmr, "sha256": digest,
            "mtime_utc": datetime.datetime.fromtimestamp(
                os.path.getmtime(args.resmr), datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S"),
            "run_copy": copy}
    args.resmr_original, args.resmr = args.resmr, copy
    return info


def remove_outputs(stem):
    """Deletes what a run wrote (FILE.EGRID/.INIT/.UNRST and any .partial- temporaries)."""
    removed = 0
    for path in glob.glob(glob.escape(stem) + ".*"):
        suffix = path[len(stem):]
        if suffix.upper() in (".EGRID", ".INIT", ".UNRST") or ".partial-" in suffix:
            os.unlink(path)
            removed += 1
    return removed


def run_synth(args, dims, steps=0, tag="run"):
    stem = os.path.join(args.scratch, f"bench_{tag}")
    remove_outputs(stem)
    subprocess.run(["sync"])
    cmd = ["/usr/bin/time", "-v", args.resmr, "synth", *map(str, dims), "-o", stem + ".EGRID",
           "--quiet", "--seed", str(args.seed)]
    if steps:
        cmd += ["--steps", str(steps)]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
    wall = time.perf_counter() - start
    records = common.json_lines(proc.stdout)
    tv = parse_time_v(proc.stderr)
    row = {"dims": list(dims), "steps": steps, "returncode": proc.returncode,
           "wall_seconds_outside": round(wall, 3), "time_v": tv}
    if proc.returncode != 0 or not records:
        row["status"] = f"failed (exit {proc.returncode})"
        row["stderr_tail"] = proc.stderr[-1500:]
    else:
        row["status"] = "ok"
        row["resmr"] = records[-1]
        row["file_bytes"] = {os.path.basename(p)[len("bench_" + tag):]: os.path.getsize(p)
                             for p in records[-1].get("files", []) if os.path.exists(p)}
    remove_outputs(stem)
    return row


def summary(values):
    values = [v for v in values if v is not None]
    if not values:
        return None
    return {"best": min(values), "median": statistics.median(values), "worst": max(values),
            "n": len(values)}


def case_result(key, label, dims, steps, runs):
    ok = [r for r in runs if r["status"] == "ok"]
    out = {"key": key, "label": label, "dims": list(dims), "steps": steps, "runs": runs}
    if not ok:
        return out
    first = ok[0]["resmr"]
    secs = [r["resmr"]["seconds"] for r in ok]
    out.update(
        cells=first["cells"], active=first["active"], bytes=first["bytes"],
        file_bytes=ok[0]["file_bytes"],
        seconds=summary(secs),
        cells_per_minute={"best": first["cells"] / min(secs) * 60,
                          "median": first["cells"] / statistics.median(secs) * 60},
        mb_per_s={"best": first["bytes"] / min(secs) / 1e6,
                  "median": first["bytes"] / statistics.median(secs) / 1e6},
        peak_rss_mib_resmr=max(r["resmr"]["peak_rss_mb"] for r in ok),
        peak_rss_mib_time_v=max(r["time_v"]["max_rss_kib"] / 1024 for r in ok
                                if r["time_v"]["max_rss_kib"] is not None),
        cpu_percent=summary([r["time_v"]["cpu_percent"] for r in ok]),
        user_seconds=summary([r["time_v"]["user_seconds"] for r in ok]),
        system_seconds=summary([r["time_v"]["system_seconds"] for r in ok]),
        fractions={k: first[k] for k in first if k.endswith("_fraction")},
    )
    return out


def dd_bandwidth(args, fsync):
    path = os.path.join(args.scratch, "dd.bin")
    count = args.dd_mib // 16
    cmd = ["dd", "if=/dev/zero", f"of={path}", "bs=16M", f"count={count}"]
    if fsync:
        cmd.append("conv=fsync")
    subprocess.run(["sync"])
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    size = os.path.getsize(path) if os.path.exists(path) else 0
    try:
        os.unlink(path)
    except OSError:
        pass
    subprocess.run(["sync"])
    m = re.search(r"(\d+) bytes .* copied, ([\d.]+) s", proc.stderr)
    dd_seconds = float(m.group(2)) if m else wall
    return {"fsync": fsync, "bytes": size, "seconds": dd_seconds, "wall_seconds": round(wall, 3),
            "mb_per_s": size / dd_seconds / 1e6 if dd_seconds else None,
            "dd_line": proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else ""}


# ------------------------------------------------------------------------------- report
def fmt_dims(d):
    return " x ".join(str(x) for x in d)


def fmt_range(values):
    values = [v for v in values if v]
    if not values:
        return "-"
    lo, hi = min(values), max(values)
    return f"{lo:,.0f}" if round(lo) == round(hi) else f"{lo:,.0f} to {hi:,.0f}"


def fmt_mcpm(x):
    return "-" if x is None else f"{x / 1e6:,.1f} M"


def write_report(result, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "synth.json"), "w") as f:
        json.dump(result, f, indent=1)
        f.write("\n")
    m = result["machine"]
    c = result["conditions"]
    dd = result["write_bandwidth"]
    dd_sync = max((d["mb_per_s"] for d in dd if d["fsync"]), default=None)
    lines = [
        "# `resmr synth` write benchmark (synthetic reservoir to EGRID + INIT)",
        "",
        f"Generated by `bench/run_synth_bench.sh` on {m['date_utc']} UTC. Raw numbers: "
        "`synth.json`.",
        "",
        "## Machine and conditions",
        "",
        f"- CPU: {m['cpu']}, {m['nproc']} cores (`nproc`); RAM: {m['ram_gib']} GiB",
        f"- OS: {m['os']}, kernel {m['kernel']}",
        f"- Compiler: {m['compiler']}",
        f"- Measured: {result['version']} (commit `{result['commit_short']}`, "
        f"`{result['commit']}`), `{os.path.relpath(result['resmr'], REPO)}` built "
        f"{result['binary']['mtime_utc']} UTC (sha256 `{result['binary']['sha256'][:12]}`; "
        "the benchmark runs a copy of it taken at the start)",
        f"- Disk: output in `bench/scratch/synth/` on {c['disk']['device']} "
        f"({c['disk']['fstype']}), {c['disk']['free_gb_at_start']:,.0f} GB free at start.",
        f"- Sequential write bandwidth of that disk (`dd if=/dev/zero bs=16M count="
        f"{result['dd_mib'] // 16}`, {result['dd_mib'] / 1024:.0f} GiB, before the resmr runs): "
        f"{fmt_range([d['mb_per_s'] for d in dd if d['fsync']])} MB/s with `conv=fsync`, "
        f"{fmt_range([d['mb_per_s'] for d in dd if not d['fsync']])} MB/s without (page cache "
        "only). The disk is a virtual one and varies from run to run; the % column below is "
        f"of the best fsync run ({'-' if dd_sync is None else f'{dd_sync:,.0f}'} MB/s).",
        f"- Load average at start: {m['loadavg_at_start']}; at end: {c['loadavg_at_end']}. "
        f"Other CPU users at start: {', '.join(c['busy_at_start']) or 'none'}; at end: "
        f"{', '.join(c['busy_at_end']) or 'none'}.",
        "",
        "## What is measured",
        "",
        f"- One process per run: `/usr/bin/time -v resmr synth NX NY NZ -o FILE.EGRID --quiet "
        f"--seed {result['seed']}` (default model: 6 faults, 25% of columns outside the "
        "outline, 5% pinched, 20% water), one run after the other; the files are deleted and "
        "`sync` run after each. resmr fsyncs every file before renaming it into place, so its "
        "time includes getting the bytes to the disk.",
        "- seconds: resmr's own (model set-up to the last rename, from its JSON line); cells/min "
        "= cells / seconds x 60; MB/s = bytes of all files written (EGRID + INIT (+ UNRST)) / "
        "seconds, 1e6 bytes. Best and median over the runs.",
        "- Peak RSS: resmr's getrusage (`peak_rss_mb`) / `/usr/bin/time -v` Maximum resident "
        "set size, MiB, largest over the runs. CPU% and user + sys from `time -v` (median).",
        "",
        "## Results",
        "",
        "| case | dims | cells (active) | written | runs | seconds best / median | "
        "cells/min best / median | MB/s best (% of dd fsync) | peak RSS resmr / time -v | "
        "CPU% | user + sys s | >= 50 M cells/min |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |",
    ]
    for case in result["cases"]:
        if "seconds" not in case:
            lines.append(f"| {case['label']} | {fmt_dims(case['dims'])} | failed | | "
                         f"{len(case['runs'])} | | | | | | | FAIL |")
            continue
        s = case["seconds"]
        cpm = case["cells_per_minute"]
        mbs = case["mb_per_s"]["best"]
        pct = f" ({100 * mbs / dd_sync:.0f}%)" if dd_sync else ""
        meets = cpm["median"] >= TARGET_CELLS_PER_MINUTE
        meets_best = cpm["best"] >= TARGET_CELLS_PER_MINUTE
        verdict = "yes" if meets else ("best only" if meets_best else "no")
        lines.append(
            f"| {case['label']} | {fmt_dims(case['dims'])} | {case['cells']:,} "
            f"({case['active']:,}) | {case['bytes'] / 1e6:,.0f} MB | {s['n']} | "
            f"{s['best']:.2f} / {s['median']:.2f} | {fmt_mcpm(cpm['best'])} / "
            f"{fmt_mcpm(cpm['median'])} | {mbs:,.0f}{pct} | "
            f"{case['peak_rss_mib_resmr']:,.1f} / {case['peak_rss_mib_time_v']:,.1f} MiB | "
            f"{case['cpu_percent']['median']:.0f}% | "
            f"{case['user_seconds']['median']:.1f} + {case['system_seconds']['median']:.1f} | "
            f"{verdict} |")
    if result.get("nz_sweep"):
        lines += ["", "## Peak RSS against the layer count (one run each)", "",
                  "| dims | cells | seconds | peak RSS resmr / time -v |",
                  "| --- | ---: | ---: | ---: |"]
        for r in result["nz_sweep"]:
            if r["status"] != "ok":
                lines.append(f"| {fmt_dims(r['dims'])} | {r['status']} | | |")
                continue
            lines.append(f"| {fmt_dims(r['dims'])} | {r['cells']:,} | {r['seconds']:.2f} | "
                         f"{r['peak_rss_mib_resmr']:,.1f} / {r['peak_rss_mib_time_v']:,.1f} MiB |")
    lines += ["", "## Targets", ""]
    for check in result["checks"]:
        lines.append(f"- {'PASS' if check['pass'] else 'FAIL'}: {check['what']}")
    lines += ["", "Notes:", ""]
    lines += [f"- {note}" for note in result["notes"]]
    lines.append("")
    with open(os.path.join(out_dir, "synth.md"), "w") as f:
        f.write("\n".join(lines))


# ------------------------------------------------------------------------------- main
def verdict(result, steps):
    """The checks: cells a minute at 1M, 10M and 100M, memory independent of the layer
    count; and the cost of report steps, as a note."""
    by_key = {c["key"]: c for c in result["cases"] if "seconds" in c}
    checks = []
    for k in ("1M", "10M", "100M"):
        c = by_key.get(k)
        if not c:
            continue
        cpm = c["cells_per_minute"]
        checks.append({
            "what": f">= 50 M cells/min to EGRID at {k} ({fmt_dims(c['dims'])}): median "
                    f"{cpm['median'] / 1e6:,.1f} M, best {cpm['best'] / 1e6:,.1f} M cells/min "
                    f"({c['seconds']['median']:.2f} s median over {c['seconds']['n']} runs); "
                    f"peak RSS {c['peak_rss_mib_time_v']:,.1f} MiB",
            "pass": cpm["median"] >= TARGET_CELLS_PER_MINUTE})
    for few, many in (("1000x1000x10", "100M"), ("1M", "100x100x1000")):
        a, b = by_key.get(few), by_key.get(many)
        if not (a and b):
            continue
        ra, rb = a["peak_rss_mib_time_v"], b["peak_rss_mib_time_v"]
        checks.append({
            "what": f"O(nx*ny) memory: peak RSS {fmt_dims(a['dims'])} {ra:,.1f} MiB vs "
                    f"{fmt_dims(b['dims'])} (10x the layers) {rb:,.1f} MiB: ratio "
                    f"{rb / ra:.2f}, +{rb - ra:,.1f} MiB (pass: within 1.25x or +8 MiB, the "
                    "calibration sample's fixed cap)",
            "pass": rb <= 1.25 * ra or rb - ra <= 8.0})
    ten, st = by_key.get("10M"), by_key.get("10M+steps10")
    if ten and st:
        extra = st["bytes"] - ten["bytes"]
        dt = st["seconds"]["median"] - ten["seconds"]["median"]
        result["steps_cost"] = {"extra_bytes": extra, "extra_seconds": dt,
                                "seconds_per_step": dt / steps,
                                "mb_per_s_of_steps": extra / dt / 1e6 if dt > 0 else None}
        result["notes"].append(
            f"Report steps: 10M cells with --steps {steps} wrote {st['bytes'] / 1e6:,.0f} MB "
            f"({extra / 1e6:,.0f} MB of UNRST) in {st['seconds']['median']:.2f} s vs "
            f"{ten['seconds']['median']:.2f} s without: {dt:.2f} s more, "
            f"{dt / steps * 1e3:,.0f} ms a step"
            + (f", the UNRST at {extra / dt / 1e6:,.0f} MB/s" if dt > 0 else "") + ".")
    return checks


def explain(result, checks):
    """Notes on where the time goes (CPU against the disk's write bandwidth)."""
    by_key = {c["key"]: c for c in result["cases"] if "seconds" in c}
    big = by_key.get("100M")
    dd_sync = max((d["mb_per_s"] for d in result["write_bandwidth"] if d["fsync"]), default=None)
    if big and dd_sync:
        result["notes"].append(
            f"100M: {big['bytes'] / 1e9:,.2f} GB in {big['seconds']['median']:.1f} s = "
            f"{big['mb_per_s']['median']:,.0f} MB/s median, {100 * big['mb_per_s']['median'] / dd_sync:.0f}% "
            f"of dd's {dd_sync:,.0f} MB/s with fsync; CPU {big['cpu_percent']['median']:.0f}% "
            f"(user {big['user_seconds']['median']:.1f} s + sys {big['system_seconds']['median']:.1f} s).")
    cpu = [c["cpu_percent"]["median"] for c in result["cases"] if c.get("cpu_percent")]
    rates = [c["mb_per_s"]["median"] for c in result["cases"] if c.get("mb_per_s")]
    if cpu and rates and dd_sync:
        result["notes"].append(
            f"Where the time goes: every run kept one core busy ({min(cpu):.0f}-{max(cpu):.0f}% "
            f"CPU, mostly user time) while writing {min(rates):,.0f}-{max(rates):,.0f} MB/s, "
            f"{100 * max(rates) / dd_sync:.0f}% or less of what dd writes to the same disk with "
            "fsync: on this machine the writer is bound by its single-threaded computation of "
            "the model, not by write bandwidth.")
    nz_checks = [ch for ch in checks if ch["what"].startswith("O(nx*ny)")]
    if any(not ch["pass"] for ch in nz_checks):
        result["notes"].append(
            "Peak RSS grows with nz at a fixed nx*ny beyond the calibration sample's fixed cap "
            "(see the sweep): look at SyntheticReservoir::Calibrate, which should keep at most "
            "2^18 values a quantile, and at the per-layer tables (16 bytes a layer).")
    result["notes"].append(
        "Both peak RSS columns agree when resmr's getrusage and time -v see the same process; "
        "time -v's figure is the one taken from outside.")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--resmr", default=os.path.join(REPO, "build", "bin", "resmr"))
    parser.add_argument("--build-dir", default=os.path.join(REPO, "build"),
                        help="for the compiler line of the report")
    parser.add_argument("--scratch", default=os.path.join(HERE, "scratch", "synth"))
    parser.add_argument("--out-dir", default=os.path.join(HERE, "results"))
    parser.add_argument("--repeats", type=int, default=3, help="runs of the 1M and 10M cases")
    parser.add_argument("--repeats-100m", type=int, default=2, help="runs of the 100M case")
    parser.add_argument("--repeats-nz", type=int, default=2,
                        help="runs of the 1000x1000x10 and 100x100x1000 cases")
    parser.add_argument("--dd-mib", type=int, default=4096, help="dd size in MiB (16 MiB blocks)")
    parser.add_argument("--dd-runs", type=int, default=2)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=1200, help="per run, seconds")
    parser.add_argument("--no-100m", action="store_true", help="skip the 100M case (quick check)")
    parser.add_argument("--no-sweep", action="store_true",
                        help="skip the peak RSS vs layer count sweep (100 x 100 x 10 .. 2000)")
    args = parser.parse_args()
    args.resmr = os.path.abspath(args.resmr)
    os.makedirs(args.scratch, exist_ok=True)
    if not os.access(args.resmr, os.X_OK):
        sys.exit(f"{args.resmr}: not built (cmake --build build --target resmr)")
    if not os.access("/usr/bin/time", os.X_OK):
        sys.exit("/usr/bin/time is needed (Debian package 'time')")

    import run_egrid_bench as egrid  # busy_processes()
    binary = snapshot_binary(args)
    result = {
        "machine": common.machine_info(args.build_dir),
        "version": common.git_version(),
        "commit": git_commit(),
        "commit_short": git_commit(short=True),
        "resmr": args.resmr_original,
        "binary": binary,
        "seed": args.seed,
        "dd_mib": args.dd_mib,
        "target_cells_per_minute": TARGET_CELLS_PER_MINUTE,
        "conditions": {"busy_at_start": egrid.busy_processes(), "disk": disk_info(args.scratch)},
        "cases": [],
        "notes": [],
    }

    # Disk first, so the dd numbers come from the same state as the first resmr run.
    result["write_bandwidth"] = []
    for i in range(args.dd_runs):
        for fsync in (True, False):
            print(f"dd {args.dd_mib} MiB, {'fsync' if fsync else 'no fsync'} ({i + 1})",
                  file=sys.stderr)
            result["write_bandwidth"].append(dd_bandwidth(args, fsync))
            print(f"  {result['write_bandwidth'][-1]['mb_per_s']:,.0f} MB/s", file=sys.stderr)

    repeats = {"size": args.repeats, "size_100m": args.repeats_100m, "nz": args.repeats_nz}
    for key, label, dims, group in CASES:
        if group == "size_100m" and args.no_100m:
            continue
        runs = []
        for i in range(repeats[group]):
            print(f"{label} ({fmt_dims(dims)}), run {i + 1}/{repeats[group]}", file=sys.stderr)
            runs.append(run_synth(args, dims, tag=key))
            r = runs[-1]
            if r["status"] == "ok":
                print(f"  {r['resmr']['seconds']:.2f} s, "
                      f"{r['resmr']['cells_per_minute'] / 1e6:,.1f} M cells/min, "
                      f"RSS {r['time_v']['max_rss_kib'] / 1024:,.1f} MiB", file=sys.stderr)
            else:
                print(f"  {r['status']}: {r.get('stderr_tail', '')[-300:]}", file=sys.stderr)
        result["cases"].append(case_result(key, label, dims, 0, runs))

    key, label, dims, steps = STEPS_CASE
    print(f"{label} ({fmt_dims(dims)})", file=sys.stderr)
    r = run_synth(args, dims, steps=steps, tag="steps")
    result["cases"].append(case_result(key, label, dims, steps, [r]))

    result["nz_sweep"] = []
    if not args.no_sweep:
        for dims in NZ_SWEEP:
            print(f"nz sweep {fmt_dims(dims)}", file=sys.stderr)
            r = run_synth(args, dims, tag="sweep")
            result["nz_sweep"].append({
                "dims": list(dims), "status": r["status"],
                "cells": r.get("resmr", {}).get("cells"),
                "seconds": r.get("resmr", {}).get("seconds"),
                "peak_rss_mib_resmr": r.get("resmr", {}).get("peak_rss_mb"),
                "peak_rss_mib_time_v": (r["time_v"]["max_rss_kib"] or 0) / 1024})

    os.unlink(binary["run_copy"])
    if os.path.exists(args.resmr_original) and sha256(args.resmr_original) != binary["sha256"]:
        result["notes"].append(
            f"{os.path.relpath(args.resmr_original, REPO)} was rebuilt during the benchmark; "
            f"every run used the copy taken at the start (sha256 {binary['sha256'][:12]}).")

    result["conditions"]["loadavg_at_end"] = " ".join(f"{x:.2f}" for x in os.getloadavg())
    result["conditions"]["busy_at_end"] = egrid.busy_processes()
    result["machine"]["date_utc"] = datetime.datetime.now(datetime.timezone.utc).strftime(
        "%Y-%m-%d %H:%M")

    checks = result["checks"] = verdict(result, steps)
    explain(result, checks)
    write_report(result, args.out_dir)
    print(f"wrote {os.path.join(args.out_dir, 'synth.md')} and synth.json", file=sys.stderr)


if __name__ == "__main__":
    main()
