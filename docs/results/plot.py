#!/usr/bin/python3
"""Regenerates docs/results/transmittance.csv and the transmittance_*.png charts of docs/results.md.

    /usr/bin/python3 docs/results/plot.py [BUILD_DIR] [SEGMENTS] [ESTIMATES]   (defaults: build 200 1000)
    /usr/bin/python3 docs/results/plot.py --from-csv docs/results/transmittance.csv   (the charts only)

Runs BUILD_DIR/bench/transmittance (see bench/transmittance.c), keeps its CSV, and draws per scene the
error of the mean of n estimates, sqrt(bias^2 + var / n) averaged over the channels' MSE, against the
density lookups (n x lookups per estimate) and against the time (n x time per estimate) it costs.
A biased estimator's curve flattens at its floor sqrt(bias^2). After a measurement (not with --from-csv) it
also writes results.md's two tables of it between their markers (tools/mdsplice.py): lookups and efficiency
per estimator ("transmittance table") and the raymarch baselines' bias floors ("transmittance bias floor").
Debian's python3-matplotlib."""
import csv
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "tools"))
import pngmeta  # noqa: E402 (tools/pngmeta.py: the murk:commit text key)
from mdsplice import splice  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
# MURK_DOCS_DIR (tools/docs.sh): write the CSV and charts into MURK_DOCS_DIR/results instead of docs/results
if os.environ.get("MURK_DOCS_DIR"):
    here = os.path.join(os.environ["MURK_DOCS_DIR"], "results")
    os.makedirs(here, exist_ok=True)
if len(sys.argv) > 2 and sys.argv[1] == "--from-csv":  # redraw the charts from a CSV measured before
    with open(sys.argv[2]) as f:
        out = f.read()
    nseg, nest = "200", "1000"
else:
    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "build")
    nseg = sys.argv[2] if len(sys.argv) > 2 else "200"
    nest = sys.argv[3] if len(sys.argv) > 3 else "1000"
    run = subprocess.run([os.path.join(build, "bench", "transmittance"), nseg, nest], check=True,
                         capture_output=True, text=True)
    out = run.stdout
    with open(os.path.join(here, "transmittance.csv"), "w") as f:
        f.write(out)
rows = list(csv.DictReader(out.splitlines()))
# one colour and one marker per estimator, never shared: tab10's ten colours, then tab20's darker half;
# solid lines for the unbiased estimators, dashed for the biased raymarch baselines
COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:gray",
           "tab:olive", "tab:cyan", "k", "navy", "darkgoldenrod", "teal"]
MARKERS = ["o", "s", "^", "v", "D", "P", "X", "*", "<", ">", "h", "p", "d", "8"]
names = list(dict.fromkeys(r["estimator"] for r in rows))
styles = {nm: (COLOURS[i % len(COLOURS)], "--" if nm.startswith("raymarch") else "-", MARKERS[i % len(MARKERS)])
          for i, nm in enumerate(names)}
for scene in dict.fromkeys(r["scene"] for r in rows):
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    for r in (r for r in rows if r["scene"] == scene):
        name = r["estimator"]
        var = sum(float(r["var_" + c]) for c in "rgb") / 3
        # bias^2 is resolved only down to ~var / ESTIMATES: drawn for the biased baseline, 0 for the
        # unbiased estimators (whose measured bias^2 is at that noise level; see the CSV)
        b2 = sum(float(r["bias2_" + c]) for c in "rgb") / 3 if name.startswith("raymarch") else 0.0
        L, ns = max(float(r["lookups"]), 1e-3), float(r["ns"])
        n = [2 ** (k / 4) for k in range(0, 4 * 20 + 1)]
        err = [(b2 + var / k) ** 0.5 for k in n]
        color, ls, mk = styles[name]
        label = name + (" (BIASED)" if name.startswith("raymarch") else "")
        kw = dict(color=color, ls=ls, marker=mk, markevery=8, markersize=6, lw=1.6, label=label)
        axes[0].loglog([k * L for k in n], err, **kw)
        axes[1].loglog([k * ns * 1e-3 for k in n], err, **kw)
    axes[0].set_xlabel("density lookups spent on one segment", fontsize=11)
    axes[1].set_xlabel("time spent on one segment (us, one thread)", fontsize=11)
    for ax in axes:
        ax.tick_params(labelsize=10)
        ax.set_ylabel("RMSE of the mean transmittance", fontsize=11)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_xlim(1, 1e5)
    axes[1].set_xlim(0.1, 1e4)
    axes[1].legend(fontsize=9, loc="lower left")
    fig.suptitle(f"{scene}: shadow-ray transmittance, error vs cost (bench/transmittance, {nseg} segments x {nest})")
    fig.tight_layout()
    fig.savefig(os.path.join(here, f"transmittance_{scene}.png"), dpi=90, metadata=pngmeta.metadata())
    plt.close(fig)


