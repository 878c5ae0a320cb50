#!/usr/bin/python3
"""bench_report.py DIR — the charts and report.md of a `murk bench` run (murk runs it; it reads
DIR/bench.csv, DIR/bench.json and DIR/maps/variantN.npy, written by murk bench).

Charts (PNG and SVG): error_vs_time, error_vs_lookups (log-log, one curve per variant, error bars from
the seeds, the 1/N slope for reference), efficiency (1/(relMSE x seconds) and 1/(relMSE x density
lookups) relative to the first variant, per budget, with error bars) and efficiency_map (which variant
is most efficient per pixel at the largest budget). Needs Debian's python3-matplotlib and python3-numpy.
"""
import csv
import json
import math
import os
import platform
import signal
import sys

import warnings

import matplotlib

matplotlib.use("Agg")
warnings.filterwarnings("ignore", category=RuntimeWarning)  # all-NaN bars of a scene without media
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402


def load_rows(d):
    """DIR/bench.csv: one dict per render, every column but the label a float."""
    with open(os.path.join(d, "bench.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for k in r:
            if k != "label":
                r[k] = float(r[k])
    return rows


def load(d):
    with open(os.path.join(d, "bench.json")) as f:
        meta = json.load(f)
    return meta, load_rows(d)


def mean_se(xs):
    xs = np.asarray(xs, dtype=float)
    if len(xs) < 2:
        return float(xs.mean()), float("nan")
    return float(xs.mean()), float(xs.std(ddof=1) / math.sqrt(len(xs)))


def aggregate(meta, rows):
    """agg[v][budget] = dict of (mean, se) per column over the seeds."""
    agg = {}
    for v in range(len(meta["variants"])):
        agg[v] = {}
        for b in sorted({r["budget"] for r in rows}):
            sel = [r for r in rows if r["variant"] == v and r["budget"] == b]
            if sel:
                agg[v][b] = {k: mean_se([r[k] for r in sel]) for k in
                             ("relmse", "seconds", "lookups", "rays", "relmse_raw", "ref_noise", "spp", "nonfinite",
                              "max_sample", "collisions")}
    return agg


def ratio(a, sa, b, sb):
    """a/b and its standard error (independent a and b, first order)."""
    if not (a > 0 and b > 0):
        return float("nan"), float("nan")
    r = a / b
    return r, r * math.sqrt((sa / a) ** 2 + (sb / b) ** 2)


def efficiency(s, cost):
    """1/(relMSE x cost) with its standard error from relMSE's and the cost's."""
    (e, se), (c, sc) = s["relmse"], s[cost]
    if not (e > 0 and c > 0):
        return float("nan"), float("nan")
    f = 1.0 / (e * c)
    return f, f * math.sqrt((se / e) ** 2 + ((sc if sc == sc else 0) / c) ** 2)


def write_atomic(path, write):
    """write(tmp) fills a temporary beside path, renamed over it when whole; removed if interrupted
    (murk bench passes SIGINT/SIGTERM on: KeyboardInterrupt here), so no chart is ever half-written."""
    tmp = "%s.tmp-%d" % (path, os.getpid())
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def save(fig, d, name, meta=None):
    """PNG and SVG; the PNG carries murk's text keys murk:commit and murk:version (from bench.json)."""
    for ext in ("png", "svg"):
        md = None
        if ext == "png" and meta:
            md = {"murk:commit": str(meta.get("commit", "unknown")), "murk:version": str(meta.get("version", "unknown"))}
        write_atomic(os.path.join(d, name + "." + ext),
                     lambda tmp: fig.savefig(tmp, format=ext, dpi=110, bbox_inches="tight", metadata=md))
    plt.close(fig)


def error_chart(d, meta, agg, cost, xlabel, name):
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    first = None
    empty = True
    for v, label in enumerate(meta["variants"]):
        pts = [(agg[v][b][cost], agg[v][b]["relmse"]) for b in sorted(agg[v])]
        pts = [p for p in pts if p[0][0] > 0 and p[1][0] > 0]
        if not pts:
            continue
        empty = False
        x = [p[0][0] for p in pts]
        y = [p[1][0] for p in pts]
        ax.errorbar(x, y, yerr=[p[1][1] if p[1][1] == p[1][1] else 0 for p in pts],
                    xerr=[p[0][1] if p[0][1] == p[0][1] else 0 for p in pts], marker="o", capsize=3, label=label)
        if first is None:
            first = (x, y)
    if first:
        x0, y0 = first[0][0], first[1][0]
        xs = np.array([min(first[0]), max(first[0])]) * np.array([0.8, 1.25])
        ax.plot(xs, y0 * x0 / xs, "k--", lw=0.8, label="1/N slope")
    if empty:
        ax.text(0.5, 0.5, "nothing to plot: no positive %s or relMSE" % xlabel, ha="center", transform=ax.transAxes)
    else:
        ax.set_xscale("log")
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("relMSE (noise-corrected), mean ± s.e. over seeds")
    ax.grid(True, which="both", alpha=0.3)
    if not empty:
        ax.legend(fontsize=8)
    save(fig, d, name, meta)


def efficiency_chart(d, meta, agg):
    budgets = sorted(agg[0])
    nv = len(meta["variants"])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    unit = "s" if meta["budget"] == "seconds" else "spp"
    for ax, cost, title in ((axes[0], "seconds", "equal time: 1/(relMSE·seconds)"),
                            (axes[1], "lookups", "equal work: 1/(relMSE·density lookups)")):
        w = 0.8 / nv
        for v, label in enumerate(meta["variants"]):
            vals, errs = [], []
            for b in budgets:
                if b not in agg[v]:
                    vals.append(float("nan"))
                    errs.append(0)
                    continue
                e, se = efficiency(agg[v][b], cost)
                e0, se0 = efficiency(agg[0][b], cost)
                r, sr = ratio(e, se, e0, se0) if v else (1.0 if e0 == e0 else float("nan"), 0.0)
                vals.append(r)
                errs.append(sr if sr == sr else 0)
            xs = np.arange(len(budgets)) + (v - (nv - 1) / 2) * w
            ax.bar(xs, vals, w, yerr=errs, capsize=3, label=label)
        ax.axhline(1.0, color="k", lw=0.8)
        ax.set_xticks(np.arange(len(budgets)))
        ax.set_xticklabels(["%g %s" % (b, unit) for b in budgets])
        ax.set_ylabel("efficiency relative to '%s'" % meta["variants"][0])
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=8)
    save(fig, d, "efficiency", meta)


def box_blur(a, r):
    """Mean over a (2r+1)^2 window (edges: the part inside), NaN-free input."""
    p = np.pad(a, r, mode="edge")
    c = np.cumsum(np.cumsum(p, 0), 1)
    c = np.pad(c, ((1, 0), (1, 0)))
    k = 2 * r + 1
    return (c[k:, k:] - c[:-k, k:] - c[k:, :-k] + c[:-k, :-k]) / (k * k)


def efficiency_map(d, meta, agg):
    nv = len(meta["variants"])
    big = max(agg[0])
    maps = [np.load(os.path.join(d, "maps", "variant%d.npy" % v)).astype(float) for v in range(nv)]
    cmap = plt.get_cmap("tab10")
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.2))
    shares = {}
    for ax, cost, title in ((axes[0], "seconds", "equal time"), (axes[1], "lookups", "equal work (density lookups)")):
        effs = []
        for v in range(nv):
            e = box_blur(np.nan_to_num(maps[v]), 3)  # 7x7 pixels: the per-pixel error of a few seeds is noisy
            c = agg[v][big][cost][0]
            effs.append(1.0 / (np.maximum(e, 1e-12) * max(c, 1e-30)))
        stack = np.stack([np.nan_to_num(m) for m in maps])
        win = np.argmax(np.stack(effs), axis=0)
        img = np.array([cmap(v % 10)[:3] for v in range(nv)])[win]
        flat = box_blur((np.abs(stack) <= 1e-12).all(axis=0).astype(float), 3) > 0.999  # no error anywhere
        img[flat] = (0.5, 0.5, 0.5)
        win[flat] = -1
        ax.imshow(img, interpolation="nearest")
        ax.set_title("most efficient variant per pixel, %s\n(%g %s, 7x7-pixel mean error)" %
                     (title, big, "s" if meta["budget"] == "seconds" else "spp"), fontsize=9)
        ax.axis("off")
        shares[cost] = [float((win == v).mean()) for v in range(nv)]
        handles = [Patch(color=cmap(v % 10), label="%s (%.0f%%)" % (meta["variants"][v], 100 * shares[cost][v]))
                   for v in range(nv)]
        if flat.any():
            handles.append(Patch(color=(0.5, 0.5, 0.5), label="no error in any variant (%.0f%%)" % (100 * flat.mean())))
        ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.02), ncol=2)
    save(fig, d, "efficiency_map", meta)
    return shares


