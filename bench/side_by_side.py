#!/usr/bin/python3
"""side_by_side.py — murk's efficiency against Tungsten's and pbrt-v4's on the same scenes, in interleaved rounds.

Usage:
  /usr/bin/python3 bench/side_by_side.py OUTDIR --murk build/core/murk [--murk B=other/murk ...]
        [--tungsten BIN] [--pbrt BIN] [--scenes-dir DIR] [--cloud] [--rounds K] [--spp N] [--ref-spp N]
        [--threads 2] [--set KEY=VALUE ...]

Scenes. With --scenes-dir DIR: every NAME that DIR holds as NAME.yaml (murk), NAME/scene.json (Tungsten)
and NAME.pbrt (pbrt-v4), written from one description each (the peers kit's scene writer makes
cbox_sphere and cbox_volume so; a renderer whose file is missing is left out). With --cloud:
bench/pbrt_cloud.py's heterogeneous cloud (cornell_smoke.yaml's, grey) for murk and pbrt-v4, written
into OUTDIR/cloud/.

Reference per scene: OUTDIR/ref_NAME.pfm or .exr if present, else rendered once at --ref-spp by
Tungsten (when the scene has a Tungsten file) or by the first murk, and kept.

Rounds. Each round renders every scene with every renderer once, at --spp samples per pixel on
--threads threads, with a seed of its own (independent errors from round to round), the renderers' order
reversed every other round (A B C, C B A, ...) so drift on a shared machine falls on both sides. Each
render is timed as a whole process (load, build, render, write), in wall seconds and in CPU seconds (the
kernel's user + system time of the finished child; steadier than wall time on a loaded machine, but it
also counts a renderer's idle threads that spin). Per render: relMSE against the reference (mean over
pixels and channels of (x - ref)^2 / (ref^2 + 0.01), as the peers kit's compare.py) and efficiency
1 / (relMSE x seconds). Printed per scene: each renderer's median over the rounds of seconds, relMSE and
efficiency (wall and CPU), murk's efficiency over each peer's per round (median, min and max), and each
renderer's image mean over the rounds beside the reference's — the check figure: a faster renderer with a
different mean is rendering something else.
"""
import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tools"))
sys.path.insert(0, HERE)
import exrio  # noqa: E402
from pbrt_lights import read_pfm  # noqa: E402


def read_img(path):
    return read_pfm(path) if path.endswith(".pfm") else exrio.read(path).astype(np.float64)


def run(cmd, cwd, log):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    with open(log, "w") as f:
        r = subprocess.run(cmd, cwd=cwd, stdout=f, stderr=subprocess.STDOUT)
    wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        sys.exit("side_by_side: %s failed (exit %d), log %s" % (" ".join(cmd), r.returncode, log))
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def pbrt_seeded(path, seed):
    """pbrt-v4's Sampler "integer seed" overrides its --seed option: a copy of the scene beside it with the
    seed set (so that every round's render has errors of its own)."""
    text = open(path).read()
    if not re.search(r'"integer seed"', text):
        return path
    copy = path[:-5] + ".seed%d.pbrt" % seed
    open(copy, "w").write(re.sub(r'"integer seed"\s*\[\s*-?\d+\s*\]', '"integer seed" [ %d ]' % seed, text))
    return copy


def command(a, kind, exe, scene, spp, seed, out):
    """The command line rendering scene (a dict of the renderers' files) with renderer `kind`."""
    if kind == "tungsten":
        return [exe, "-t", str(a.threads), "-s", str(seed), "--spp", str(spp), "-e", out, scene["tungsten"]]
    if kind == "pbrt":
        return [exe, "--nthreads", str(a.threads), "--quiet", "--seed", str(seed), "--spp", str(spp), "--outfile", out,
                pbrt_seeded(scene["pbrt"], seed)]
    cmd = [exe, "render", scene["murk"], "-o", out, "--quiet", "--threads", str(a.threads), "--spp", str(spp),
           "--set", "render.seed=%d" % seed]
    for kv in a.set:
        cmd += ["--set", kv]
    return cmd


def scenes_of(a):
    found = {}
    if a.scenes_dir:
        d = os.path.abspath(a.scenes_dir)
        for f in sorted(os.listdir(d)):
            if f.endswith(".yaml"):
                name = f[:-5]
                s = {"murk": os.path.join(d, f), "dir": d}
                if os.path.exists(os.path.join(d, name, "scene.json")):
                    s["tungsten"] = os.path.join(d, name, "scene.json")
                if os.path.exists(os.path.join(d, name + ".pbrt")):
                    s["pbrt"] = os.path.join(d, name + ".pbrt")
                found[name] = s
    if a.cloud:
        import pbrt_cloud
        d = os.path.join(os.path.abspath(a.outdir), "cloud")
        y, p = pbrt_cloud.write(a.murks[0][1], d, a.res, a.spp)
        found["cloud"] = {"murk": y, "pbrt": p, "dir": d}
    return found