SHORT = {"cornell_smoke": "smoke", "dense_cloud": "dense", "chromatic_smoke": "chromatic"}
LABELS = {"ratio": "`ratio`", "residual_ratio": "`residual_ratio` (control 1)", "track_length": "`track_length`",
          "unbiased_raymarch": "`unbiased_raymarch` (depth_step 1, order 1)",
          "unbiased_raymarch_ds4": "`unbiased_raymarch` depth_step 4",
          "unbiased_raymarch_ds0.25": "`unbiased_raymarch` depth_step 0.25",
          "power_series": "`power_series` (chunk_depth 4)", "power_series_cd1": "`power_series` chunk_depth 1",
          "power_series_cd16": "`power_series` chunk_depth 16"}


def label(name):
    if name.startswith("raymarch_"):
        return "`raymarch` step %s (**BIASED**)" % name.split("_", 1)[1]
    return LABELS.get(name, "`%s`" % name)


def sci(x, spec="%.1e"):
    """3.9e-3, not 3.9e-03."""
    return (spec % x).replace("e-0", "e-").replace("e+0", "e+").replace("e+", "e")


def eff(x):
    """An efficiency ratio: three significant digits, whole numbers from 1000 on."""
    return "%.0f" % x if x >= 1000 else "%.3g" % x


def fmt(spec, x):
    return spec(x) if callable(spec) else spec % x


def tables(rows, nseg, nest, mean_t):
    """results.md's two generated blocks: the table of lookups and efficiencies, and the bias floors."""
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    at = {(r["scene"], r["estimator"]): r for r in rows}
    head = ", ".join(SHORT.get(sc, sc) for sc in scenes)
    cols = (("lookups", "lookups / estimate", "%.1f"), ("eff_lookups", "efficiency in lookups vs ratio", eff),
            ("eff_time", "efficiency in time vs ratio", eff))
    t = ["| estimator | " + " | ".join("%s (%s)" % (c[1], head) for c in cols) + " |", "|---" * (1 + len(cols)) + "|"]
    for nm in dict.fromkeys(r["estimator"] for r in rows):
        t.append("| %s | " % label(nm) + " | ".join(", ".join(fmt(c[2], float(at[sc, nm][c[0]])) for sc in scenes)
                                                   for c in cols) + " |")
    t += ["", "`bench/transmittance %s %s`: %s segments per scene, %s estimates per segment%s.\nFor `raymarch` "
          "the efficiency is that of one estimate; its error floor is below." % (
              nseg, nest, nseg, nest, ";\nmean reference transmittance " + ", ".join(
                  "%.2g" % mean_t[sc] for sc in scenes) if all(sc in mean_t for sc in scenes) else "")]
    f = ["| raymarch step | bias floor sqrt(bias²) of the worst channel, " + " | ".join(SHORT.get(sc, sc) for sc in scenes)
         + " |", "|---" * (1 + len(scenes)) + "|"]
    for nm in (n for n in dict.fromkeys(r["estimator"] for r in rows) if n.startswith("raymarch_")):
        cells = []
        for sc in scenes:
            r = at[sc, nm]
            c = max("rgb", key=lambda c: float(r["bias2_" + c]))
            b2, var = float(r["bias2_" + c]), float(r["var_" + c])
            # bias^2 at most half the variance of the mean of the estimates is within the measurement's noise
            if b2 == 0:  # the measured bias² was below the noise of its estimate: transmittance.c clamps it
                cells.append("0 (below the measurement's noise)")
            elif b2 <= 0.5 * var / float(nest):
                cells.append("≤ %s (at the measurement's noise)" % sci(b2 ** 0.5, "%.0e"))
            else:
                cells.append(sci(b2 ** 0.5))
        f.append("| %s | %s |" % (nm.split("_", 1)[1], " | ".join(cells)))
    return "\n".join(t), "\n".join(f)


if len(sys.argv) <= 2 or sys.argv[1] != "--from-csv":  # a measurement: its tables into results.md
    mean_t = {}
    for line in run.stderr.splitlines():  # "cornell_smoke: 200 segments, mean reference T 0.1912"
        if ": " in line and "mean reference T " in line:
            mean_t[line.split(":")[0]] = float(line.rsplit(" ", 1)[1])
    md = os.path.join(os.path.dirname(here), "results.md")
    table, floor = tables(rows, nseg, nest, mean_t)
    splice(md, "transmittance table", "docs/results/plot.py", table)
    splice(md, "transmittance bias floor", "docs/results/plot.py", floor)
print(out, end="")
