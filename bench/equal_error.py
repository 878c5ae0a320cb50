#!/usr/bin/python3
"""Equal-error figures (issue 15): relMSE at equal spp and efficiency 1 / (relMSE x time) for
(independent, sobol) x (before, after the media changes) on three scenes, measured in one run.

    /usr/bin/python3 bench/equal_error.py [--res 64] [--spp 64] [--ref-spp 2048] [--rounds 3]
                                          [--threads 2] [--scenes cornell,medium,cloud] [--out DIR]
                                          [--samplers independent,sobol] [--variants before,after] [--crop X,Y,W,H]
                                          [--seed0 1]

Scenes: `cornell` (scenes/cornell.yaml, path), `medium` (scenes/cornell_smoke.yaml with a constant
chromatic medium in its box, decomposition tracker, volpath_nee), `cloud` (cornell_smoke.yaml as it is,
the procedural cloud, decomposition tracker) and, only when asked for (`--scenes ...,lamp`), `lamp`
(test_boundaries' box scene: a large lamp close above a medium box, for light sampling) and `fog`
(scenes/fog_lamp.yaml: a small lamp inside thin fog, for equiangular sampling). Each scene gets a converged reference (sobol, --ref-spp,
seed 1000; rendered once and kept in DIR). Then `--rounds` rounds, each rendering every configuration
once in turn (interleaved, so a drift of the machine's speed hits all of them alike) with the round's own
seed. Error: `murk compare`'s relMSE against the reference, averaged over the rounds (it is an
expectation). Time: the render's CPU seconds (user + system, from the kernel's accounting of the child):
on a machine shared with other work the wall time measures the other work too. Printed per configuration:
mean relMSE, median CPU time and the efficiency 1 / (relMSE x time) relative to the first configuration
(the first sampler, the first variant: independent, before),
with the spread (min..max) of the per-round ratios. A CSV of every render goes to DIR/equal_error.csv.

"before" switches the media changes of issue 15 off through the integrator's and the medium's parameters
(`light_sampling: area`, `rr_threshold: 1`, `stratify_flights: false`), "after" is the defaults; `--variants before,solid_angle,rr0.1,equiangular,after`
measures each candidate alone too (`equiangular`: volpath_nee's `equiangular: true`, off by default;
`smis`: the spectral_mis tracker, `closed_form`: spectral_mis with `closed_form: true`, `cf+eq`: both);
`noflight` is "after" with the medium's stratified free flights off (`stratify_flights: false`: every
number of a flight from the PCG stream), e.g.
`--scenes cloud,cloud_delta,medium,medium_delta,grey --samplers sobol --variants noflight,after`. The reference renders with the defaults; every
configuration estimates the same image (tests/test_boundaries.c's z-tests check that)."""
import argparse, csv, os, re, resource, statistics, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MURK = os.environ.get("MURK", os.path.join(ROOT, "build", "core", "murk"))  # MURK=path: another build

MEDIUM = ["--set", "media.smoke.type=decomposition", "--set", "media.smoke.density={constant: 1}",
          "--set", "media.smoke.sigma_a=[0.05, 0.1, 0.3]", "--set", "media.smoke.sigma_s=[1.2, 0.8, 0.4]",
          "--set", "media.smoke.g=0.2"]
