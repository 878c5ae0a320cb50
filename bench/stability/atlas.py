#!/usr/bin/python3
"""The stability atlas (issue 9): where each tracker and transmittance estimator degrades.

A small scene family — a medium (homogeneous or a procedural cloud) in a box, lit by an area light and a
constant background — is swept one parameter at a time around a base case, and every point is rendered
with every tracker (and, for the shadow rays, every unbiased transmittance estimator under delta).
Per point and method: non-finite samples, the largest sample over its pixel's reference mean, the
firefly rate (share of samples above 100x their pixel's reference mean), the relative variance of the pixel means (from the
samples themselves), time, density lookups (murk's cost counters), efficiency = 1 / (relative variance x
time) and 1 / (relative variance x lookups), each relative to delta's, and a bias
z-score of the image mean per channel against a reference: the closed form where one exists (the
absorbing homogeneous box seen from outside: E[pixel] = background x exp(-sigma_t x chord), integrated
over each pixel's footprint), else spectral_mis with a bounding majorant and control (majorant_factor
max(1, f), control 1) at 4x the samples and another seed.

    /usr/bin/python3 bench/stability/atlas.py            # the whole atlas: docs/stability.md (tens of minutes)
    /usr/bin/python3 bench/stability/atlas.py --quick    # the sweeps' extreme points, small images (seconds)
    options: --out DIR (default bench-out/stability), --docs (write docs/stability.md and its figures;
             the default without --quick), --check (exit 1 if a point has a non-finite sample or |z| > 5),
             --finite-only (no references, no z: judge only that every sample is finite; the default test
             suite's stability_quick: the z of 16 spp renders of heavy-tailed estimators is no
             calibrated test, so the bias check is left to the whole atlas, the suite 'stability')

Per-sample figures come from murk's hidden MURK_SAMPLE_DUMP (core/render/render.c). Needs Debian's
python3-numpy and python3-matplotlib (tools/build.sh installs them)."""
import argparse, json, math, os, re, subprocess, sys, time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MURK = os.environ.get("MURK_EXE", os.path.join(ROOT, "build", "core", "murk"))
TRACKERS = ["delta", "decomposition", "spectral", "spectral_mis", "naive_spectral"]
ESTIMATORS = ["ratio", "residual_ratio", "track_length", "unbiased_raymarch", "power_series"]
BG = (0.4, 0.45, 0.5)

# The sweeps: name -> (values, the key it sets, which methods, media). Base case: grey extinction 1.5 per unit
# density (optical depth 3 across the homogeneous box), albedo 0.8, g 0, majorant_factor 1, resolution 16,
# control 1, camera outside.
SWEEPS = [
    ("chroma", [1, 3, 10, 100, 1000], "extinction ratio 1:r across the channels (albedo 0.8 each)"),
    ("albedo", [0, 0.5, 0.9, 0.99, 0.999, 1], "single-scattering albedo"),
    ("density", [1e-4, 1e-2, 1, 1e2, 1e4], "density scale (x the base optical depth 3)"),
    ("majorant_factor", [0.25, 0.5, 0.9, 1, 2, 8, 32], "majorant_factor (majorant_repair: true, the default)"),
    ("majorant_factor_norepair", [0.25, 0.5, 0.9], "majorant_factor with majorant_repair: false"),
    ("majorant_resolution", [1, 4, 16, 64, 128], "majorant_resolution (cells along the box)"),
    ("control", [0, 0.5, 1, 2, 5, 10], "decomposition control (repair: true, the default)"),
    ("control_norepair", [2, 5, 10], "decomposition control with repair: false"),
    ("g", [-0.99, -0.5, 0, 0.5, 0.99], "Henyey-Greenstein g"),
    ("roughness", [0, 0.05, 0.2, 0.5, 1], "GGX roughness, a surface inside the medium seen at grazing incidence"),
    ("camera", ["outside", "inside"], "camera outside / inside the medium"),
    ("absorber", [0.01, 0.3, 1, 3], "absorbing homogeneous box (albedo 0): density scale; closed form"),
]
SWEEP_DOC = {s[0]: s[2] for s in SWEEPS}


