#!/usr/bin/python3
"""Speed against accuracy for every tracker: render each scene with each tracker for a set of time
budgets (murk render --time), measure relMSE against a high-spp reference (murk compare), and write
bench-out/trackers.csv and one error-vs-time chart per scene (bench-out/trackers_SCENE.png).

    /usr/bin/python3 bench/trackers.py [--times 2,4,8] [--res 128] [--ref-spp 2048] [--scenes a,b]

Run it on an otherwise idle machine: all renders of one invocation share it, so the ratios between
trackers are what to quote. Needs Debian's python3-matplotlib (tools/build.sh does not install it:
apt-get install python3-matplotlib)."""
import argparse, csv, os, re, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MURK = os.path.join(ROOT, "build", "core", "murk")
TRACKERS = ["delta", "decomposition", "spectral", "spectral_mis", "naive_spectral"]
SCENES = {"cornell_smoke": "smoke", "spectral_extinction": "medium"}


def run(args):
    r = subprocess.run([MURK] + args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("murk %s failed:\n%s%s" % (" ".join(args), r.stdout, r.stderr))
    return r.stdout


def render(scene, out, res, extra):
    s = run(["render", os.path.join(ROOT, "scenes", scene + ".yaml"), "-o", out,
             "--set", "render.resolution=[%d,%d]" % (res, res)] + extra)
    return s


def relmse(test, ref):
    m = re.search(r"relMSE ([0-9.e+-]+)", run(["compare", test, ref]))
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--times", default="2,4,8")
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--scenes", default=",".join(SCENES))
    a = ap.parse_args()
    out = os.path.join(ROOT, "bench-out")
    os.makedirs(out, exist_ok=True)
    rows = []
    for scene in a.scenes.split(","):
        medium = SCENES[scene]
        ref = os.path.join(out, scene + "_ref.exr")
        print("reference %s: %d spp (spectral_mis)" % (scene, a.ref_spp), flush=True)
        render(scene, ref, a.res, ["--spp", str(a.ref_spp), "--set", "media.%s.type=spectral_mis" % medium,
                                   "--set", "render.seed=12345"])
        for t in [float(x) for x in a.times.split(",")]:
            for tr in TRACKERS:
                img = os.path.join(out, "%s_%s_%g.exr" % (scene, tr, t))
                log = render(scene, img, a.res, ["--time", str(t), "--spp", "1000000",
                                                 "--set", "media.%s.type=%s" % (medium, tr)])
                m = re.search(r"(\d+) spp, ([0-9.]+) s", log)
                spp, secs = int(m.group(1)), float(m.group(2))
                e = relmse(img, ref)
                rows.append(dict(scene=scene, tracker=tr, budget=t, spp=spp, seconds=secs, relmse=e,
                                 relmse_x_time=e * secs))
                print("%-20s %-15s %5.1fs budget: %5d spp in %6.2f s  relMSE %.4e  relMSE*time %.4e"
                      % (scene, tr, t, spp, secs, e, e * secs), flush=True)
    with open(os.path.join(out, "trackers.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("python3-matplotlib missing: no charts (the CSV is written)")
        return
    for scene in a.scenes.split(","):
        plt.figure(figsize=(6, 4.5))
        for tr in TRACKERS:
            pts = sorted((r["seconds"], r["relmse"]) for r in rows if r["scene"] == scene and r["tracker"] == tr)
            plt.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=tr)
        plt.xlabel("render time [s]")
        plt.ylabel("relMSE against reference")
        plt.title("%s: error against time (lower-left is better)" % scene)
        plt.grid(True, which="both", alpha=0.3)
        plt.legend()
        plt.tight_layout()
        plt.savefig(os.path.join(out, "trackers_%s.png" % scene), dpi=100)
    print("wrote", os.path.join(out, "trackers.csv"))


if __name__ == "__main__":
    main()
