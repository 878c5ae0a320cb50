#!/usr/bin/python3
"""figure4.py — the reference report's Figure 4 as the report set it: spectral tracking against the naive
per-channel baseline on heterogeneous chromatic media, the baseline rendered in three passes, one per
channel (naive_spectral `channel: red|green|blue`, put together by bench/three_pass.py), at equal spp per
channel. Beside them murk's own one-render naive baseline (a hero channel per path) and spectral MIS.

Timing protocol: ROUNDS interleaved rounds (every variant once per round, in a rotated order, each round
with its own seed), the load average recorded before and after each render; per variant the median
render time with its spread (smallest-largest), the density lookups (machine-independent work) and the
relMSE against a reference (spectral_mis, another seed). A ratio is called resolved only when the
spreads of the two variants' times do not overlap.

    bench/figure4.py [--scale S] [--rounds R] [--spp N] [--res N] [--out DIR] [--docs DIR]

writes DIR/fig4_SCENE.png strips (the first round's images) and DIR/fig4_table.md, with --md FILE also
into FILE between its fig4 table markers (docs/gallery.md's Figure 4; tools/mdsplice.py), and the renders
to --out. The block gives the run's parameters and load, the table, and per scene the ratios the gallery's
text reads (time and lookups of the three passes over spectral tracking; efficiency per unit time; murk's
naive and spectral MIS against spectral tracking). Needs Debian's python3-numpy and python3-matplotlib."""
import argparse
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from mdsplice import splice  # noqa: E402
MURK = os.environ.get("MURK", os.path.join(ROOT, "build", "core", "murk"))
PY = "/usr/bin/python3"
SCENES = ["absorption", "scattering", "extinction"]
# the medium as the report had it: heterogeneous, a procedural cloud filling the sphere's box
HETERO = "media.medium.density={cloud: {min: [-0.6, 0.1, -0.6], max: [0.6, 1.3, 0.6], seed: 3, frequency: 3}}"
VARIANTS = ["naive3", "naive_spectral", "spectral", "spectral_mis"]
LABEL = {"naive3": "naive, three passes (the report's)", "naive_spectral": "naive, hero per path (murk's)",
         "spectral": "spectral tracking", "spectral_mis": "spectral MIS"}
CAPTION = {"naive3": "naive, 3 passes\\n(the report's)", "naive_spectral": "naive, hero\\nper path (murk's)",
           "spectral": "spectral\\ntracking", "spectral_mis": "spectral\\nMIS"}


def load():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def render(scene, out, spp, res, seed, sets):
    cmd = [MURK, "render", scene, "-o", out, "--spp", str(spp), "--quiet", "--set", "render.resolution=[%d,%d]" % (res, res),
           "--set", "render.seed=%d" % seed, "--set", HETERO]
    for s in sets:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True)


