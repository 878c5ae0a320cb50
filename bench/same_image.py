#!/usr/bin/python3
"""same_image.py — do two murk builds estimate the same expected image?

    /usr/bin/python3 bench/same_image.py --old OLD/murk --new NEW/murk [--seeds 6] [--spp 128] [--res 40]
                                         [--block 4] [--out DIR]
    /usr/bin/python3 bench/same_image.py --self-test

For changes that alter pixels but must not alter the expectation (another order of drawing random
numbers, a faster log in free-flight sampling, ...): the build before the change (--old) and the build
with it (--new) render the three scenes of tests/test_roulette_long.c — scenes/cornell.yaml (path),
scenes/cornell_smoke.yaml (its cloud, volpath_nee) and a constant chromatic medium in the same box
(delta tracking) — and the Cornell box with a sphere for its short block (a scene's few spheres are
intersected by murk's host, not Embree) --seeds times each at --res x --res and --spp, on 2 threads, old and new with
different seeds so that their estimates are independent. Then, per scene, the block-wise z-test of
tests/testutil.c's img_stack_agree, mirrored here: per pixel and channel (r, g, b and their average)
the mean over the seeds and the variance of that mean; per block of --block x --block pixels and
channel the difference of the block means over its standard error. The two agree when no block's
|z| exceeds STAT_Z (tests/stat.h: 5) in r, g or b and the mean over the blocks of the channel-average z
is within STAT_Z / sqrt(nblocks) of 0; fewer than 16 blocks with signal is a failure (too little to
judge).

Must fail, per scene: the new build with the lamp (shapes.5 in both scenes) 1 % brighter against the
old build must be reported as differing; if it agrees, these sizes cannot see a 1 % change and the
script says so. One line per comparison: the worst block's |z|, the mean z, the old build's block
standard error in percent and the verdict. Exit 0 only when every scene agrees and every must-fail case
differs; 1 otherwise (2: a render failed or dropped NaN/inf samples).

Renders go to DIR (default: a temporary folder, removed at the end). --self-test runs the statistic
on synthetic stacks (no rendering): the same mean agrees, one block shifted by 10 standard errors
differs, a global 1 % shift under small noise differs (through the mean z: no block alone shows it),
too few blocks with signal fails.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tools"))
import exrio  # noqa: E402

STAT_Z = 5.0  # tests/stat.h
MIN_BLOCKS = 16  # tests/testutil.c: fewer blocks with signal is too little to judge

# tests/test_roulette_long.c's three cases and a sphere: (label, scene file, its --set overrides)
SCENES = [
    ("cornell", "cornell.yaml", []),
    ("cornell_smoke", "cornell_smoke.yaml", []),
    ("constant chromatic medium", "cornell_smoke.yaml",
     ["--set", "media.smoke.type=delta", "--set", "media.smoke.density={constant: 1}",
      "--set", "media.smoke.sigma_a=[0.05, 0.1, 0.3]", "--set", "media.smoke.sigma_s=[1.2, 0.8, 0.4]",
      "--set", "media.smoke.g=0.2"]),
    ("cornell, a sphere", "cornell.yaml",
     ["--set", "shapes.7={type: sphere, center: [0.35, 0.3, 0.25], radius: 0.3, material: white}"]),
]
BRIGHTER = ["--set", "shapes.5.emission=[17.17, 12.12, 4.04]"]  # the lamp of both scenes, 1.01 x
SEED0 = {"old": 100, "new": 200, "bright": 300}  # disjoint seeds: independent estimates


def stack(images):
    """(mean, var) of images (k, h, w, 3): per pixel and channel (r, g, b, their average) the mean over
    the k images and the variance of that mean (sample variance / k), as tests/testutil.c's
    img_stack_render."""
    x = np.asarray(images, dtype=np.float64)
    x = np.concatenate([x, x.mean(axis=3, keepdims=True)], axis=3)
    k = x.shape[0]
    return x.mean(axis=0), x.var(axis=0, ddof=1) / k


def compare(a, r, block):
    """tests/testutil.c's stack_compare of stack a against the reference stack r (each (mean, var)):
    a dict with ok, and the figures of its line."""
    (ma, va), (mr, vr) = a, r
    if ma.shape != mr.shape:
        raise ValueError("images of %s and %s pixels" % (ma.shape[:2], mr.shape[:2]))
    h, w = mr.shape[:2]
    nby, nbx, n = h // block, w // block, float(block * block)

    def sums(p):  # (nby, nbx, 4): per block and channel the sum over its pixels
        return p[:nby * block, :nbx * block].reshape(nby, block, nbx, block, 4).sum(axis=(1, 3))

    ma, mr, va, vr = sums(ma), sums(mr), sums(va), sums(vr)
    noisy = va + vr > 0.0  # all-black blocks have no variance and carry no information
    z = np.where(noisy, (ma - mr) / np.sqrt(np.where(noisy, va + vr, 1.0)), 0.0)
    # r, g, b: |z| of the noisy blocks; a difference without noise is certainly not the same image
    zabs = np.where(noisy, np.abs(z), np.where(ma != mr, np.inf, -1.0))[:, :, :3]
    nblocks = int(noisy[:, :, 3].sum())
    res = {"nblocks": nblocks, "zmax": 0.0, "where": (-1, -1, -1), "zmean": 0.0, "zm": 0.0, "se": 0.0}
    if zabs.size and zabs.max() > 0.0:
        by, bx, c = np.unravel_index(int(np.argmax(zabs)), zabs.shape)
        res["zmax"], res["where"] = float(zabs[by, bx, c]), (int(bx), int(by), int(c))
    if nblocks < MIN_BLOCKS:
        res["ok"] = False
        return res
    sel = noisy[:, :, 3]
    res["zmean"] = float(z[:, :, 3][sel].sum()) / nblocks
    res["zm"] = res["zmean"] * np.sqrt(nblocks)
    res["se"] = 100.0 * float((np.sqrt(vr[:, :, 3][sel]) / n).sum()) / float((mr[:, :, 3][sel] / n).sum())
    res["ok"] = bool(res["zmax"] <= STAT_Z and abs(res["zm"]) <= STAT_Z)
    return res


def line(label, res):
    if res["nblocks"] < MIN_BLOCKS:
        return "  %-56s only %d blocks with signal: DIFFER" % (label, res["nblocks"])
    bx, by, c = res["where"]
    return ("  %-56s max |z| %.2f (block %d,%d ch %d), mean z %+.3f over %d blocks (%+.2f se), block se %.2f%%: %s"
            % (label, res["zmax"], bx, by, c, res["zmean"], res["nblocks"], res["zm"], res["se"],
               "agree" if res["ok"] else "DIFFER"))


def die(msg):
    print("same_image: " + msg, file=sys.stderr)
    sys.exit(2)


def render_stack(murk, label, scene, extra, tag, args, out):
    """The stack of args.seeds renders of scene by murk, seeds SEED0[tag] + k, into out/LABEL_TAG_SEED.exr."""
    images = []
    for k in range(args.seeds):
        seed = SEED0[tag] + k
        path = os.path.join(out, "%s_%s_%d.exr" % (label.replace(" ", "_"), tag, seed))
        cmd = [murk, "render", scene, "--set", "render.resolution=[%d, %d]" % (args.res, args.res),
               "--spp", str(args.spp), "--set", "render.seed=%d" % seed, "--threads", "2", "--quiet",
               "-o", path] + extra
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if p.returncode != 0:
            die("%s failed (%d):\n%s" % (" ".join(cmd), p.returncode, p.stdout))
        nonfinite = exrio.meta(path).get("murk:nonfinite_samples")
        if nonfinite != "0":
            die("%s: %s NaN/inf samples" % (path, nonfinite or "(no count of)"))
        images.append(exrio.read(path))
    return stack(images)


def run(args):
    out = args.out or tempfile.mkdtemp(prefix="same_image_")
    os.makedirs(out, exist_ok=True)
    print("same_image: old %s, new %s; %d seeds x %d spp at %dx%d, %dx%d blocks, |z| <= %g"
          % (args.old, args.new, args.seeds, args.spp, args.res, args.res, args.block, args.block, STAT_Z))
    differ, missed = [], []
    try:
        for label, name, extra in SCENES:
            scene = os.path.join(ROOT, "scenes", name)
            old = render_stack(args.old, label, scene, extra, "old", args, out)
            new = render_stack(args.new, label, scene, extra, "new", args, out)
            bright = render_stack(args.new, label, scene, extra + BRIGHTER, "bright", args, out)
            res = compare(new, old, args.block)
            print(line("%s: new against old" % label, res))
            if not res["ok"]:
                differ.append(label)
            res = compare(bright, old, args.block)
            print(line("%s: lamp 1.01 x (must fail)" % label, res))
            if res["ok"]:
                missed.append(label)
            sys.stdout.flush()
    finally:
        if not args.out:
            shutil.rmtree(out, ignore_errors=True)
    if differ:
        print("same_image: the builds estimate different images on: %s" % ", ".join(differ))
    if missed:
        print("same_image: the must-fail case agreed on %s: at these sizes the check cannot see a 1 %% change"
              " (more --seeds or --spp)" % ", ".join(missed))
    if not differ and not missed:
        print("same_image: the same expected image on every scene; every must-fail case differs")
    return 1 if differ or missed else 0


def self_test():
    """The statistic on synthetic stacks; 0 if every case comes out as it must."""
    rng = np.random.default_rng(1)
    h = w = 40
    block, k = 4, 6
    truth = 0.2 + rng.random((h, w, 3))

    def noisy(mean, rel):  # k images of expectation mean, each pixel's noise rel x its value
        return mean[None] * (1.0 + rel * rng.standard_normal((k,) + mean.shape))

    ref = stack(noisy(truth, 0.3))
    failed = 0

    def case(label, a, r, want):
        nonlocal failed
        res = compare(a, r, block)
        bad = res["ok"] != want
        failed += bad
        print(line("%s (must %s)" % (label, "agree" if want else "differ"), res) + ("  <-- WRONG" if bad else ""))
        return res

    case("the same mean", stack(noisy(truth, 0.3)), ref, True)
    # one block shifted by 10 standard errors of its difference, in its noisiest channel (as testutil.c's
    # img_stack_must_differ_block)
    a = stack(noisy(truth, 0.3))
    by, bx = h // block // 2, w // block // 2
    sl = (slice(by * block, (by + 1) * block), slice(bx * block, (bx + 1) * block))
    m, v = a[0][sl][:, :, :3].sum(axis=(0, 1)), (a[1] + ref[1])[sl][:, :, :3].sum(axis=(0, 1))
    bias = float((10.0 * np.sqrt(v) / m).max())
    shifted = a[0].copy()
    shifted[sl] *= 1.0 + bias
    case("block (%d,%d) %+.2g%%" % (bx, by, 100.0 * bias), (shifted, a[1]), ref, False)
    # a global 1 % shift that no single block shows (each within STAT_Z): only the mean z over the blocks sees it
    res = case("global +1%, noise 5% a sample", stack(noisy(1.01 * truth, 0.05)), stack(noisy(truth, 0.05)), False)
    if res["zmax"] > STAT_Z:
        failed += 1
        print("  <-- WRONG: a block sees the global shift alone; the case does not test the mean z")
    dark = np.zeros_like(truth)  # black but for the top row of blocks: 10 blocks with signal, below 16
    dark[:block, :] = truth[:block, :]
    case("one row of blocks with signal", stack(noisy(dark, 0.3)), stack(noisy(dark, 0.3)), False)
    print("same_image --self-test: %s" % ("ok" if not failed else "%d case(s) WRONG" % failed))
    return 1 if failed else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--old", help="murk executable built before the change (the reference)")
    ap.add_argument("--new", help="murk executable built with the change")
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--spp", type=int, default=128)
    ap.add_argument("--res", type=int, default=40)
    ap.add_argument("--block", type=int, default=4)
    ap.add_argument("--out", help="folder for the renders (kept); default a temporary one")
    ap.add_argument("--self-test", action="store_true", help="the statistic on synthetic stacks, no rendering")
    args = ap.parse_args()
    if args.self_test:
        return self_test()
    if not args.old or not args.new:
        ap.error("--old and --new are required (or --self-test)")
    if args.seeds < 2:
        ap.error("--seeds must be at least 2 (the variance comes from the seeds)")
    return run(args)


if __name__ == "__main__":
    sys.exit(main())
