"""Shared timing/RSS reporting for the peer parsers (one JSON line on stdout)."""

import json
import resource
import sys
import time


def peak_rss_bytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # Linux: KiB


def run(tool, version, parse, describe=None):
    """Times parse(path) once and prints {"tool", "version", "seconds", "peak_rss_bytes"...}."""
    path = sys.argv[1]
    rss_before = peak_rss_bytes()  # interpreter + imports, before any parsing
    start = time.perf_counter()
    result = parse(path)
    seconds = time.perf_counter() - start
    record = {
        "tool": tool,
        "version": version,
        "seconds": round(seconds, 3),
        "peak_rss_bytes": peak_rss_bytes(),
        "rss_before_parse_bytes": rss_before,
    }
    if describe:
        record.update(describe(result))
    print(json.dumps(record), flush=True)