def machine(meta):
    model = ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return "%s, %d cores online%s, %s %s" % (platform.node(), meta["cores"], (" (" + model + ")") if model else "",
                                              platform.system(), platform.release())


def fmt(x, s):
    if not (x == x):
        return "n/a"
    return "%.3g ± %.2g" % (x, s) if s == s else "%.3g" % x


# A ratio of efficiencies is a measured difference only when it lies more than this many standard errors
# from 1; closer, the summary says that no variant is measurably better.
RESOLVED_SE = 2.0


def load_line(meta):
    """The load average before and after the renders (bench.json), and whether it exceeded the cores."""
    ld = meta.get("load")
    if not ld or ld["before"][0] < 0:
        return "load average: not recorded"
    worst = max(ld["before"][0], ld["after"][0])
    return "load average (1, 5, 15 min): %s before the renders, %s after%s" % (
        ", ".join("%.2f" % x for x in ld["before"]), ", ".join("%.2f" % x for x in ld["after"]),
        "; **above the %d cores: times, and equal-time ratios, are noisy (lookups are not)**" % meta["cores"]
        if worst > meta["cores"] else "")


def summary(meta, agg, shares):
    big = max(agg[0])
    nv = len(meta["variants"])
    unit = "s" if meta["budget"] == "seconds" else "spp"
    base = meta["variants"][0]
    parts = []
    for cost, what in (("seconds", "at equal time"), ("lookups", "at equal work (density lookups)")):
        rs = []
        for v in range(nv):
            e, se = efficiency(agg[v][big], cost)
            e0, se0 = efficiency(agg[0][big], cost)
            r, sr = ratio(e, se, e0, se0) if v else ((1.0, 0.0) if e0 == e0 else (float("nan"), float("nan")))
            rs.append((r, sr, v))
        ok = [x for x in rs if x[0] == x[0]]
        if not ok:
            parts.append("%s nothing can be said (no positive relMSE or %s)." % (what, cost))
            continue
        best = max(ok, key=lambda x: x[0])
        if nv == 1:
            e, se = efficiency(agg[0][big], cost)
            parts.append("%s its efficiency is %s." % (what, fmt(e, se)))
        elif best[2] == 0:
            runner = max((x for x in ok if x[2]), key=lambda x: x[0], default=None)
            sig = (1 - runner[0]) / runner[1] if runner and runner[1] > 0 else float("inf")
            if runner and sig < RESOLVED_SE:
                parts.append("%s no variant is measurably more efficient than another: the next best after '%s', "
                             "'%s', reaches %s of its efficiency (%.1f standard errors below 1; a difference needs "
                             "%g)." % (what, base, meta["variants"][runner[2]], fmt(runner[0], runner[1]), sig,
                                       RESOLVED_SE))
            else:
                parts.append("%s '%s' (the first variant) is the most efficient; the next best, '%s', reaches %s of "
                             "its efficiency." % (what, base, meta["variants"][runner[2]],
                                                   fmt(runner[0], runner[1])) if runner else "")
        else:
            sig = (best[0] - 1) / best[1] if best[1] > 0 else float("inf")
            if not best[1] > 0:
                parts.append("%s '%s' has the largest efficiency, %s× that of '%s', but with one seed there is no "
                             "error estimate: no difference is resolved." %
                             (what, meta["variants"][best[2]], fmt(best[0], best[1]), base))
            elif sig < RESOLVED_SE:
                parts.append("%s no variant is measurably more efficient than '%s': the best, '%s', reaches %s× its "
                             "efficiency (%.1f standard errors above 1; a difference needs %g)." %
                             (what, base, meta["variants"][best[2]], fmt(best[0], best[1]), sig, RESOLVED_SE))
            else:
                parts.append("%s '%s' is the most efficient: %s× the efficiency of '%s' (%s)." %
                             (what, meta["variants"][best[2]], fmt(best[0], best[1]), base,
                              "%.1f standard errors above 1" % sig if best[1] > 0 else "no error estimate"))
    parts = parts[:1] + [p[:1].upper() + p[1:] for p in parts[1:]]
    ref = meta["reference"]
    if ref["noise_estimated"]:
        share = [agg[v][big]["ref_noise"][0] / agg[v][big]["relmse_raw"][0] for v in range(nv)
                 if agg[v][big]["relmse_raw"][0] > 0]
        refs = ("The reference (%d spp) contributes %.1f%% of the measured relMSE at %g %s (its own noise, estimated "
                "from its %d-chunk spread and subtracted)." % (ref["spp"], 100 * float(np.mean(share)) if share else 0,
                                                               big, unit, 4))
    else:
        refs = "The reference was given (%s); its own noise is unknown and not subtracted." % ref["path"]
    if shares and nv > 1:
        top = max(range(nv), key=lambda v: shares["seconds"][v])
        maps = ("Per pixel at equal time, '%s' wins %.0f%% of the image." % (meta["variants"][top],
                                                                                100 * shares["seconds"][top]))
    else:
        maps = ""
    return "At the largest budget (%g %s, %d seeds each), %s %s %s" % (big, unit, meta["repeat"], " ".join(parts), refs,
                                                                      maps)


