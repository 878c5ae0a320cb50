#!/usr/bin/python3
"""A notebook-style sweep with the Python module: decomposition tracking's `control` (the share of the
density's minimum taken as the homogeneous control medium) on the cloud of cornell_smoke, each value
rendered at a few spp budgets, its relMSE against one reference plotted against render time. The curve
lowest and leftmost wins. Run from the build tree:

    meson devenv -C build -w . /usr/bin/python3 docs/python_sweep.py [OUT.png]

(Ctrl-C stops the render in progress and ends the sweep.) Needs python3-matplotlib."""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import murk  # noqa: E402

SCENE = "scenes/cornell_smoke.yaml"
SMALL = {"render.resolution": [96, 96], "media.smoke.type": "decomposition"}
CONTROLS = [0.0, 0.5, 1.0, 2.0]
BUDGETS = [4, 16, 64]

# The reference: many samples, another seed than the renders compared with it.
reference = murk.render(SCENE, spp=1024, seed=99, set=dict(SMALL, **{"media.smoke.type": "delta"}), quiet=True)
print("reference: %s" % reference)

fig, ax = plt.subplots(figsize=(6, 4))
for control in CONTROLS:
    times, errors = [], []
    for spp in BUDGETS:
        r = murk.render(SCENE, spp=spp, seed=1, set=dict(SMALL, **{"media.smoke.control": control}), quiet=True)
        f = murk.compare(r, reference)
        times.append(r.seconds)
        errors.append(f["relmse"])
        print("control %-4g %4d spp: %.3f s, relMSE %.3e (z %.1f), %d density lookups"
              % (control, spp, r.seconds, f["relmse"], f["z"], r.counters["total"]["lookups"]))
    ax.loglog(times, errors, "o-", label="control %g" % control)
ax.set_xlabel("render time (s)")
ax.set_ylabel("relMSE against the reference")
ax.set_title("decomposition tracking's control on cornell_smoke")
ax.legend()
fig.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "python_sweep.png"
fig.savefig(out, dpi=100)
print("wrote %s" % out)
