#!/usr/bin/python3
"""A notebook-style sweep with the Python module: decomposition tracking's `control` (the share of the
density's minimum taken as the homogeneous control medium) on the cloud of cornell_smoke, each value
rendered at a few spp budgets, its relMSE against one reference plotted against render time and, beside
it, against density lookups (the machine-independent cost). The curve lowest and leftmost wins. Run from the build tree:

    meson devenv -C build -w . /usr/bin/python3 docs/python_sweep.py [--quick] [OUT.png]

(--quick: a 32x32 image and small budgets, a check that it runs. Ctrl-C stops the render in progress and
ends the sweep.) Needs python3-matplotlib."""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import murk  # noqa: E402

QUICK = "--quick" in sys.argv[1:]
ARGS = [a for a in sys.argv[1:] if a != "--quick"]
SCENE = "scenes/cornell_smoke.yaml"
SMALL = {"render.resolution": [32, 32] if QUICK else [64, 64], "media.smoke.type": "decomposition"}
CONTROLS = [0.0, 0.25, 0.5, 1.0]
BUDGETS = [1, 4] if QUICK else [4, 16, 64]
REF_SPP = 64 if QUICK else 1024

# The reference: many samples, another seed than the renders compared with it.
reference = murk.render(SCENE, spp=REF_SPP, seed=99, set=dict(SMALL, **{"media.smoke.type": "delta"}), quiet=True)
print("reference: %s" % reference, flush=True)

fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
for control in CONTROLS:
    times, lookups, errors = [], [], []
    for spp in BUDGETS:
        r = murk.render(SCENE, spp=spp, seed=1, set=dict(SMALL, **{"media.smoke.control": control}), quiet=True)
        f = murk.compare(r, reference)
        times.append(r.seconds)
        lookups.append(r.counters["total"]["lookups"])
        errors.append(f["relmse"])
        print("control %-4g %4d spp: %.3f s, relMSE %.3e (z %.1f), %d density lookups"
              % (control, spp, r.seconds, f["relmse"], f["z"], r.counters["total"]["lookups"]), flush=True)
    ax.loglog(times, errors, "o-", label="control %g" % control)
    bx.loglog(lookups, errors, "o-", label="control %g" % control)
ax.set_xlabel("render time (s)")
bx.set_xlabel("density lookups")
ax.set_ylabel("relMSE against the reference")
fig.suptitle("decomposition tracking's control on cornell_smoke")
bx.legend()
fig.tight_layout()
out = ARGS[0] if ARGS else "python_sweep.png"
fig.savefig(out, dpi=100)
print("wrote %s" % out)