def compare(test, ref):
    out = subprocess.run([MURK, "compare", test, ref, "--json"], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def one(variant, scene, base, spp, res, seed, ref):
    """Renders one variant; its relMSE, seconds and lookups, and the load before and after."""
    l0 = load()
    if variant == "naive3":
        secs = looks = 0.0
        passes = []
        for ch in ("red", "green", "blue"):
            p = "%s_%s.exr" % (base, ch)
            render(scene, p, spp, res, seed, ["media.medium.type=naive_spectral", "media.medium.channel=" + ch])
            c = compare(p, ref)
            secs += c["seconds"]
            looks += c["lookups"]
            passes.append(p)
        subprocess.run([PY, os.path.join(ROOT, "bench", "three_pass.py"), base + ".exr"] + passes, check=True)
        rel = compare(base + ".exr", ref)["relmse"]
    else:
        render(scene, base + ".exr", spp, res, seed, ["media.medium.type=" + variant])
        c = compare(base + ".exr", ref)
        rel, secs, looks = c["relmse"], c["seconds"], c["lookups"]
    return {"relmse": rel, "seconds": secs, "lookups": looks, "load": (l0, load())}


def spread(xs):
    """(median, smallest, largest)."""
    return statistics.median(xs), min(xs), max(xs)


def fmt_med(m, spec):
    return (spec + " [" + spec + "–" + spec + "]") % m


def summary(x):
    """One variant's rounds: seconds and relMSE as (median, min, max), the median lookups, the load range."""
    return {"seconds": spread([y["seconds"] for y in x]), "relmse": spread([y["relmse"] for y in x]),
            "lookups": statistics.median([y["lookups"] for y in x]),
            "load": (min(y["load"][0] for y in x), max(y["load"][1] for y in x))}


def apart(a, b):
    """Whether two (median, min, max) spreads do not overlap."""
    return a[1] > b[2] or a[2] < b[1]


def verdict(s, S):
    """The lines the gallery reads for scene s, from the summaries S of its variants."""
    n, sp, h, m = S["naive3"], S["spectral"], S["naive_spectral"], S["spectral_mis"]
    t = lambda a, b, k: a[k][0] / b[k][0]  # noqa: E731 (ratio of medians)
    sep = lambda a, b, k: "apart" if apart(a[k], b[k]) else "overlap"  # noqa: E731
    # the efficiency ratio's bounds from the spreads: the three passes at their best against spectral at its worst
    lo = n["relmse"][1] * n["seconds"][1] / (sp["relmse"][2] * sp["seconds"][2])
    hi = n["relmse"][2] * n["seconds"][2] / (sp["relmse"][1] * sp["seconds"][1])
    return ("- %s: three-pass naive / spectral = **%.2f×** the time (%s), %.2f× the density lookups\n"
            "  - per unit time spectral tracking is %.2f× as efficient as the three passes (median relMSE × median "
            "time; %.2f–%.2f× between the spreads' extremes: %s)\n"
            "  - against spectral tracking: murk's one-render naive takes %.2f× its time (spreads %s) with %.2f× its "
            "relMSE (spreads %s); spectral MIS %.2f× its time (spreads %s) with %.2f× its relMSE (spreads %s)" % (
                s, t(n, sp, "seconds"), "resolved: the spreads do not overlap" if apart(n["seconds"], sp["seconds"])
                else "NOT resolved: the spreads overlap", n["lookups"] / sp["lookups"],
                t(n, sp, "relmse") * t(n, sp, "seconds"), lo, hi,
                "resolved" if lo > 1 or hi < 1 else "NOT resolved",
                t(h, sp, "seconds"), sep(h, sp, "seconds"), t(h, sp, "relmse"), sep(h, sp, "relmse"),
                t(m, sp, "seconds"), sep(m, sp, "seconds"), t(m, sp, "relmse"), sep(m, sp, "relmse")))


def row(s, v, spp, x):
    per_channel = spp if v in ("naive3", "spectral", "spectral_mis") else "%d (hero: ~%.3g)" % (spp, spp / 3)
    return "| %s | %s | %s | %s s | %.3g | %s | %.1f–%.1f |" % (
        s, LABEL[v], per_channel, fmt_med(x["seconds"], "%.2f"), x["lookups"], fmt_med(x["relmse"], "%.3g"),
        x["load"][0], x["load"][1])


def make_strip(a, s, spp, rel):
    """DOCS/fig4_SCENE.png: round 0's images side by side, each with its relMSE."""
    strip = [os.path.join(a.out, "%s_%s_r0.png" % (s, v)) + ":" + CAPTION[v] + "\\nrelMSE %.3g" % rel[v]
             for v in VARIANTS]
    subprocess.run([PY, os.path.join(ROOT, "bench", "strip.py"), "--title",
                    "Fig. 4, %s: %d spp/channel" % (s, spp), os.path.join(a.docs, "fig4_%s.png" % s)] + strip,
                   check=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scale", type=float, default=1.0, help="multiplies spp and reference spp")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--spp", type=int, default=32, help="spp per pass / per render")
    ap.add_argument("--ref-spp", type=int, default=512)
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "fig4"))
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs", "gallery"))
    ap.add_argument("--md", help="splice the table into this markdown file, between its markers "
                    "'<!-- fig4 table: generated by bench/figure4.py, do not edit -->' and '<!-- end fig4 table -->'")
    ap.add_argument("--strips-only", action="store_true", help="redraw the strips from round 0's renders in --out")
    a = ap.parse_args()
    spp = max(1, round(a.spp * a.scale))
    if a.strips_only:
        for s in SCENES:
            ref = os.path.join(a.out, "%s_ref.exr" % s)
            make_strip(a, s, spp, {v: compare(os.path.join(a.out, "%s_%s_r0.exr" % (s, v)), ref)["relmse"]
                                   for v in VARIANTS})
        return
    ref_spp = max(2, round(a.ref_spp * a.scale))
    os.makedirs(a.out, exist_ok=True)
    os.makedirs(a.docs, exist_ok=True)
    rows = ["| scene | variant | spp per channel | time, median [min–max] | density lookups | relMSE, median "
            "[min–max] | load before–after |", "|---|---|---|---|---|---|---|"]
    verdicts, loads = [], []
    for s in SCENES:
        scene = os.path.join(ROOT, "scenes", "spectral_%s.yaml" % s)
        ref = os.path.join(a.out, "%s_ref.exr" % s)
        render(scene, ref, ref_spp, a.res, 1000, ["media.medium.type=spectral_mis"])
        res = {v: [] for v in VARIANTS}
        for r in range(a.rounds):
            order = VARIANTS[r % len(VARIANTS):] + VARIANTS[:r % len(VARIANTS)]
            for v in order:
                res[v].append(one(v, scene, os.path.join(a.out, "%s_%s_r%d" % (s, v, r)), spp, a.res, r, ref))
        S = {v: summary(res[v]) for v in VARIANTS}
        rows += [row(s, v, spp, S[v]) for v in VARIANTS]
        loads += [x for v in VARIANTS for x in S[v]["load"]]
        verdicts.append(verdict(s, S))
        make_strip(a, s, spp, {v: res[v][0]["relmse"] for v in VARIANTS})
    block = block_text(params(a.rounds, spp, a.res, ref_spp, min(loads), max(loads)), rows, verdicts)
    with open(os.path.join(a.docs, "fig4_table.md"), "w") as f:
        f.write("<!-- generated by bench/figure4.py (--scale %g --rounds %d --spp %d --res %d): do not edit -->\n"
                % (a.scale, a.rounds, a.spp, a.res))
        f.write(block)
    print(block, end="")
    if a.md:
        splice(a.md, "fig4 table", "bench/figure4.py", block)


def params(rounds, spp, res, ref_spp, lo, hi):
    return ("%d rounds, %d spp per channel, %dx%d, reference %d spp; load average %.1f–%.1f over the renders "
            "(before the first to after the last)." % (rounds, spp, res, res, ref_spp, lo, hi))


def block_text(par, rows, verdicts):
    return par + "\n\n" + "\n".join(rows) + "\n\n" + "\n".join(verdicts) + "\n"


if __name__ == "__main__":
    main()