def point_params(sweep, v):
    p = dict(chroma=1, albedo=0.8, density=1.0, majorant_factor=1, majorant_repair=True, majorant_resolution=16,
             control=1, control_repair=True, g=0, roughness=None, camera="outside")
    if sweep == "majorant_factor_norepair":
        p.update(majorant_factor=v, majorant_repair=False)
    elif sweep == "control_norepair":
        p.update(control=v, control_repair=False)
    elif sweep == "absorber":
        p.update(albedo=0, density=v)
    else:
        p[sweep] = v
    return p


def scene_yaml(p, medium, tracker, estimator, res, spp, seed):
    r = float(p["chroma"])
    st = [1.5 / math.sqrt(r), 1.5, 1.5 * math.sqrt(r)]
    a = p["albedo"]
    ss = [a * x for x in st]
    sa = [(1 - a) * x for x in st]
    if medium == "homogeneous":
        dens = "{ constant: 1 }"
    else:
        dens = ("{ cloud: { min: [-1, -1, -1], max: [1, 1, 1], seed: 3, frequency: 2, octaves: 4, coverage: 0.6, "
                "resolution: 40 } }")
    keys = ["type: %s" % tracker, "density: %s" % dens, "sigma_a: [%.9g, %.9g, %.9g]" % tuple(sa),
            "sigma_s: [%.9g, %.9g, %.9g]" % tuple(ss), "scale: %.9g" % p["density"], "g: %g" % p["g"],
            "majorant_factor: %g" % p["majorant_factor"], "majorant_resolution: %d" % p["majorant_resolution"]]
    if not p["majorant_repair"]:
        keys.append("majorant_repair: false")
    if tracker == "decomposition":
        keys.append("control: %g" % p["control"])
        if not p["control_repair"]:
            keys.append("repair: false")
    if estimator:
        keys.append("transmittance: %s" % estimator)
    if p["camera"] == "inside":
        cam = "{ from: [0, -0.2, 0.6], at: [0, 0, -1], up: [0, 1, 0], fov: 60, medium: m }"
    elif p["roughness"] is not None:
        cam = "{ from: [0, -0.45, 3.5], at: [0, -0.55, 0], up: [0, 1, 0], fov: 30 }"
    else:
        cam = "{ from: [0, 0, 4], at: [0, 0, 0], up: [0, 1, 0], fov: 30 }"
    shapes = ["  - { type: quad, center: [0, 2.5, 0], u: [0.6, 0, 0], v: [0, 0, 0.6], material: light, "
              "emission: [12, 12, 12] }",
              "  - { type: box, min: [-1, -1, -1], max: [1, 1, 1], interior: m }"]
    if p["roughness"] is not None:
        shapes.append("  - { type: quad, center: [0, -0.6, 0], u: [0, 0, 0.9], v: [0.9, 0, 0], material: surf }")
    return "\n".join([
        "murk: 1",
        "render: { resolution: [%d, %d], spp: %d, seed: %d }" % (res, res, spp, seed),
        "camera: %s" % cam,
        "integrator: { type: volpath_nee, max_depth: 64 }",
        "background: [%g, %g, %g]" % BG,
        "materials:",
        "  light: { type: diffuse, albedo: [0, 0, 0] }"] +
        # murk render refuses a material no shape uses: surf only with its quad
        (["  surf: { type: ggx, albedo: [0.1, 0.1, 0.1], specular: [0.9, 0.9, 0.9], roughness: %g }"
          % p["roughness"]] if p["roughness"] is not None else []) + [
        "media:",
        "  m: { %s }" % ", ".join(keys),
        "shapes:"] + shapes) + "\n"


