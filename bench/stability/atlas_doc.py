"""docs/stability.md and its heat maps from the atlas rows (bench/stability/atlas.py)."""
import math, os

import numpy as np

FIG_DIR = "stability"  # under docs/


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
              ("firefly rate (samples > 100x pixel mean)", lambda r: r["firefly"], "magma_r", (0, None)),
              ("|bias z| (image mean)", lambda r: abs(r["z"]), "Reds", (0, 5))]
    fig, axes = plt.subplots(1, 3, figsize=(4.2 * 3 + 1.5, 0.32 * len(labels) + 1.8))
    for ax, (name, f, cmap, (lo, hi)) in zip(axes, panels):
        M = np.full((len(labels), len(vals)), np.nan)
        for i, (m, t) in enumerate([(m, t) for m in media for t in meths]):
            for j, v in enumerate(vals):
                rr = [r for r in rows if r["sweep"] == sweep and r["medium"] == m and r["method"] == t and
                      r["value"] == v]
                if rr:
                    M[i, j] = f(rr[0])
        top = hi if hi is not None else max(1e-9, np.nanmax(M) if np.isfinite(M).any() else 1)
        im = ax.imshow(M, cmap=cmap, vmin=lo, vmax=top, aspect="auto")
        for i in range(M.shape[0]):
            for j in range(M.shape[1]):
                if np.isfinite(M[i, j]):
                    ax.text(j, i, "%.2g" % M[i, j], ha="center", va="center", fontsize=6)
        ax.set_xticks(range(len(vals)))
        ax.set_xticklabels([str(v) for v in vals], fontsize=7)
        ax.set_yticks(range(len(labels)))
        ax.set_yticklabels(labels if ax is axes[0] else [""] * len(labels), fontsize=7)
        ax.set_title(name, fontsize=8)
        fig.colorbar(im, ax=ax, fraction=0.04)
    fig.suptitle("%s — %s" % (sweep, title), fontsize=9)
    fig.tight_layout()
    os.makedirs(os.path.join(root, "docs", FIG_DIR), exist_ok=True)
    rel = "%s/%s.png" % (FIG_DIR, sweep)
    fig.savefig(os.path.join(root, "docs", rel), dpi=80)
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
    L.append("Generated by `/usr/bin/python3 bench/stability/atlas.py` (issue 9; `--quick` runs the sweeps' "
             "extreme points in seconds; `meson test -C build --setup stability --suite stability` runs the "
             "whole atlas with `--check`). Do not edit by hand: edit `bench/stability/atlas_doc.py`.")
    L.append("")
    L.append("This run: %d renders of %dx%d pixels at %d spp (references: %d spp), %.1f minutes on a shared "
             "2-core machine (times, and so efficiencies, carry the noise of that load: read factors of 2, not "
             "percent). **Non-finite samples: %d in all.** Largest |bias z|: %.2f (%s, %s, %s = %s). Highest "
             "firefly rate: %.3g (%s, %s, %s = %s)."
             % (len(rows), meta["res"], meta["res"], meta["spp"], meta["ref_spp"], meta["minutes"], nonfinite,
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
    L.append("- **time**: murk's render time (wall clock, loaded machine); no density-lookup counts yet (the "
             "`murk:counters` metadata is another branch's work);")
    L.append("- **efficiency** = 1 / (relvar x time), shown relative to `delta` at the same point;")
    L.append("- **bias z**: (image mean - reference) / its standard error, per channel, the largest |z| shown; "
             "`zblock` is the largest over 4x4 blocks (48 figures, so values near 3 are expected). Reference: "
             "the **closed form** for the absorbing homogeneous box (albedo 0; E[pixel] = background x "
             "exp(-sigma_t x chord), integrated over each pixel's footprint), else **spectral_mis** with a "
             "bounding majorant (`majorant_factor` max(1, f)) and `control` 1 at 4x the spp and another seed — "
             "the most robust tracker in the atlas: its weights stay bounded for every chroma.")
    L.append("")
    L += repair_section(meta)
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
        L.append("| medium | value | method | non-finite | max/mean | fireflies | relvar | time s | eff / delta | z | zblock |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            if r["sweep"] != sw:
                continue
            L.append("| %s | %s | %s | %d | %s | %s | %s | %s | %s | %+.2f | %.2f |" % (
                r["medium"], r["value"], r["method"], r["nonfinite"], fmt(r["maxratio"]), fmt(r["firefly"], "%.2e"),
                fmt(r["relvar"], "%.2e"), fmt(r["seconds"], "%.2f"), fmt(r["eff_rel"], "%.2f"), r["z"], r["zblock"]))
        L.append("")
    with open(os.path.join(root, "docs", "stability.md"), "w") as f:
        f.write("\n".join(L))
    print("wrote docs/stability.md and docs/%s/*.png" % FIG_DIR)