SCENES = {
    "cornell": ("cornell.yaml", []),
    "medium": ("cornell_smoke.yaml", MEDIUM),
    "cloud": ("cornell_smoke.yaml", ["--set", "media.smoke.type=decomposition"]),
    # only when asked for (--scenes ...): the same media with delta tracking, and a homogeneous grey medium
    # (delta: there the first tentative collision of a flight is its scattering distance)
    "cloud_delta": ("cornell_smoke.yaml", ["--set", "media.smoke.type=delta"]),
    "medium_delta": ("cornell_smoke.yaml", MEDIUM + ["--set", "media.smoke.type=delta"]),
    "grey": ("cornell_smoke.yaml", ["--set", "media.smoke.type=delta", "--set", "media.smoke.density={constant: 1}",
                                    "--set", "media.smoke.sigma_a=[0.1, 0.1, 0.1]",
                                    "--set", "media.smoke.sigma_s=[0.9, 0.9, 0.9]", "--set", "media.smoke.g=0.2"]),
    "lamp": ("lamp.yaml", []),  # written into DIR (LAMP)
    "fog": ("fog_lamp.yaml", ["--set", "integrator.equiangular=false"]),
}
# `lamp`: test_boundaries' box scene (tests/test_lights.c): a 1 x 1 lamp just under the ceiling, a
# constant chromatic medium box right under it (delta tracker, volpath_nee), the lamp large in the
# solid angle of the box's top and of the walls near it. Written into DIR.
LAMP = """murk: 1
render: { resolution: [32, 32], spp: 64, seed: 0 }
camera: { from: [0, 1, 3.4], at: [0, 1, 0], up: [0, 1, 0], fov: 40 }
integrator: { type: volpath_nee, max_depth: 1000 }
materials:
  white: { type: diffuse, albedo: [0.73, 0.73, 0.73] }
  red: { type: diffuse, albedo: [0.5, 0.5, 0.5] }
  green: { type: diffuse, albedo: [0.3, 0.3, 0.3] }
media:
  smoke: { type: delta, density: { constant: 1 }, sigma_a: [0.05, 0.1, 0.2], sigma_s: [0.5, 0.5, 0.5] }
shapes:
  - { type: quad, center: [0, 0, 0], u: [0, 0, 1], v: [1, 0, 0], material: white }
  - { type: quad, center: [0, 2, 0], u: [1, 0, 0], v: [0, 0, 1], material: white }
  - { type: quad, center: [0, 1, -1], u: [1, 0, 0], v: [0, 1, 0], material: white }
  - { type: quad, center: [-1, 1, 0], u: [0, 1, 0], v: [0, 0, 1], material: red }
  - { type: quad, center: [1, 1, 0], u: [0, 0, 1], v: [0, 1, 0], material: green }
  - { type: quad, center: [0, 1.99, 0], u: [0.5, 0, 0], v: [0, 0, 0.5], material: white, emission: [3, 3, 3] }
  - { type: box, min: [-0.6, 0.1, -0.6], max: [0.6, 1.3, 0.6], interior: smoke }
"""
SAMPLERS = ["independent", "sobol"]
# The media candidates, each alone, as integrator parameters (murk plugins volpath_nee):
VARIANTS = {"before": ["--set", "integrator.light_sampling=area", "--set", "integrator.rr_threshold=1",
                       "--set", "media.{m}.stratify_flights=false"],
            "solid_angle": ["--set", "integrator.light_sampling=solid_angle", "--set", "integrator.rr_threshold=1"],
            "rr0.1": ["--set", "integrator.light_sampling=area", "--set", "integrator.rr_threshold=0.1"],
            # Russian roulette's threshold alone (murk's rule 1, Tungsten's 0.1, and between)
            "rr1": ["--set", "integrator.rr_threshold=1"],
            "rr0.3": ["--set", "integrator.rr_threshold=0.3"],
            "both": ["--set", "integrator.light_sampling=solid_angle", "--set", "integrator.rr_threshold=0.1"],
            "equiangular": ["--set", "integrator.equiangular=true"],
            "smis": ["--set", "media.{m}.type=spectral_mis"],
            "closed_form": ["--set", "media.{m}.type=spectral_mis", "--set", "media.{m}.closed_form=true"],
            "cf+eq": ["--set", "media.{m}.type=spectral_mis", "--set", "media.{m}.closed_form=true",
                      "--set", "integrator.equiangular=true"],
            "after": [],
            # stratified free flights (the medium key stratify_flights, default on) switched off alone
            "noflight": ["--set", "media.{m}.stratify_flights=false"]}
# {m}: the scene's medium. The cornell scene (`path`, no medium) drops the settings of a medium and of
# volpath_nee's own parameters: there those variants render as "after".
MEDIUM_NAME = {"fog": "fog"}  # else "smoke"


def variant_args(scene, v):
    args = [x.replace("{m}", MEDIUM_NAME.get(scene, "smoke")) for x in VARIANTS[v]]
    if scene != "cornell":
        return args
    pairs = [args[i:i + 2] for i in range(0, len(args), 2)]
    return [x for p in pairs if not (p[1].startswith("media.") or p[1].startswith("integrator.equiangular"))
            for x in p]


