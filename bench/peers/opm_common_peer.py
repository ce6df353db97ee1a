#!/usr/bin/python3
"""Peer: OPM's deck parser (Debian python3-opm-common), run with Debian's /usr/bin/python3.

    /usr/bin/python3 bench/peers/opm_common_peer.py DECK

Parses the whole deck (every keyword, into opm::Deck items) with unknown keywords ignored.
"""

import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _peer  # noqa: E402

from opm.io.parser import ParseContext, Parser, action  # noqa: E402


def version():
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "python3-opm-common"],
                             capture_output=True, text=True, check=True).stdout
        return "python3-opm-common " + out.strip()
    except (OSError, subprocess.CalledProcessError):
        return "opm-common (unknown version)"


def parse(path):
    context = ParseContext([
        ("PARSE_UNKNOWN_KEYWORD", action.ignore),
        ("PARSE_RANDOM_TEXT", action.ignore),
        ("PARSE_RANDOM_SLASH", action.ignore),
        ("PARSE_MISSING_DIMS_KEYWORD", action.ignore),
        ("PARSE_EXTRA_RECORDS", action.ignore),
    ])
    return Parser().parse(path, context)


def describe(deck):
    return {"keywords": len(deck), "parsed": "whole deck (all keywords)"}


if __name__ == "__main__":
    _peer.run("opm-common Parser", version(), parse, describe)
