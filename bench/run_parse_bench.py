#!/usr/bin/env python3
"""Runs the GRDECL parse benchmark: resmr and its peers on the same deck, in one run.

Called by bench/run_parse_bench.sh (which builds and generates the deck); see there.
Writes OUT_DIR/grdecl_parse.json and OUT_DIR/grdecl_parse.md.

Every tool runs as its own process, one after the other, under the same caps: an address
space limit (--mem-limit-gb, RLIMIT_AS) and a wall-clock limit (--timeout). A tool that hits
either is recorded as such, with the peak RSS it had reached (from wait4), instead of failing
the run. The deck is read once before the first tool, so every tool reads it from a warm
page cache.
"""

import argparse
import datetime
import json
import os
import platform
import resource
import signal
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


# ------------------------------------------------------------------------------- machine
def read_first(path, prefix):
    try:
        with open(path) as f:
            for line in f:
                if line.startswith(prefix):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def os_name():
    try:
        with open("/etc/os-release") as f:
            for line in f:
                if line.startswith("PRETTY_NAME="):
                    return line.split("=", 1)[1].strip().strip('"')
    except OSError:
        pass
    return platform.platform()


def cmake_cache(build_dir, key):
    try:
        with open(os.path.join(build_dir, "CMakeCache.txt")) as f:
            for line in f:
                if line.startswith(key + ":"):
                    return line.split("=", 1)[1].strip()
    except OSError:
        pass
    return ""


def compiler_info(build_dir):
    cxx = cmake_cache(build_dir, "CMAKE_CXX_COMPILER") or "c++"
    try:
        first = subprocess.run([cxx, "--version"], capture_output=True, text=True).stdout
        first = first.splitlines()[0]
    except (OSError, IndexError):
        first = cxx
    build_type = cmake_cache(build_dir, "CMAKE_BUILD_TYPE") or "?"
    flags = cmake_cache(build_dir, "CMAKE_CXX_FLAGS_" + build_type.upper())
    return f"{first} ({build_type}: {flags})".replace(" ()", "")


def machine_info(build_dir):
    mem_kb = read_first("/proc/meminfo", "MemTotal")
    return {
        "cpu": read_first("/proc/cpuinfo", "model name"),
        "nproc": os.cpu_count(),
        "ram_gib": round(int(mem_kb.split()[0]) / 2**20, 1) if mem_kb != "unknown" else None,
        "os": os_name(),
        "kernel": platform.release(),
        "compiler": compiler_info(build_dir),
        "python": platform.python_version(),
        "loadavg_at_start": " ".join(f"{x:.2f}" for x in os.getloadavg()),
        "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
    }


def git_version():
    try:
        head = subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", REPO, "status", "--porcelain", "--", "Core"],
                               capture_output=True, text=True).stdout.strip()
        return f"resmr git {head}" + ("+local Core changes" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "resmr"


# ------------------------------------------------------------------------------- running
def run_capped(cmd, timeout, mem_limit_bytes):
    """Runs cmd with RLIMIT_AS and a wall-clock limit. Returns a dict with stdout, stderr,
    returncode, wall seconds, peak RSS (wait4, bytes) and status."""

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (mem_limit_bytes, mem_limit_bytes))

    out_path = f"/tmp/resmr_bench_{os.getpid()}.out"
    err_path = f"/tmp/resmr_bench_{os.getpid()}.err"
    with open(out_path, "w") as out, open(err_path, "w") as err:
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=out, stderr=err, preexec_fn=limit,
                                start_new_session=True)
        status = None
        timed_out = False
        while status is None:
            pid, wait_status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid == proc.pid:
                status = wait_status
                break
            if time.perf_counter() - start > timeout:
                timed_out = True
                os.killpg(proc.pid, signal.SIGKILL)  # the group of the process started here
                pid, status, usage = os.wait4(proc.pid, 0)
                break
            time.sleep(0.2)
        wall = time.perf_counter() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
    with open(out_path) as f:
        stdout = f.read()
    with open(err_path) as f:
        stderr = f.read()
    os.unlink(out_path)
    os.unlink(err_path)
    result = {"returncode": proc.returncode, "wall_seconds": round(wall, 3),
              "peak_rss_bytes_wait4": usage.ru_maxrss * 1024, "stdout": stdout,
              "stderr_tail": stderr[-1500:]}
    if timed_out:
        result["status"] = f"timeout: killed after {timeout:.0f} s"
    elif proc.returncode == 0:
        result["status"] = "ok"
    elif "MemoryError" in stderr or "bad_alloc" in stderr or "Cannot allocate" in stderr:
        result["status"] = f"out of memory under the {mem_limit_bytes / 1e9:.0f} GB cap"
    else:
        result["status"] = f"failed (exit {proc.returncode})"
    return result


def json_lines(text):
    records = []
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("{"):
            try:
                records.append(json.loads(line))
            except json.JSONDecodeError:
                pass
    return records


def warm_cache(path):
    start = time.perf_counter()
    with open(path, "rb", buffering=0) as f:
        while f.read(1 << 24):
            pass
    return time.perf_counter() - start