def report(d, meta, agg, shares):
    big = max(agg[0])
    unit = "s" if meta["budget"] == "seconds" else "spp"
    L = ["# murk bench: %s" % meta["scene"], "",
         "```sh", meta["command"], "```", "",
         "- murk %s; machine: %s; render threads: %s" % (meta["version"], machine(meta),
                                                         meta["threads"] or "all cores"),
         "- " + load_line(meta),
         "- budgets: %s per render, each with %d seeds; variants: %d" % ("seconds (equal time)" if unit == "s" else "spp",
                                                                       meta["repeat"], len(meta["variants"])),
         "- reference: `%s` (%s)" % (meta["reference"]["path"], "given" if meta["reference"]["given"] else
                                     "%d spp of %s, %s" % (meta["reference"]["spp"],
                                                           " ".join("`--set %s`" % x for x in meta["reference"]["sets"])
                                                           or "the first variant, '%s'" % meta["variants"][0],
                                                           "reused from the cache" if meta["reference"]["reused"]
                                                           else "rendered for this run and cached")),
         "- relMSE = mean over pixels and channels of ((a − r)² − v) / (r² + 0.01), r the reference, v the estimated "
         "variance of its per-pixel mean (0 for a given reference): an unbiased estimate of a render's own relMSE. "
         "Error bars: the standard error over the seeds.",
         "", "## Summary", "", summary(meta, agg, shares), "",
         "## At %g %s" % (big, unit), "",
         "| variant | relMSE | seconds | density lookups | rays | efficiency vs first, equal time | equal lookups |"
         " NaN/Inf | max sample |",
         "|---|---|---|---|---|---|---|---|---|"]
    for v, label in enumerate(meta["variants"]):
        s = agg[v][big]
        cells = []
        for cost in ("seconds", "lookups"):
            e, se = efficiency(s, cost)
            e0, se0 = efficiency(agg[0][big], cost)
            r, sr = ratio(e, se, e0, se0) if v else (1.0, 0.0)
            cells.append(fmt(r, sr) if v else "1")
        L.append("| %s | %s | %s | %.4g | %.4g | %s | %s | %d | %.3g |" % (
            label, fmt(*s["relmse"]), fmt(*s["seconds"]), s["lookups"][0], s["rays"][0], cells[0], cells[1],
            int(s["nonfinite"][0] * meta["repeat"]), s["max_sample"][0]))
    L += ["", "## Charts", "",
          "Error against time and against density lookups (log-log; the dashed line is the 1/N slope of an "
          "unbiased estimator):", "",
          "![error vs time](error_vs_time.png) ![error vs lookups](error_vs_lookups.png)", "",
          "Efficiency relative to the first variant, per budget:", "", "![efficiency](efficiency.png)", "",
          "Which variant is most efficient where (per pixel, largest budget):", "",
          "![efficiency map](efficiency_map.png)", "",
          "Every render's figures: [bench.csv](bench.csv).", ""]
    def write(tmp):
        with open(tmp, "w") as f:
            f.write("\n".join(L))
    write_atomic(os.path.join(d, "report.md"), write)


def main():
    signal.signal(signal.SIGTERM, signal.default_int_handler)  # SIGTERM too removes the temporary
    if len(sys.argv) != 2:
        sys.exit("usage: bench_report.py DIR (a murk bench output folder)")
    d = sys.argv[1]
    meta, rows = load(d)
    agg = aggregate(meta, rows)
    error_chart(d, meta, agg, "seconds", "render time (s)", "error_vs_time")
    error_chart(d, meta, agg, "lookups", "density lookups", "error_vs_lookups")
    efficiency_chart(d, meta, agg)
    shares = efficiency_map(d, meta, agg)
    report(d, meta, agg, shares)
    print("charts and report: %s" % os.path.join(d, "report.md"))


if __name__ == "__main__":
    try:
        main()
    except KeyboardInterrupt:  # SIGINT or SIGTERM (murk bench says what happened); no traceback
        sys.exit(130)