def render(path, out, res, spp):
    """Renders; returns (seconds, samples as an (npix, spp, 3) float32 array)."""
    dump = out + ".samples"
    env = dict(os.environ, MURK_SAMPLE_DUMP=dump)
    r = subprocess.run([MURK, "render", path, "-o", out + ".exr"], capture_output=True, text=True, env=env)
    if r.returncode != 0:
        sys.exit("murk render %s failed:\n%s%s" % (path, r.stdout, r.stderr))
    m = re.search(r"(\d+) spp, ([0-9.]+) s", r.stdout + r.stderr)
    secs = float(m.group(2)) if m else float("nan")
    m = re.search(r"medium 'm': (\d+) lookups", r.stdout + r.stderr)  # murk's cost counters
    lookups = int(m.group(1)) if m else -1
    x = np.fromfile(dump, dtype=np.float32).reshape(res * res, spp, 3)
    os.remove(dump)
    warn = sorted(set(l for l in (r.stdout + r.stderr).splitlines() if "warning" in l))
    return secs, lookups, x, warn


def camera_dirs(p, res, sub):
    """Ray origin and directions of sub x sub stratified points per pixel (as render.c's camera_ray)."""
    if p["camera"] == "inside" or p["roughness"] is not None:
        return None
    frm, at, up, fov = np.array([0, 0, 4.0]), np.zeros(3), np.array([0, 1.0, 0]), 30.0
    w = (at - frm) / np.linalg.norm(at - frm)
    u = np.cross(w, up)
    u /= np.linalg.norm(u)
    v = np.cross(u, w)
    tn = math.tan(0.5 * fov * math.pi / 180)
    s = (np.arange(sub) + 0.5) / sub
    fx = (np.arange(res)[:, None] + s[None, :]).reshape(-1)
    px = (2 * fx / res - 1) * tn
    py = (1 - 2 * fx / res) * tn
    d = w[None, None, :] + u[None, None, :] * px[None, :, None] + v[None, None, :] * py[:, None, None]
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    return frm, d  # d[iy*sub.., ix*sub.., 3]


def closed_form(p, res):
    """E[pixel] for the absorbing homogeneous box seen from outside: bg x exp(-sigma_t x chord)."""
    cd = camera_dirs(p, res, 32)
    if cd is None:
        return None
    o, d = cd
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-1 - o) / d
        t2 = (1 - o) / d
    tin = np.max(np.minimum(t1, t2), axis=2)
    tout = np.min(np.maximum(t1, t2), axis=2)
    chord = np.clip(tout - np.maximum(tin, 0), 0, None)
    r = float(p["chroma"])
    st = np.array([1.5 / math.sqrt(r), 1.5, 1.5 * math.sqrt(r)]) * p["density"]
    T = np.exp(-chord[:, :, None] * st[None, None, :]) * np.array(BG)[None, None, :]
    T = T.reshape(res, 32, res, 32, 3).mean(axis=(1, 3))
    # pixels on the box's silhouette: the 32x32 quadrature of a step is not exact there; left out of the z
    hit = (chord > 0).reshape(res, 32, res, 32).mean(axis=(1, 3))
    edge = ((hit > 0) & (hit < 1)).reshape(res * res)
    return T.reshape(res * res, 3), edge


def lum(x):
    return 0.2126 * x[..., 0] + 0.7152 * x[..., 1] + 0.0722 * x[..., 2]


