#!/usr/bin/python3
"""pbrt_cloud.py — scenes/cornell_smoke.yaml's heterogeneous cloud, written for murk and for pbrt-v4 from one
description, so the two can be compared side by side (bench/side_by_side.py --cloud renders and times them).

Usage: /usr/bin/python3 bench/pbrt_cloud.py MURK OUTDIR [--res N] [--spp N]

MURK is murk's binary (build/core/murk): `murk grid` bakes the cloud (cornell_smoke.yaml's parameters:
seed 7, frequency 2.5, octaves 5, coverage 0.7, 64^3 voxels over the medium's box) into OUTDIR/cloud.vol,
and the script writes
  OUTDIR/cloud.yaml   murk: the scene, its medium's density read from cloud.vol;
  OUTDIR/cloud.pbrt   pbrt-v4: the same scene, the medium a `uniformgrid` whose density values are the
                      .vol's, inline ("float density", x fastest, then y, then z: the .vol's order).
Both grids put their values at cell centres and interpolate trilinearly; they differ only in the border
half-cells (murk clamps to the last centre, pbrt-v4 blends towards 0 outside), and the baked cloud is 0
there (the script checks it), so the two media are the same function.

The scene is cornell_smoke.yaml made grey — walls 0.73 / 0.5 / 0.3, a lamp of radiance 12 — because
pbrt-v4 renders spectrally: grey reflectances and lights map to flat spectra and back to the same grey,
where coloured ones would differ by the RGB-to-spectrum round trip, not by the renderers. The medium is
the original (sigma_a 0.5, sigma_s 18, g 0.2: optical depth up to about 20 through the cloud), the box
an index-matched boundary (pbrt-v4's "interface" material), 64 scattering events at most in both.
Conventions as in bench/pbrt_lights.py (pbrt's camera space is left-handed: Scale -1 1 1 before
LookAt; its fov is the shorter image axis's, here square). murk's default sampler and tracker (sobol,
`delta` with residual ratio tracking for shadow rays) against pbrt-v4's defaults (zsobol, volpath:
delta tracking over its majorant grid, ratio tracking for shadow rays).
"""
import argparse
import os
import struct
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pbrt_lights import box_mesh, fmt, quad_mesh  # noqa: E402

BOX = ((-0.6, 0.05, -0.6), (0.6, 1.45, 0.6))
CLOUD = ["--seed", "7", "--frequency", "2.5", "--octaves", "5", "--coverage", "0.7", "--res", "64"]
# (centre, u, v, grey albedo, emission) — cornell_smoke.yaml's shapes
QUADS = [((0, 0, 0), (0, 0, 1), (1, 0, 0), 0.73, 0), ((0, 2, 0), (1, 0, 0), (0, 0, 1), 0.73, 0),
         ((0, 1, -1), (1, 0, 0), (0, 1, 0), 0.73, 0), ((-1, 1, 0), (0, 0, 1), (0, 1, 0), 0.5, 0),
         ((1, 1, 0), (0, 1, 0), (0, 0, 1), 0.3, 0), ((0, 1.998, 0), (0.235, 0, 0), (0, 0, 0.19), 0.78, 12)]
MEDIUM = dict(sigma_a=0.5, sigma_s=18.0, g=0.2)
MAX_DEPTH = 64


def bake(murk, out):
    vol = os.path.join(out, "cloud.vol")
    lo, hi = BOX
    subprocess.run([murk, "grid", vol, "--min", ",".join(map(str, lo)), "--max", ",".join(map(str, hi))] + CLOUD,
                   check=True, stdout=subprocess.DEVNULL)
    b = open(vol, "rb").read()
    enc, nx, ny, nz, ch = struct.unpack("<5i", b[4:24])
    d = np.frombuffer(b[48:], "<f4").reshape(nz, ny, nx)
    border = max(abs(d[[0, -1]]).max(), abs(d[:, [0, -1]]).max(), abs(d[:, :, [0, -1]]).max())
    if enc != 1 or ch != 1 or border != 0:
        sys.exit("pbrt_cloud: the baked grid is not a one-channel float grid that is 0 on its border")
    return vol, (nx, ny, nz), d


