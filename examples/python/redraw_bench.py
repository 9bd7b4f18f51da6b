#!/usr/bin/env python3
"""Redraw one of the benchmark's work-precision figures with matplotlib, from its CSV.

Every figure of `rotor bench --svg bench.svg` has its data beside it: `bench-<scene>.csv`
holds one row per point (runner, setting, median run time, steady-state and transient errors,
and whether the point passes the scene's loose gate). This script draws the same two panels
as `bench-<scene>.svg`: error against run time, log-log, one line per runner, filled markers
where the loose gate passes and open ones where it fails. Only matplotlib is needed (no
rotorbench); run from anywhere:

    python3 examples/python/redraw_bench.py reports/bench/bench-t1-u1.5-rest.csv [out.png]
"""

import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402

MARKERS = "osD^v<>ph*"


def read(path):
    """Rows per runner, in the file's order: (time, steady, transient, passes)."""
    runners = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            num = lambda k: float(row[k]) if row[k] else None  # noqa: E731
            runners.setdefault(row["runner"], []).append(
                (num("time_s"), num("steady_rel"), num("transient_max"), row["passes_loose"] != "false")
            )
    return runners


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: redraw_bench.py BENCH-SCENE.csv [OUT.png]")
    src = Path(sys.argv[1])
    out = Path(sys.argv[2]) if len(sys.argv) > 2 else Path(src.stem + ".png")
    runners = read(src)
    fig, axes = plt.subplots(2, 1, figsize=(7.6, 8.8), constrained_layout=True)
    labels = [
        (1, r"max$(|\Delta T|/T,\ |\Delta \max\omega_l|/\max\omega_l)$"),
        (2, r"max $|\Delta\omega_l|$ [rad/s]"),
    ]
    for ax, (k, ylabel) in zip(axes, labels):
        for i, (name, pts) in enumerate(runners.items()):
            pts = [p for p in pts if p[k] is not None and p[k] > 0]
            if not pts:
                continue
            (line,) = ax.loglog([p[0] for p in pts], [p[k] for p in pts], label=name,
                                marker=MARKERS[i % len(MARKERS)], markersize=4)
            failing = [p for p in pts if not p[3]]
            ax.loglog([p[0] for p in failing], [p[k] for p in failing], linestyle="none",
                      marker=MARKERS[i % len(MARKERS)], markersize=4,
                      markerfacecolor="white", markeredgecolor=line.get_color())
        ax.set_xlabel("run time [s] (median)")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="major", color="#ddd")
    axes[0].set_title(f"{src.stem}: open markers fail the loose gate", fontsize=10)
    axes[0].legend(ncol=4, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.15))
    fig.savefig(out, dpi=150)
    n = sum(len(p) for p in runners.values())
    print(f"{out}: {len(runners)} runners, {n} points")


if __name__ == "__main__":
    main()