def stats(x, ref=None):
    """Per-pixel means and variances of the means; fireflies and the largest sample relative to the
    reference's pixel mean (the true pixel value: a sample's own pixel mean at n spp can never exceed n
    times itself), floored at 1% of the image's mean so that a bright sample in a black pixel counts."""
    finite = np.isfinite(x).all(axis=2)
    nonfinite = int((~finite).sum())
    xf = np.where(finite[:, :, None], x, 0.0).astype(np.float64)
    n = np.maximum(finite.sum(axis=1), 1)
    mean = xf.sum(axis=1) / n[:, None]
    var = ((xf - mean[:, None, :]) ** 2 * finite[:, :, None]).sum(axis=1) / np.maximum(n - 1, 1)[:, None]
    L = lum(xf)
    Lm = lum(mean if ref is None else ref)
    Lm = np.maximum(Lm, 0.01 * max(float(Lm.mean()), 1e-12))
    ratio = np.abs(L) / Lm[:, None]
    fire = float(((ratio > 100) & finite).sum()) / float(finite.sum() if finite.sum() else 1)
    return dict(spp=x.shape[1], nonfinite=nonfinite, mean=mean, var_mean=var / n[:, None], maxratio=float(ratio.max()), fire=fire)


def relvar(s):
    return float(np.mean(s["var_mean"] / (s["mean"] ** 2 + 0.01)))


