#!/usr/bin/env python3
"""Summary of scripts/mukca_compare.sh or mukca_pooled.sh output (TSV on
stdin): per robot, cases, median held-out RMS kincal / authors, how many
cases kincal's RMS <= the authors', median |distance error| kincal /
authors, how many cases kincal's <= the authors'; then all robots.
Markdown table (docs/REAL_DATA.md). NA rows (a failed calibration) count as
losses."""
import statistics
import sys

rows = [l.rstrip("\n").split("\t") for l in sys.stdin if l.strip()]
head, rows = rows[0], rows[1:]
col = {n: i for i, n in enumerate(head)}


def num(r, name):
    try:
        return float(r[col[name]])
    except ValueError:
        return float("nan")


by = {}
for r in rows:
    by.setdefault(r[0], []).append(r)
print("| robot | cases | median RMS kincal / authors | kincal RMS <= authors "
      "| median abs distance error kincal / authors | kincal <= authors |")
print("| --- | --- | --- | --- | --- | --- |")


def line(name, rs):
    kr = [num(r, "kincal_rms") for r in rs]
    ar = [num(r, "authors_rms") for r in rs]
    kd = [abs(num(r, "kincal_dist_err")) for r in rs]
    ad = [abs(num(r, "authors_dist_err")) for r in rs]
    win_r = sum(1 for k, a in zip(kr, ar) if k <= a)
    win_d = sum(1 for k, a in zip(kd, ad) if k <= a)
    med = lambda v: statistics.median([x for x in v if x == x] or [float("nan")])
    print("| %s | %d | %.3f / %.3f | %d | %.3f / %.3f | %d |" %
          (name, len(rs), med(kr), med(ar), win_r, med(kd), med(ad), win_d))


for robot in sorted(by):
    line(robot, by[robot])
line("all", rows)
