#!/usr/bin/env python3
"""Lists product functions longer than a limit (default 150 lines).

    scripts/function_lengths.py [--limit 150] [--all]

A function is a definition whose signature starts in column 0 or at one
level of indentation inside a namespace/class (C++ as the project writes it,
clang-format'ed); its length runs from the signature's first line to the
closing brace. Tests (*_test.cc), benchmarks, fuzzers and tests/ are not
product code. A function may stay longer when a comment line directly above
its signature says why, starting with "// Long:" (listed, not counted as a
violation). Exit 1 when a function is over the limit without a reason or any
function is over 200 lines.
"""
import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FOLDERS = ["data", "camcal", "calib", "vision", "plan", "synth", "bundle",
           "diagnose", "capture", "report", "app"]
SIGNATURE = re.compile(r"^(?:  )?(?!(?:if|for|while|switch|return|else|do)\b)"
                       r"[A-Za-z_~][\w:<>,*&\s~]*\b([A-Za-z_~][\w:~]*)\s*\(")


def strip(line):
    """The line without string, char literals and // comments."""
    line = re.sub(r'"(?:\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(?:\\.|[^'\\])*'", "''", line)
    return line.split("//", 1)[0]


def functions(path):
    lines = open(path, encoding="utf-8", errors="replace").read().split("\n")
    i, n = 0, len(lines)
    while i < n:
        m = SIGNATURE.match(lines[i])
        if not m or lines[i].rstrip().endswith(";"):
            i += 1
            continue
        # The signature ends at the first "{" before any ";".
        j, text = i, ""
        while j < n and j < i + 12:
            text += strip(lines[j])
            if "{" in text or ";" in text:
                break
            j += 1
        if "{" not in text or (";" in text and text.index(";") < text.index("{")):
            i += 1
            continue
        depth, k = 0, i
        started = False
        while k < n:
            for ch in strip(lines[k]):
                if ch == "{":
                    depth += 1
                    started = True
                elif ch == "}":
                    depth -= 1
            if started and depth <= 0:
                break
            k += 1
        reason = i > 0 and lines[i - 1].strip().startswith("// Long:")
        if k - i + 1 > 3:
            yield m.group(1), i + 1, k - i + 1, reason
        i = k + 1


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--limit", type=int, default=150)
    ap.add_argument("--all", action="store_true", help="list every function")
    args = ap.parse_args()
    rows = []
    for folder in FOLDERS:
        for dirpath, _, files in os.walk(os.path.join(ROOT, folder)):
            for f in sorted(files):
                if not f.endswith(".cc") or f.endswith("_test.cc"):
                    continue
                p = os.path.join(dirpath, f)
                for name, line, length, reason in functions(p):
                    rows.append((length, os.path.relpath(p, ROOT), line, name, reason))
    rows.sort(reverse=True)
    bad = 0
    for length, path, line, name, reason in rows:
        if length <= args.limit and not args.all:
            continue
        flag = ""
        if length > 200:
            flag, bad = "  OVER 200", bad + 1
        elif length > args.limit:
            flag = "  (reason beside it)" if reason else "  OVER LIMIT"
            bad += 0 if reason else 1
        print(f"{length:5d}  {path}:{line}  {name}{flag}")
    print(f"{bad} function(s) over the limit without a reason")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