def run(args):
    """Runs murk, returns (stdout, CPU seconds of the child)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run([MURK] + args, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        sys.exit("murk %s failed:\n%s%s" % (" ".join(args), r.stdout, r.stderr))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return r.stdout + r.stderr, cpu


def render(scene, out, a, spp, seed, extra):
    path, sets = SCENES[scene]
    args = ["render", os.path.join(ROOT, "scenes", path), "-o", out, "--quiet", "--spp", str(spp),
            "--threads", str(a.threads), "--set", "render.resolution=[%d,%d]" % (a.res, a.res),
            "--set", "render.seed=%d" % seed] + sets + extra
    return run(args)[1]


def relmse(img, ref, crop=None):
    out, _ = run(["compare", img, ref] + (["--crop", crop] if crop else []))
    m = re.search(r"relMSE ([0-9.eE+-]+)", out)
    if not m:
        sys.exit("murk compare: no relMSE in:\n" + out)
    return float(m.group(1))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--res", type=int, default=64)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--ref-spp", type=int, default=2048)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--scenes", default="cornell,medium,cloud")
    p.add_argument("--variants", default="before,after")
    p.add_argument("--samplers", default=",".join(SAMPLERS))
    p.add_argument("--out", default=os.path.join(ROOT, "bench-out"))
    p.add_argument("--seed0", type=int, default=1, help="round r renders with seed SEED0 + r")
    p.add_argument("--crop", help="X,Y,W,H: the relMSE of that rectangle only (murk compare --crop)")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "lamp.yaml"), "w") as f:
        f.write(LAMP)
    SCENES["lamp"] = (os.path.join(a.out, "lamp.yaml"), [])
    scenes = a.scenes.split(",")
    variants = a.variants.split(",")
    samplers = a.samplers.split(",")
    configs = [(s, smp, v) for s in scenes for smp in samplers for v in variants]
    refs = {}
    for s in scenes:
        refs[s] = os.path.join(a.out, "ref_%s_%d_%d.exr" % (s, a.res, a.ref_spp))
        if not os.path.exists(refs[s]):
            print("reference %s: %d spp ..." % (s, a.ref_spp), flush=True)
            render(s, refs[s], a, a.ref_spp, 1000, [])
    rows = []
    for rnd in range(a.rounds):
        for (s, smp, v) in configs:
            img = os.path.join(a.out, "ee_%s_%s_%s.exr" % (s, smp, v))
            extra = variant_args(s, v)
            cpu = render(s, img, a, a.spp, a.seed0 + rnd, ["--set", "render.sampler=" + smp] + extra)
            e = relmse(img, refs[s], a.crop)
            rows.append({"round": rnd, "scene": s, "sampler": smp, "variant": v, "relmse": e, "cpu_s": cpu})
            print("round %d  %-8s %-12s %-11s relMSE %.4e  cpu %7.2f s" % (rnd, s, smp, v, e, cpu), flush=True)
    with open(os.path.join(a.out, "equal_error.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("\n%d x %d, %d spp, %d threads, %d rounds; reference %d spp (sobol); efficiency = 1/(relMSE x CPU s)"
          % (a.res, a.res, a.spp, a.threads, a.rounds, a.ref_spp))
    print("%-8s %-12s %-11s %11s %8s %22s %22s" % ("scene", "sampler", "variant", "relMSE", "CPU s",
                                                   "relMSE / base [spread]", "efficiency [spread]"))
    for s in scenes:
        base = [r for r in rows if r["scene"] == s and r["sampler"] == samplers[0] and r["variant"] == variants[0]]
        for smp in samplers:
            for v in variants:
                mine = [r for r in rows if r["scene"] == s and r["sampler"] == smp and r["variant"] == v]
                e = statistics.mean(r["relmse"] for r in mine)
                t = statistics.median(r["cpu_s"] for r in mine)
                er = [m["relmse"] / b["relmse"] for m, b in zip(mine, base)]
                ef = [(b["relmse"] * b["cpu_s"]) / (m["relmse"] * m["cpu_s"]) for m, b in zip(mine, base)]
                e0 = statistics.mean(r["relmse"] for r in base)
                t0 = statistics.median(r["cpu_s"] for r in base)
                print("%-8s %-12s %-11s %11.4e %8.2f %8.3f [%.2f..%.2f] %8.3f [%.2f..%.2f]"
                      % (s, smp, v, e, t, e / e0, min(er), max(er), (e0 * t0) / (e * t), min(ef), max(ef)))


if __name__ == "__main__":
    main()