def murk_scene(vol, res, spp):
    shapes = "".join("  - { type: quad, center: [%s], u: [%s], v: [%s], material: m%d%s }\n"
                     % (fmt(c).replace(" ", ", "), fmt(u).replace(" ", ", "), fmt(v).replace(" ", ", "), i,
                        ", emission: [%g, %g, %g]" % (e, e, e) if e else "")
                     for i, (c, u, v, a, e) in enumerate(QUADS))
    mats = "".join("  m%d: { type: diffuse, albedo: %g }\n" % (i, q[3]) for i, q in enumerate(QUADS))
    return f"""murk: 1
# bench/pbrt_cloud.py: scenes/cornell_smoke.yaml made grey, its cloud baked to cloud.vol (also in cloud.pbrt)
render: {{ resolution: [{res}, {res}], spp: {spp}, seed: 0 }}
camera: {{ from: [0, 1, 3.4], at: [0, 1, 0], up: [0, 1, 0], fov: 40 }}
integrator: {{ type: volpath_nee, max_depth: {MAX_DEPTH} }}
background: [0, 0, 0]
materials:
{mats}media:
  smoke: {{ type: delta, density: {{ grid: {os.path.basename(vol)} }}, sigma_a: {MEDIUM['sigma_a']}, sigma_s: {MEDIUM['sigma_s']}, g: {MEDIUM['g']} }}
shapes:
{shapes}  - {{ type: box, min: [{fmt(BOX[0]).replace(' ', ', ')}], max: [{fmt(BOX[1]).replace(' ', ', ')}], interior: smoke }}
"""


def pbrt_scene(n, d, res, spp):
    sa, ss = MEDIUM["sigma_a"], MEDIUM["sigma_s"]
    dens = " ".join("%.9g" % x for x in d.ravel())
    body = []
    for c, u, v, a, e in QUADS:
        light = '  AreaLightSource "diffuse" "rgb L" [ %g %g %g ]\n' % (e, e, e) if e else ""
        body.append('AttributeBegin\n%s  Material "diffuse" "rgb reflectance" [ %g %g %g ]\n  %s\nAttributeEnd\n'
                    % (light, a, a, a, quad_mesh(c, u, v)))
    return f"""# bench/pbrt_cloud.py: scenes/cornell_smoke.yaml made grey, for pbrt-v4
Scale -1 1 1
LookAt 0 1 3.4  0 1 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Sampler "zsobol" "integer pixelsamples" [ {spp} ] "integer seed" [ 0 ]
Integrator "volpath" "integer maxdepth" [ {MAX_DEPTH} ] "bool regularize" false
PixelFilter "box" "float xradius" [ 0.5 ] "float yradius" [ 0.5 ]
Film "rgb" "string filename" [ "cloud.exr" ] "integer xresolution" [ {res} ] "integer yresolution" [ {res} ] "bool savefp16" false
WorldBegin
MakeNamedMedium "smoke" "string type" "uniformgrid" "rgb sigma_a" [ {sa} {sa} {sa} ] "rgb sigma_s" [ {ss} {ss} {ss} ]
  "float scale" [ 1 ] "float g" [ {MEDIUM['g']} ] "point3 p0" [ {fmt(BOX[0])} ] "point3 p1" [ {fmt(BOX[1])} ]
  "integer nx" [ {n[0]} ] "integer ny" [ {n[1]} ] "integer nz" [ {n[2]} ]
  "float density" [ {dens} ]
{"".join(body)}AttributeBegin
  Material "interface"
  MediumInterface "smoke" ""
  {box_mesh(*BOX)}
AttributeEnd
"""


def write(murk, out, res, spp):
    """Bakes the grid and writes OUTDIR/cloud.yaml and OUTDIR/cloud.pbrt; returns their paths."""
    os.makedirs(out, exist_ok=True)
    vol, n, d = bake(murk, out)
    paths = os.path.join(out, "cloud.yaml"), os.path.join(out, "cloud.pbrt")
    open(paths[0], "w").write(murk_scene(vol, res, spp))
    open(paths[1], "w").write(pbrt_scene(n, d, res, spp))
    return paths


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("murk")
    ap.add_argument("outdir")
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--spp", type=int, default=16)
    a = ap.parse_args()
    for p in write(os.path.abspath(a.murk), a.outdir, a.res, a.spp):
        print(p)


if __name__ == "__main__":
    main()
