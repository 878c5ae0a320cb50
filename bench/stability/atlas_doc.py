"""docs/stability.md and its heat maps from the atlas rows (bench/stability/atlas.py)."""
import math, os, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "tools"))
import pngmeta  # noqa: E402 (tools/pngmeta.py: the murk:commit text key)

import numpy as np

FIG_DIR = "stability"  # under docs/


def docs_dir(root):
    """docs/ of the tree, or MURK_DOCS_DIR when set (tools/docs.sh writes a whole docs folder elsewhere)."""
    return os.environ.get("MURK_DOCS_DIR") or os.path.join(root, "docs")


def fmt(x, spec="%.3g"):
    if isinstance(x, str):
        return x
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    return spec % x


def methods_of(rows, sweep):
    seen = []
    for r in rows:
        if r["sweep"] == sweep and r["method"] not in seen:
            seen.append(r["method"])
    return seen


def values_of(rows, sweep):
    seen = []
    for r in rows:
        if r["sweep"] == sweep and r["value"] not in seen:
            seen.append(r["value"])
    return seen


def heatmaps(root, rows, sweep, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    media = [m for m in ("homogeneous", "cloud") if any(r["sweep"] == sweep and r["medium"] == m for r in rows)]
    meths = methods_of(rows, sweep)
    vals = values_of(rows, sweep)
    labels = ["%s · %s" % (m[:5], t) for m in media for t in meths]
    panels = [("efficiency / delta's (log10)", lambda r: math.log10(r["eff_rel"]) if r["eff_rel"] and
               r["eff_rel"] > 0 and math.isfinite(r["eff_rel"]) else float("nan"), "RdYlGn", (-2, 2)),
              ("efficiency per density lookup / delta's (log10)", lambda r: math.log10(r["eff_lookups_rel"]) if
               r.get("eff_lookups_rel") and r["eff_lookups_rel"] > 0 and math.isfinite(r["eff_lookups_rel"])
               else float("nan"), "RdYlGn", (-2, 2)),
              ("firefly rate (samples > 100x pixel mean)", lambda r: r["firefly"], "magma_r", (0, None)),
              ("|bias z| (image mean)", lambda r: abs(r["z"]), "Reds", (0, 5))]
    mats = []
    for name, f, cmap, lim in panels:
        M = np.full((len(labels), len(vals)), np.nan)
        for i, (m, t) in enumerate([(m, t) for m in media for t in meths]):
            for j, v in enumerate(vals):
                rr = [r for r in rows if r["sweep"] == sweep and r["medium"] == m and r["method"] == t and
                      r["value"] == v]
                if rr:
                    M[i, j] = f(rr[0])
        if np.isfinite(M).any():  # a panel with no number (no delta to compare with) is left out, not drawn empty
            mats.append((name, M, cmap, lim))
    fig, axes = plt.subplots(1, len(mats), figsize=(4.8 * len(mats) + 2.5, 0.42 * len(labels) + 2.2), squeeze=False)
    axes = axes[0]
    for ax, (name, M, cmap, (lo, hi)) in zip(axes, mats):
        top = hi if hi is not None else max(1e-3, np.nanmax(M) if np.isfinite(M).any() else 1)
        im = ax.imshow(M, cmap=cmap, vmin=lo, vmax=top, aspect="auto")
        for i in range(M.shape[0]):
            for j in range(M.shape[1]):
                if np.isfinite(M[i, j]):
                    ax.text(j, i, "%.2g" % M[i, j], ha="center", va="center", fontsize=9)
        ax.set_xticks(range(len(vals)))
        ax.set_xticklabels([str(v) for v in vals], fontsize=10)
        ax.set_yticks(range(len(labels)))
        ax.set_yticklabels(labels if ax is axes[0] else [""] * len(labels), fontsize=10)
        ax.set_title(name, fontsize=11)
        fig.colorbar(im, ax=ax, fraction=0.04).ax.tick_params(labelsize=9)
    fig.suptitle("%s — %s" % (sweep, title), fontsize=12)
    fig.tight_layout()
    os.makedirs(os.path.join(docs_dir(root), FIG_DIR), exist_ok=True)
    rel = "%s/%s.png" % (FIG_DIR, sweep)
    fig.savefig(os.path.join(docs_dir(root), rel), dpi=90, metadata=pngmeta.metadata())
    plt.close(fig)
    return rel


def repair_section(meta):
    L = ["## Where a majorant or control is wrong", ""]
    L.append(
        "A majorant below the density (`majorant_factor` < 1) or a decomposition control above it used to "
        "weight every violating collision by up to 2a - 1 (a = density / majorant), multiplied along every "
        "path: unbiased, but relMSE 1e19 (factor 0.5) and 1e43 (control 5) on cornell_smoke. Now:")
    L.append("")
    L.append(
        "- **The core repairs the majorant before rendering** (`majorant_repair: true`, the default). murk's "
        "majorant grid holds, per cell, the exact maximum of the interpolated field (density.h; the cloud and "
        "the grids are voxel data, so the maximum is attained at a voxel), so a factor < 1 leaves every cell "
        "with density below the density somewhere in it, and the repair gives each such cell its exact bound "
        "back: the majorant of factor 1. It depends on the scene only, so the image stays a pure function of "
        "(scene, seed, spp) for any thread count and tiling — a majorant raised at run time and shared between "
        "threads would not. The warning names the cells (e.g. `majorant_factor 0.5 < 1 leaves 1657 of 3136 "
        "majorant cells below the density; murk raised them to their exact bound before rendering (as "
        "majorant_factor 1: no bias, no extra noise, the time of a bounding majorant ...)`).")
    L.append(
        "- **decomposition clamps its control** to each cell's minimum density (`repair: true`, the default): "
        "control > 1 acts as 1, the largest control that stays below the density everywhere; its shadow rays "
        "always use the clamped control (ratio tracking cannot undo an overshooting closed-form control "
        "without exponentially heavy weights: |z| 17 in tests/test_stability.c before that change).")
    L.append(
        "- **With the repairs off** (`majorant_repair: false`, `repair: false`, or a third-party tracker whose "
        "majorants are estimated) a tracker weights the violating collision and then tracks the rest of the "
        "FLIGHT with the majorant raised 2x the excess (`murk_collisions_raise` in murk/tracking.h; "
        "decomposition also lowers the flight's control below the density seen; ratio tracking raises its "
        "majorant per ray). That is unbiased — the null-collision identity holds for any majorant over the "
        "rest of the segment, which is estimated afresh after each collision — and per path, from the path's "
        "own random numbers. It bounds the weight of one flight (the largest |weight| over 200000 "
        "flights at factor 0.25 in tests/test_stability.c: 7 to 77; 240 to 37700 with the raise disabled), but a path has no state that outlives a flight, "
        "so every flight of a long path may pay one violation again: the image is far better than before but "
        "still unusable at factor 0.5 (table). That mode is for diagnosis; the repairs are the default.")
    L.append("")
    v = meta.get("violations") or []
    if v:
        L.append("relMSE at equal spp (96x96, 32 spp) against a 256-spp `spectral_mis` render with another seed; "
                 "the bounding rows are the target (within 3x):")
        L.append("")
        L.append("| scene | variant | relMSE | time s |")
        L.append("|---|---|---|---|")
        for r in v:
            L.append("| %s | %s | %.3g | %.2f |" % (r["scene"], r["variant"], r["relmse"], r["seconds"]))
        L.append("")
    L.append(
        "Before these repairs (murk at commit e2aa582, before the Sobol sampler, the same renders against a "
        "256-spp reference of that time, measured once by hand; the bounding rows then: 1.36e-2 and 1.33e-2): "
        "cornell_smoke delta at majorant_factor 0.9 / 0.5 / 0.25: 1.41e-2 / 1.05e20 / 1.72e23; decomposition at "
        "control 1.5 / 5 / 10: 0.334 / 9.1e42 / 1.7e48; spectral_extinction spectral at factor 0.5 / 0.25: "
        "5.4e23 / 1.1e23, spectral_mis at 0.25: 2.1e29, delta at 0.25: 7.8e40, decomposition at control 10: "
        "8.4e41. With the repairs every one of these equals its bounding case (bitwise the same image). "
        "Without them (the diagnosis mode) the per-flight raise helps at factor 0.5 (2e15 and 3e16 in two runs, "
        "against 1.05e20) "
        "but not everywhere: decomposition at control 1.5 with `repair: false` measured 9.1 (3.5 in this run, "
        "with murk's Sobol sampler) against 0.33 before (over seeds 1-3: 1.9 / 13 / 7.2 against 0.33 / 5.5 / "
        "0.98) — single renders of such "
        "heavy-tailed estimators vary by 10x between seeds, and the cause of that difference is not found; "
        "keep the repairs on.")
    L.append("")
    return L


FINDINGS = [
    "## Three surprises", "",
    "1. **The baseline's noise is everywhere, not just in the medium.** `naive_spectral` carries one channel per "
    "path on every path, so a background seen through an almost empty medium (density 1e-4) gets full colour "
    "noise: 1e6 to 1e7 times delta's cost for the same error, the largest gap in the atlas — at the point where "
    "the medium hardly matters.",
    "2. **A majorant 4x too low is no longer a problem; one 32x too high costs the shadow estimators most.** "
    "With the load-time repair, `majorant_factor` 0.25 renders bitwise the image of factor 1. At factor 32 "
    "the trackers and the other shadow estimators stay within the timing noise of delta, but `power_series` "
    "falls to 0.16-0.54 of delta's efficiency (0.23-0.52 per lookup). Without the repair, the homogeneous box "
    "is worse off than the cloud (1.4-3% fireflies against 1e-4 or less): in a "
    "constant density every tentative collision violates, in the cloud only the dense parts do, and one "
    "violation per flight is enough to spoil a path with many flights.",
    "3. **An unbiased estimator can look biased: the one significant |z| was a variance that grows "
    "exponentially.** `power_series` shadow rays at density scale 1e4 in the cloud came out 5% dark (z about "
    "-18). Its expectation was right; its per-chunk factors, ~1 on average but spread 0.09-1.8 where the "
    "majorant is loose, multiplied over hundreds of chunks, so almost every sample was ~0 and the rare huge "
    "ones never came at 64 spp. Fixed (bounded variance, see the method); every point now has |z| below 5.",
    "",
]


# What each method is, where it fails, what murk does there and what to pick instead (hand-written; the
# figures after each are computed from the run).
METHODS = [
    ("delta", "Delta tracking with the albedo as weight and residual ratio tracking for shadow rays; on chromatic "
     "extinction it chooses collisions history-aware and weights the channels (spectral tracking in all but "
     "name). The robust default: no sweep breaks it. It degrades only in time — cost grows with the majorant's "
     "optical depth (dense media, loose majorants: `majorant_factor` 32) — and on the absorbing box seen "
     "directly, where a camera ray through a thick absorber is a binary estimate (passes with weight 1 or is "
     "absorbed), so a thick absorber viewed head-on shows rare bright samples (the fireflies of the absorber "
     "sweep). murk warns about nothing here; pick it unless a row below says otherwise."),
    ("decomposition", "Decomposition tracking: a closed-form control (the cell's minimum density) plus a tracked "
     "residual. It matches delta within the timing noise nearly everywhere (in this scene family the cloud's "
     "minorant is 0 in most cells, so the control rarely has anything to take), and a coarse "
     "`majorant_resolution` does not hurt it more than delta. On the homogeneous box the control takes every "
     "collision and it looks the density up almost never: 400x delta's efficiency per lookup (the time-based "
     "figure hides that here, because a constant density costs little to look up). "
     "`control` > 1 used to be its failure mode (relMSE 1e43); it is now clamped at load (`repair`), so the "
     "control sweep is flat. With `repair: false` it weights the violating residual collisions and lowers the "
     "flight's control: unbiased, but the noisiest points of the whole atlas (`control_norepair` on the "
     "homogeneous box: up to 13% fireflies, a sample 1e10 times its pixel). On the homogeneous box it is immune "
     "to a majorant that is too low (the control takes every collision). Pick it for media whose minorant grid "
     "is tight; keep `repair` on."),
    ("spectral", "Spectral tracking (Kutz et al. 2017) with history-aware probabilities: one flight for all "
     "channels, absorption sampled as a path end. On grey media it is strictly worse than delta (it kills paths "
     "at absorption events where delta weights them: about 3x delta's variance at the median grey point, "
     "up to 30x), and it loses most on the thin media (density 1e-4: 0.01-0.03 of delta's efficiency). Its "
     "weights stay bounded up to chroma 1:1000 (no NaN, no fireflies). murk says nothing; pick "
     "`delta` (the same per-channel weighting without the absorption lottery) or `spectral_mis`."),
    ("spectral_mis", "Spectral MIS (Miller et al. 2019): hero-channel tracking with the balance heuristic over "
     "channels. On grey media it is delta tracking bit for bit (same samples, same image); on chromatic media it "
     "is the steadiest: never the worst point of a sweep, no fireflies up to 1:1000. It is the reference "
     "tracker of this atlas for that reason. Pick it for strongly chromatic media."),
    ("naive_spectral", "Per-channel delta tracking, one channel per path: the baseline. It carries one channel "
     "with weight 3 on every path, also on paths that never meet the medium, so it puts colour noise on the "
     "background seen through a nearly empty medium (efficiency 1e-6..1e-7 of delta at density 1e-4) and loses "
     "10x to 100x on every grey or mildly chromatic point. It is unbiased everywhere. Only at 1:1000 chroma does "
     "it approach the others. Use it to measure the others, not to render."),
    ("delta+ratio", "Plain ratio tracking for shadow rays: unbiased and bounded for a bounding majorant; it pays "
     "one lookup per majorant collision, so it loses against residual ratio tracking where the minorant is "
     "tight and at loose majorants (`majorant_factor` 32)."),
    ("delta+residual_ratio", "Residual ratio tracking (murk's default for shadow rays): never worse than ratio "
     "tracking beyond the timing noise, exact on constant density."),
    ("delta+track_length", "Track-length (binary) transmittance: a shadow ray is 0 or 1. Surprisingly close to "
     "ratio tracking in this scene family (the shadow rays are short and light), worst where the majorant is "
     "loose (`majorant_factor` 32)."),
    ("delta+unbiased_raymarch", "Unbiased ray marching (Kettunen et al. 2021): fine at moderate density, but its "
     "march cost follows the optical depth: at density 1e4 it is 100x slower than delta for the same noise, and "
     "on the almost empty cloud (density 1e-4) it adds noise where every other estimator is exact (30x worse "
     "per lookup there)."),
    ("delta+power_series", "The cumulative power-series estimator (Georgiev et al. 2019's p-series CMF): "
     "unbiased at every point, but the costliest shadow estimator in dense media. This atlas found it 5% dark "
     "at density 1e4 in the cloud (z -18 and -20), now fixed: a shadow ray leaving the cloud's lit top crosses "
     "the empty part of a dense majorant cell, thousands of majorant optical depths where the density is ~0; "
     "with the series' order the bare Poisson count, each chunk there gave a random factor (0.09 to 1.8 at "
     "depth 4) instead of ~1, the chunks' factors multiply, and the product was almost always ~0 (variance "
     "growing like exp(loose majorant depth): the sample mean far below the expectation). A second, rarer "
     "fault (found by reading, not shown to matter here): a chunk cut that rounded down to a float could "
     "swallow the rest of the cell into one chunk, stopped at 0 past 1024 points. Now the order is topped up to where the Poisson CMF reaches 1 - 1e-8 (bounded "
     "variance) and a float-limited cut closes the chunk; test_transmittance's dense-cell case holds both. "
     "The price is lookups: about 20 per chunk of depth 4 instead of 4, so in dense media it has 0.26-0.4 of "
     "delta's efficiency (density 100 and 1e4; about 4x delta's time in the cloud at 1e4); "
     "prefer ratio or residual_ratio there."),
]


def timing_noise(rows):
    """spectral_mis and delta draw the same samples on grey media (identical relvar): their time ratio is noise."""
    idx = {(r["sweep"], r["medium"], str(r["value"]), r["method"]): r for r in rows}
    t = []
    for r in rows:
        d = idx.get((r["sweep"], r["medium"], str(r["value"]), "delta"))
        if r["method"] == "spectral_mis" and d and d["relvar"] == r["relvar"] and d["seconds"] > 0:
            t.append(r["seconds"] / d["seconds"])
    if len(t) < 5:
        return "not measurable in this run"
    t.sort()
    return ("on grey media `spectral_mis` draws exactly delta's samples, so its time over delta's is pure noise: "
            "median %.2f, 10%%-90%% %.2f-%.2f, extremes %.2f-%.2f over %d points — efficiency ratios within that "
            "band are ties" % (t[len(t) // 2], t[len(t) // 10], t[-1 - len(t) // 10], t[0], t[-1], len(t)))


def method_facts(rows, method):
    rr = [r for r in rows if r["method"] == method]
    if not rr:
        return ""
    eff = [r for r in rr if r.get("eff_rel") and math.isfinite(r["eff_rel"]) and r["eff_rel"] > 0]
    parts = []
    if eff and method != "delta":
        e = sorted(x["eff_rel"] for x in eff)
        w = min(eff, key=lambda x: x["eff_rel"])
        parts.append("efficiency / delta's: median %.2g over %d points, lowest %.2g (%s, %s = %s)"
                     % (e[len(e) // 2], len(e), w["eff_rel"], w["medium"], w["sweep"], w["value"]))
    f = max(rr, key=lambda x: x["firefly"])
    if f["firefly"] > 0:
        parts.append("highest firefly rate %.2g (%s, %s = %s)" % (f["firefly"], f["medium"], f["sweep"], f["value"]))
    else:
        parts.append("no fireflies anywhere")
    z = max(rr, key=lambda x: abs(x["z"]))
    parts.append("largest |z| %.1f (%s, %s = %s)" % (abs(z["z"]), z["medium"], z["sweep"], z["value"]))
    parts.append("non-finite samples: %d" % sum(x["nonfinite"] for x in rr))
    return "In this run: " + "; ".join(parts) + "."


def methods_section(rows):
    L = ["## The methods", ""]
    for m, text in METHODS:
        if any(r["method"] == m for r in rows):
            L.append("**%s** — %s %s" % (m, text, method_facts(rows, m)))
            L.append("")
    return L


def write(root, meta, rows, sweep_doc, prose=None):
    sweeps = []
    for r in rows:
        if r["sweep"] not in sweeps:
            sweeps.append(r["sweep"])
    nonfinite = sum(r["nonfinite"] for r in rows)
    zmax = max(rows, key=lambda r: abs(r["z"]))
    fmax = max(rows, key=lambda r: r["firefly"])
    L = []
    L.append("# Stability atlas: where each tracker and transmittance estimator degrades")
    L.append("")
    L.append("Generated by `/usr/bin/python3 bench/stability/atlas.py` (`--quick` runs the sweeps' "
             "extreme points in seconds; `meson test -C build --setup stability --suite stability` runs the "
             "whole atlas with `--check`). Do not edit by hand: edit `bench/stability/atlas_doc.py`.")
    L.append("")
    L.append("This run: %d renders of %dx%d pixels at %d spp (references: %d spp), %.1f minutes (%.1f with the "
             "relMSE renders of the next section) on a shared "
             "2-core machine (times, and so efficiencies, carry the noise of that load: read factors of 2, not "
             "percent). **Non-finite samples: %d in all.** Largest |bias z|: %.2f (%s, %s, %s = %s). Highest "
             "firefly rate: %.3g (%s, %s, %s = %s)."
             % (len(rows), meta["res"], meta["res"], meta["spp"], meta["ref_spp"], meta["minutes"],
                meta.get("minutes_all", meta["minutes"]), nonfinite,
                abs(zmax["z"]), zmax["method"], zmax["medium"], zmax["sweep"], zmax["value"], fmax["firefly"],
                fmax["method"], fmax["medium"], fmax["sweep"], fmax["value"]))
    L.append("")
    L.append("## The scene family")
    L.append("")
    L.append("A medium fills the box [-1, 1]^3: `homogeneous` (constant density 1) or `cloud` (murk's procedural "
             "fBm cloud, resolution 40, coverage 0.6). An area light (12 x 1.2^2) hangs above it and the background "
             "is a constant (0.4, 0.45, 0.5); the camera looks at the box from z = 4 (`camera: outside`) or sits "
             "inside it (`inside`). Base case: grey extinction 1.5 per unit density (optical depth 3 across the "
             "homogeneous box), albedo 0.8, g 0, `majorant_factor` 1, `majorant_resolution` 16, decomposition "
             "`control` 1, integrator `volpath_nee` (max depth 64). Each sweep changes one key. Methods: the five "
             "trackers (each with its own shadow rays: residual ratio tracking), and under `delta` every unbiased "
             "`transmittance:` estimator (names `delta+ESTIMATOR`) on the density, majorant, chroma and absorber "
             "sweeps.")
    L.append("")
    L.append("## What is measured")
    L.append("")
    L.append("Per point and method, from every sample of the render (murk's hidden `MURK_SAMPLE_DUMP`):")
    L.append("")
    L.append("- **non-finite**: samples that are NaN or infinite (murk drops them from the pixel; must be 0);")
    L.append("- **max/mean**: the largest sample's luminance over its pixel's mean in the reference (the largest "
             "single-sample weight, as the image sees it; the reference's mean, because a pixel's own mean at n "
             "spp can never be exceeded more than n-fold; floored at 1% of the image's mean);")
    L.append("- **firefly rate**: the share of samples whose luminance exceeds 100x that pixel mean;")
    L.append("- **relvar**: mean over pixels of Var(pixel mean) / (mean^2 + 0.01), from the samples' own variance;")
    L.append("- **time**: murk's render time (wall clock, loaded machine);")
    L.append("- **lookups**: density lookups of the medium (murk's cost counters, printed after each render): "
             "machine-independent work;")
    L.append("- **efficiency** = 1 / (relvar x time) and **per lookup** = 1 / (relvar x lookups), each shown "
             "relative to `delta` at the same point (the lookup-based one carries no timing noise, but it ignores "
             "work that is not a lookup, e.g. unbiased_raymarch's arithmetic or naive_spectral's extra bounces);")
    L.append("- **timing noise**: %s;" % timing_noise(rows))
    L.append("- **bias z**: (image mean - reference) / its standard error, per channel, the largest |z| shown; "
             "`zblock` is the largest over 4x4 blocks (48 figures, so values near 3 are expected). Reference: "
             "the **closed form** for the absorbing homogeneous box (albedo 0; E[pixel] = background x "
             "exp(-sigma_t x chord), integrated over each pixel's footprint), else **spectral_mis** with a "
             "bounding majorant (`majorant_factor` max(1, f)) and `control` 1 at 4x the spp and another seed — "
             "the most robust tracker in the atlas: its weights stay bounded for every chroma.")
    L.append("")
    L += repair_section(meta)
    L += methods_section(rows)
    L += FINDINGS
    if prose:
        L += prose
    for sw in sweeps:
        L.append("## Sweep: %s" % sw)
        L.append("")
        L.append(sweep_doc.get(sw, ""))
        L.append("")
        try:
            rel = heatmaps(root, rows, sw, sweep_doc.get(sw, ""))
            L.append("![%s](%s)" % (sw, rel))
            L.append("")
        except ImportError:
            L.append("(python3-matplotlib missing: no heat map)")
            L.append("")
        L.append("| medium | value | method | non-finite | max/mean | fireflies | relvar | time s | lookups | eff / delta | "
                 "eff per lookup / delta | z | zblock |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            if r["sweep"] != sw:
                continue
            L.append("| %s | %s | %s | %d | %s | %s | %s | %s | %s | %s | %s | %+.2f | %.2f |" % (
                r["medium"], r["value"], r["method"], r["nonfinite"], fmt(r["maxratio"]), fmt(r["firefly"], "%.2e"),
                fmt(r["relvar"], "%.2e"), fmt(r["seconds"], "%.2f"), r.get("lookups", "—"), fmt(r["eff_rel"], "%.2f"),
                fmt(r.get("eff_lookups_rel", float("nan")), "%.2f"), r["z"], r["zblock"]))
        L.append("")
    with open(os.path.join(docs_dir(root), "stability.md"), "w") as f:
        f.write("\n".join(L))
    print("wrote docs/stability.md and docs/%s/*.png" % FIG_DIR)