def reference(a, name, s):
    for ext in (".pfm", ".exr"):
        p = os.path.join(a.outdir, "ref_" + name + ext)
        if os.path.exists(p):
            return read_img(p)
    kind, exe = ("tungsten", a.tungsten) if "tungsten" in s and a.tungsten else ("murk", a.murks[0][1])
    p = os.path.join(a.outdir, "ref_%s%s" % (name, ".pfm" if kind == "tungsten" else ".exr"))
    print("%s: reference, %s at %d spp ..." % (name, kind, a.ref_spp), flush=True)
    run(command(a, kind, exe, s, a.ref_spp, 1234567, p), s["dir"], p + ".log")
    return read_img(p)


def relmse(img, ref):
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + 1e-2)))


def spread(xs):
    return "%.3g [%.3g..%.3g]" % (statistics.median(xs), min(xs), max(xs))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir")
    ap.add_argument("--murk", action="append", required=True, help="murk's binary; LABEL=PATH for several")
    ap.add_argument("--tungsten")
    ap.add_argument("--pbrt")
    ap.add_argument("--scenes-dir")
    ap.add_argument("--cloud", action="store_true")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--res", type=int, default=256, help="the cloud scene's resolution")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--set", action="append", default=[], help="KEY=VALUE for murk's renders")
    a = ap.parse_args()
    os.makedirs(a.outdir, exist_ok=True)
    a.murks = [(m.split("=", 1) if "=" in m else ("murk", m)) for m in a.murk]
    a.murks = [(lab, os.path.abspath(p)) for lab, p in a.murks]
    a.tungsten = a.tungsten and os.path.abspath(a.tungsten)
    a.pbrt = a.pbrt and os.path.abspath(a.pbrt)
    scenes = scenes_of(a)
    if not scenes:
        sys.exit("side_by_side: no scenes (--scenes-dir DIR and/or --cloud)")
    print("load average at start: %.2f %.2f %.2f" % os.getloadavg())
    for name, s in scenes.items():
        ref = reference(a, name, s)
        sides = [(lab, "murk", exe) for lab, exe in a.murks]
        sides += [(k, k, getattr(a, k)) for k in ("tungsten", "pbrt") if k in s and getattr(a, k)]
        res = {lab: {"wall": [], "cpu": [], "rel": [], "mean": []} for lab, _, _ in sides}
        for k in range(a.rounds):
            order = sides if k % 2 == 0 else sides[::-1]
            for lab, kind, exe in order:
                out = os.path.join(a.outdir, "%s_%s_%d.%s" % (name, lab, k, "pfm" if kind != "murk" else "exr"))
                wall, cpu = run(command(a, kind, exe, s, a.spp, 100 + k, out), s["dir"], out + ".log")
                img = read_img(out)
                r = res[lab]
                r["wall"].append(wall), r["cpu"].append(cpu), r["rel"].append(relmse(img, ref))
                r["mean"].append(float(img.mean()))
            print("%s round %d: %s" % (name, k + 1, "  ".join(
                "%s %.2fs/%.2fcpu relMSE %.4g" % (lab, res[lab]["wall"][-1], res[lab]["cpu"][-1], res[lab]["rel"][-1])
                for lab, _, _ in sides)), flush=True)
        print("\n%s: %d rounds at %d spp, %d threads; reference mean %.5f; load average now %.2f" % (
            name, a.rounds, a.spp, a.threads, float(ref.mean()), os.getloadavg()[0]))
        print("  %-10s %18s %18s %20s %20s %20s  %s" % ("renderer", "wall s", "CPU s", "relMSE", "eff (wall)",
                                                         "eff (CPU)", "image mean"))
        for lab, _, _ in sides:
            r = res[lab]
            r["ew"] = [1 / (e * t) for e, t in zip(r["rel"], r["wall"])]
            r["ec"] = [1 / (e * t) for e, t in zip(r["rel"], r["cpu"])]
            print("  %-10s %18s %18s %20s %20s %20s  %.5f" % (lab, spread(r["wall"]), spread(r["cpu"]), spread(r["rel"]),
                                                              spread(r["ew"]), spread(r["ec"]), statistics.mean(r["mean"])))
        for lab, kind, _ in sides:
            if kind != "murk":
                continue
            for plab, pkind, _ in sides:
                if pkind == "murk" and plab == lab:
                    continue
                for key, what in (("ew", "wall"), ("ec", "CPU")):
                    q = [x / y for x, y in zip(res[lab][key], res[plab][key])]
                    print("  %s / %s efficiency (%s): %s" % (lab, plab, what, spread(q)))


if __name__ == "__main__":
    main()