# ------------------------------------------------------------------------------- report
def fmt_bytes(n):
    return "-" if n is None else f"{n / 2**20:,.0f} MiB"


def write_report(result, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "grdecl_parse.json"), "w") as f:
        json.dump(result, f, indent=1)
        f.write("\n")

    m = result["machine"]
    d = result["deck"]
    lines = [
        "# GRDECL parse benchmark",
        "",
        f"Generated by `bench/run_parse_bench.sh` on {m['date_utc']} UTC. "
        "Raw numbers: `grdecl_parse.json`.",
        "",
        "## Machine",
        "",
        f"- CPU: {m['cpu']}, {m['nproc']} cores; RAM: {m['ram_gib']} GiB",
        f"- OS: {m['os']}, kernel {m['kernel']}",
        f"- Compiler: {m['compiler']}",
        f"- Python (driver): {m['python']}; load average at start: {m['loadavg_at_start']} "
        "(every tool is single-threaded here; other work on the machine shares its cores)",
        "",
        "## Deck",
        "",
        f"- `{d['name']}`: {d['bytes']:,} bytes ({d['bytes'] / 1e9:.3f} GB) of ASCII GRDECL, "
        f"{d.get('cells', 0):,} cells ({d.get('dims', '?')}), generated by "
        "`bench/make_tiled_deck.py`: the Reek grid (xtgeo test data, 40 x 64 x 14) tiled in "
        "I and J; keywords SPECGRID, COORD, ZCORN, ACTNUM (N*value runs), PORO, PERMX, "
        "FAULTS.",
        f"- Page cache: warm. The deck was read once before the first tool "
        f"({d['warm_read_seconds']:.1f} s), and the machine's RAM holds it, so every tool "
        "reads it from the page cache; the numbers measure parsing, not the disk.",
        f"- Caps for every tool: {result['caps']['mem_limit_gb']:.0f} GB address space "
        f"(RLIMIT_AS), {result['caps']['timeout_s']:.0f} s wall clock.",
        "",
        "## Results",
        "",
        "MB/s = deck bytes / parse seconds / 1e6 (every tool reads the whole file). Peak RSS "
        "is the process's (VmHWM / ru_maxrss), interpreter and imports included for the "
        "Python peers. Output size = values the tool keeps from the deck at 8 bytes each "
        "(all arrays for resmr and OPM; COORD + ZCORN + ACTNUM for the geometry-only "
        "loaders xtgeo and resdata, whatever precision they store them in).",
        "",
        "| tool | version | status | seconds | MB/s | peak RSS | output size | RSS / output |",
        "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    for row in result["tools"]:
        secs = row.get("seconds")
        mbs = row.get("mb_per_s")
        ratio = row.get("rss_over_output")
        lines.append(
            f"| {row['tool']} | {row['version']} | {row['status']} | "
            f"{'-' if secs is None else f'{secs:.2f}'} | {'-' if mbs is None else f'{mbs:.0f}'} | "
            f"{fmt_bytes(row.get('peak_rss_bytes'))} | {fmt_bytes(row.get('output_bytes'))} | "
            f"{'-' if ratio is None else f'{ratio:.2f}x'} |")
    lines.append("")
    ours = result["tools"][0]
    if ours.get("runs"):
        lines.append(f"resmr: median of {len(ours['runs'])} runs in one process (each run's "
                     "deck freed before the next); per run: " +
                     ", ".join(f"{r['seconds']:.2f} s" for r in ours["runs"]) + ".")
        lines.append("")
    lines.append("## Targets")
    lines.append("")
    for check in result["checks"]:
        lines.append(f"- {'PASS' if check['pass'] else 'FAIL'}: {check['what']}")
    lines.append("")
    lines.append("Notes:")
    lines.append("")
    for note in result["notes"]:
        lines.append(f"- {note}")
    lines.append("")
    with open(os.path.join(out_dir, "grdecl_parse.md"), "w") as f:
        f.write("\n".join(lines))


# ------------------------------------------------------------------------------- main
def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--deck", required=True)
    parser.add_argument("--bench-exe", required=True)
    parser.add_argument("--build-dir", required=True)
    parser.add_argument("--venv-python", default="")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--timeout", type=float, default=900)
    parser.add_argument("--mem-limit-gb", type=float, default=20)
    parser.add_argument("--out-dir", default=os.path.join(HERE, "results"))
    parser.add_argument("--skip", nargs="*", default=[], help="peer names to skip")
    args = parser.parse_args()

    mem_limit = int(args.mem_limit_gb * 1e9)
    deck_bytes = os.path.getsize(args.deck)
    print(f"deck {args.deck}: {deck_bytes:,} bytes; warming the page cache", file=sys.stderr)
    warm = warm_cache(args.deck)

    result = {
        "machine": machine_info(args.build_dir),
        "deck": {"name": os.path.basename(args.deck), "bytes": deck_bytes,
                 "warm_read_seconds": round(warm, 2)},
        "caps": {"mem_limit_gb": args.mem_limit_gb, "timeout_s": args.timeout},
        "tools": [],
        "notes": [],
    }

    # resmr
    print(f"resmr: {args.runs} runs", file=sys.stderr)
    run = run_capped([args.bench_exe, args.deck, str(args.runs)], args.timeout, mem_limit)
    runs = [r for r in json_lines(run["stdout"]) if "seconds" in r]
    row = {"tool": "resmr ParseGrdeclFile", "version": git_version(), "status": run["status"],
           "runs": runs, "peak_rss_bytes": run["peak_rss_bytes_wait4"]}
    if runs:
        secs = sorted(r["seconds"] for r in runs)[len(runs) // 2]
        row.update(seconds=secs, mb_per_s=deck_bytes / secs / 1e6,
                   output_bytes=runs[0]["output_bytes"],
                   peak_rss_bytes=max(r["peak_rss_bytes"] for r in runs))
        row["rss_over_output"] = row["peak_rss_bytes"] / row["output_bytes"]
        result["deck"]["cells"] = runs[0]["cells"]
    if run["status"] != "ok":
        row["stderr_tail"] = run["stderr_tail"]
    result["tools"].append(row)
    geometry_bytes = runs[0]["geometry_bytes"] if runs else None
    all_bytes = runs[0]["output_bytes"] if runs else None
    with open(args.deck) as f:  # dims, from the SPECGRID near the top
        head = f.read(4096).split("SPECGRID", 1)
        if len(head) == 2:
            result["deck"]["dims"] = " x ".join(head[1].split()[:3])

    # peers
    peers = [
        ("opm", "/usr/bin/python3", "opm_common_peer.py", all_bytes),
        ("resdata", args.venv_python, "resdata_peer.py", geometry_bytes),
        ("xtgeo", args.venv_python, "xtgeo_peer.py", geometry_bytes),
    ]
    for name, python, script, output_bytes in peers:
        if name in args.skip:
            continue
        if not python or not os.path.exists(python):
            result["notes"].append(f"{name}: not run, no Python at '{python}'.")
            continue
        print(f"{name}: 1 run", file=sys.stderr)
        run = run_capped([python, os.path.join(HERE, "peers", script), args.deck],
                         args.timeout, mem_limit)
        records = json_lines(run["stdout"])
        rec = records[-1] if records else {}
        row = {"tool": rec.get("tool", name), "version": rec.get("version", "?"),
               "status": run["status"], "output_bytes": output_bytes,
               "peak_rss_bytes": rec.get("peak_rss_bytes", run["peak_rss_bytes_wait4"]),
               "rss_before_parse_bytes": rec.get("rss_before_parse_bytes"),
               "wall_seconds_process": run["wall_seconds"], "parsed": rec.get("parsed")}
        if "seconds" in rec:
            row.update(seconds=rec["seconds"], mb_per_s=deck_bytes / rec["seconds"] / 1e6)
        elif run["status"].startswith("timeout"):
            # Partial info: it had not finished after the whole limit.
            row["mb_per_s_upper_bound"] = deck_bytes / args.timeout / 1e6
        if output_bytes:
            row["rss_over_output"] = row["peak_rss_bytes"] / output_bytes
        if run["status"] != "ok":
            row["stderr_tail"] = run["stderr_tail"]
        result["tools"].append(row)
        print(f"  {row['status']} {row.get('seconds')} s", file=sys.stderr)

    # verdict
    ours = result["tools"][0]
    peers_done = [t for t in result["tools"][1:]]
    ok = ours.get("mb_per_s") is not None
    result["checks"] = [
        {"what": f"resmr >= 150 MB/s on a >= 1 GB deck ({ours.get('mb_per_s', 0):.0f} MB/s, "
                 f"{deck_bytes / 1e9:.2f} GB)",
         "pass": ok and ours["mb_per_s"] >= 150 and deck_bytes >= 1e9},
        {"what": "resmr faster than every peer measured (" + ", ".join(
            f"{t['tool']}: " + (f"{t['mb_per_s']:.0f} MB/s" if "mb_per_s" in t else t["status"])
            for t in peers_done) + ")",
         "pass": ok and all(t.get("mb_per_s", t.get("mb_per_s_upper_bound", 0)) <
                            ours["mb_per_s"] for t in peers_done)},
        {"what": f"resmr peak RSS <= 1.5x its output ({ours.get('rss_over_output', 0):.2f}x)",
         "pass": ok and ours["rss_over_output"] <= 1.5},
    ]
    for t in peers_done:
        if t.get("parsed"):
            result["notes"].append(f"{t['tool']} parses: {t['parsed']}; peak RSS before "
                                   f"parsing (interpreter + imports): "
                                   f"{fmt_bytes(t.get('rss_before_parse_bytes'))}.")
        if t["status"] != "ok":
            result["notes"].append(f"{t['tool']}: {t['status']}; "
                                   f"peak RSS reached {fmt_bytes(t['peak_rss_bytes'])}.")
    write_report(result, args.out_dir)
    print(open(os.path.join(args.out_dir, "grdecl_parse.md")).read())


if __name__ == "__main__":
    main()