def zscore(s, ref_mean, ref_var, mask=None):
    """Largest |z| over channels of the image mean, and over 4x4 blocks (the block maximum of 48 figures);
    pixels where mask is true are left out."""
    npix = s["mean"].shape[0]
    res = int(round(math.sqrt(npix)))
    d = s["mean"] - ref_mean
    if mask is not None:
        d = np.where(mask[:, None], 0.0, d)
    # the closed form's quadrature and float rounding: 1e-5 relative per pixel
    v = s["var_mean"] + (ref_var if ref_var is not None else (1e-5 * ref_mean) ** 2) + 1e-12
    zimg = d.sum(axis=0) / np.sqrt(np.maximum(v.sum(axis=0), 1e-300))
    zi = float(zimg[np.argmax(np.abs(zimg))])
    b = 4
    dd = d.reshape(b, res // b, b, res // b, 3).sum(axis=(1, 3))
    vv = v.reshape(b, res // b, b, res // b, 3).sum(axis=(1, 3))
    zb = dd / np.sqrt(np.maximum(vv, 1e-300))
    # a block of few samples can see no variance at all (every sample equal, e.g. all passing an absorber
    # unhit): its z means nothing; blocks are only scored from 2000 samples up
    return zi, float(np.abs(zb).max()) if s["spp"] * npix // (b * b) >= 2000 else float("nan")


def run(a):
    out = a.out
    os.makedirs(out, exist_ok=True)
    rows = []
    res, spp, ref_spp = (12, 16, 64) if a.quick else (a.res, a.spp, 4 * a.spp)
    media = ["cloud"] if a.quick else ["homogeneous", "cloud"]
    t_start = time.time()
    rendered = set()  # --quick: scenes already rendered (the base case is the chroma and camera sweeps' first point)
    for sweep, values, _ in SWEEPS:
        if a.quick:
            values = [values[0], values[-1]]
        for medium in media:
            if sweep == "majorant_resolution" and medium == "homogeneous":
                continue  # one cell is exact for a constant density
            if sweep == "absorber" and medium == "cloud":
                if a.quick:
                    medium = "homogeneous"
                else:
                    continue  # the closed form is for the homogeneous box
            trackers = ["decomposition"] if sweep.startswith("control") else TRACKERS
            methods = [(t, None) for t in trackers]
            if sweep in ("density", "majorant_factor", "chroma", "absorber") and not a.quick:
                methods += [("delta", e) for e in ESTIMATORS]
            for v in values:
                p = point_params(sweep, v)
                tag = "%s_%s_%s" % (sweep, medium, v)
                cf = closed_form(p, res) if (medium == "homogeneous" and p["albedo"] == 0) else None
                ref, mask = cf if cf is not None else (None, None)
                ref_var, ref_kind = None, "closed form"
                if ref is None and a.finite_only:
                    ref_kind = "none"
                elif ref is None:
                    rp = dict(p, majorant_factor=max(1, p["majorant_factor"]), majorant_repair=True, control=1)
                    path = os.path.join(out, tag + "_ref.yaml")
                    with open(path, "w") as f:
                        f.write(scene_yaml(rp, medium, "spectral_mis", None, res, ref_spp, 777))
                    _, _, x, _ = render(path, os.path.join(out, tag + "_ref"), res, ref_spp)
                    rs = stats(x)
                    ref, ref_var, ref_kind = rs["mean"], rs["var_mean"], "spectral_mis %d spp" % ref_spp
                for tracker, est in methods:
                    name = tracker + ("+" + est if est else "")
                    text = scene_yaml(p, medium, tracker, est, res, spp, 1)
                    if a.quick and text in rendered:
                        continue
                    rendered.add(text)
                    path = os.path.join(out, "%s_%s.yaml" % (tag, name))
                    with open(path, "w") as f:
                        f.write(text)
                    secs, lookups, x, warn = render(path, os.path.join(out, "%s_%s" % (tag, name)), res, spp)
                    s = stats(x, ref)
                    zi, zb = zscore(s, ref, ref_var, mask) if ref is not None else (0.0, float("nan"))
                    rv = relvar(s)
                    row = dict(sweep=sweep, medium=medium, value=v, method=name, nonfinite=s["nonfinite"],
                               maxratio=s["maxratio"], firefly=s["fire"], relvar=rv, seconds=secs,
                               eff=1.0 / (rv * secs) if rv > 0 and secs > 0 else float("inf"), lookups=lookups,
                               eff_lookups=1.0 / (rv * lookups) if rv > 0 and lookups > 0 else float("nan"),
                               z=zi, zblock=zb,
                               ref=ref_kind, warnings=warn)
                    rows.append(row)
                    print("%-26s %-12s %-7s %-30s nonfinite %d  max/mean %9.3g  fireflies %.2e  relvar %.3e  "
                          "%6.2f s  z %+6.2f  zblock %5.2f" % (sweep, medium, v, name, s["nonfinite"], s["maxratio"],
                                                               s["fire"], rv, secs, zi, zb), flush=True)
    for r in rows:  # efficiency relative to delta (same sweep, medium, value; delta's own shadow rays)
        base = [q for q in rows if q["sweep"] == r["sweep"] and q["medium"] == r["medium"] and
                q["value"] == r["value"] and q["method"] == "delta"]
        r["eff_rel"] = r["eff"] / base[0]["eff"] if base and base[0]["eff"] > 0 else float("nan")
        bl = base[0]["eff_lookups"] if base else float("nan")
        r["eff_lookups_rel"] = r["eff_lookups"] / bl if bl > 0 and r["eff_lookups"] > 0 else float("nan")
    meta = dict(res=res, spp=spp, ref_spp=ref_spp, quick=a.quick, minutes=(time.time() - t_start) / 60.0,
                violations=[] if a.quick else violations(out))
    meta["minutes_all"] = (time.time() - t_start) / 60.0
    with open(os.path.join(out, "atlas.json"), "w") as f:
        json.dump(dict(meta=meta, rows=rows), f, indent=0, default=str)
    print("atlas: %d renders in %.1f min (%s)" % (len(rows), meta["minutes"], os.path.join(out, "atlas.json")))
    return meta, rows


# Item 0's figure: relMSE at equal spp against a bounding reference on two of murk's own scenes, for wrong
# majorants and controls with murk's repairs (the default) and without them (the per-flight repair only).
VIOLATIONS = [
    ("cornell_smoke", "smoke", [
        ("delta, majorant_factor 1 (bounding)", []),
        ("delta, majorant_factor 0.9", ["majorant_factor=0.9"]),
        ("delta, majorant_factor 0.5", ["majorant_factor=0.5"]),
        ("delta, majorant_factor 0.25", ["majorant_factor=0.25"]),
        ("delta, majorant_factor 0.9, majorant_repair false", ["majorant_factor=0.9", "majorant_repair=false"]),
        ("delta, majorant_factor 0.5, majorant_repair false", ["majorant_factor=0.5", "majorant_repair=false"]),
        ("decomposition, control 1 (bounding)", ["type=decomposition"]),
        ("decomposition, control 1.5", ["type=decomposition", "control=1.5"]),
        ("decomposition, control 10", ["type=decomposition", "control=10"]),
        ("decomposition, control 1.5, repair false", ["type=decomposition", "control=1.5", "repair=false"]),
    ]),
    ("spectral_extinction", "medium", [
        ("spectral, majorant_factor 1 (bounding)", []),
        ("spectral, majorant_factor 0.25", ["majorant_factor=0.25"]),
        ("spectral_mis, majorant_factor 1 (bounding)", ["type=spectral_mis"]),
        ("spectral_mis, majorant_factor 0.25", ["type=spectral_mis", "majorant_factor=0.25"]),
        ("decomposition, control 1 (bounding)", ["type=decomposition"]),
        ("decomposition, control 10", ["type=decomposition", "control=10"]),
        ("spectral, majorant_factor 0.25, majorant_repair false", ["majorant_factor=0.25", "majorant_repair=false"]),
    ]),
]


def violations(out, res=96, spp=32, ref_spp=256):
    rows = []
    for scene, medium, variants in VIOLATIONS:
        path = os.path.join(ROOT, "scenes", scene + ".yaml")
        size = ["--set", "render.resolution=[%d,%d]" % (res, res)]
        ref = os.path.join(out, "viol_%s_ref.exr" % scene)
        r = subprocess.run([MURK, "render", path, "-o", ref, "--spp", str(ref_spp), "--set", "render.seed=99",
                            "--set", "media.%s.type=spectral_mis" % medium] + size, capture_output=True, text=True)
        if r.returncode:
            sys.exit(r.stderr)
        for i, (label, sets) in enumerate(variants):
            img = os.path.join(out, "viol_%s_%d.exr" % (scene, i))
            args = [MURK, "render", path, "-o", img, "--spp", str(spp)] + size
            for kv in sets:
                args += ["--set", "media.%s.%s" % (medium, kv)]
            r = subprocess.run(args, capture_output=True, text=True)
            if r.returncode:
                sys.exit(r.stderr)
            m = re.search(r"(\d+) spp, ([0-9.]+) s", r.stdout + r.stderr)
            c = subprocess.run([MURK, "compare", img, ref], capture_output=True, text=True).stdout
            e = float(re.search(r"relMSE ([0-9.e+-]+)", c).group(1))
            warn = [l for l in (r.stdout + r.stderr).splitlines() if "warning" in l]
            rows.append(dict(scene=scene, variant=label, relmse=e, seconds=float(m.group(2)) if m else float("nan"),
                             warning=warn[0] if warn else ""))
            print("%-20s %-55s relMSE %.3e  %.2f s" % (scene, label, e, rows[-1]["seconds"]), flush=True)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=os.path.join(ROOT, "bench-out", "stability"))
    ap.add_argument("--res", type=int, default=24)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--docs", action="store_true")
    ap.add_argument("--no-docs", action="store_true")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--finite-only", action="store_true")
    ap.add_argument("--from-json", help="skip the renders: make the docs from an earlier atlas.json")
    a = ap.parse_args()
    if a.from_json:
        with open(a.from_json) as f:
            j = json.load(f)
        meta, rows = j["meta"], j["rows"]
    else:
        meta, rows = run(a)
    if (a.docs or not a.quick) and not a.no_docs:
        import atlas_doc
        atlas_doc.write(ROOT, meta, rows, SWEEP_DOC)
    bad = [r for r in rows if r["nonfinite"] or abs(r["z"]) > 5]
    for r in bad:
        print("FAIL %s %s %s %s: nonfinite %d, z %.2f" % (r["sweep"], r["medium"], r["value"], r["method"],
                                                          r["nonfinite"], r["z"]))
    if a.check and bad:
        sys.exit(1)


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    main()
