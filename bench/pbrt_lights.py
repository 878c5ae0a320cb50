#!/usr/bin/python3
"""pbrt_lights.py — murk's lights against pbrt-v4's, block-wise, on two grey scenes.

Usage: /usr/bin/python3 bench/pbrt_lights.py PBRT MURK OUTDIR [--res N] [--spp N] [--seeds K] [--scenes a,b]

PBRT is a pbrt-v4 binary, MURK murk's (build/core/murk). For each scene the script writes the murk YAML
and the pbrt-v4 file from one description, renders each K times with independent seeds (pbrt's
"independent" sampler), and compares the two means block by block (8 x 8 pixels): per block and channel
z = (mean_murk - mean_pbrt) / sqrt(se_murk^2 + se_pbrt^2) from the spread over the seeds. It prints the
mean ratio murk / pbrt, the largest |z|, the mean z over the blocks and the fraction of blocks beyond 3
sigma.

  envmap   a grey diffuse sphere (albedo 0.5) on a grey floor (0.3), seen from above, under a grey
           environment that is a closed form of the direction (a sky gradient over a darker ground,
           continuous, and one soft bright lobe): murk
           reads it as a 256 x 128 lat-long EXR, pbrt-v4 as a 256 x 256 equal-area square (its
           ImageInfiniteLight's only mapping, Clarberg's octahedral map), both tabulated at their texel
           centres; path tracing, 5 bounces.
  sunmedium  a box of homogeneous grey medium (sigma_a 0.1, sigma_s 1.9, g 0.3) on a grey floor under a
           delta sun of irradiance 3 (pbrt's "distant" light, "L" = irradiance); volpath_nee against
           pbrt's volpath, 16 bounces.

pbrt-v4 is spectral: grey RGB reflectances and radiances become flat spectra (reflectances) and the
colour space's illuminant (lights), which the film maps back to the same grey, so grey scenes compare
without a spectral tolerance. The two tabulations of the environment differ by their texels' footprints
(a second-order difference for this smooth map). Conventions: pbrt's camera space is left-handed (Scale
-1 1 1 before LookAt) and its fov is that of the shorter image axis.
"""
import argparse
import math
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
import exrio  # noqa: E402

SUN = np.array([0.5, 1.0, 0.35]) / np.linalg.norm([0.5, 1.0, 0.35])
LOBE = np.array([-0.6, 0.45, -0.3]) / np.linalg.norm([-0.6, 0.45, -0.3])


def env_radiance(d):
    """The grey environment's radiance arriving from unit directions d (..., 3), y up."""
    y = d[..., 1]
    base = np.where(y > 0, 0.3 + 0.6 * y, 0.3 + 0.1 * y)  # a sky over a darker ground, continuous
    lobe = 25.0 * np.exp(20.0 * (d @ LOBE - 1.0))  # a soft bright spot of about 13 degrees
    return base + lobe


def latlong(w, h):
    """murk's mapping (core/render/envmap.h): theta from +y, phi = atan2(x, -z), u = 1/2 + phi / 2 pi."""
    v = (np.arange(h) + 0.5) / h
    u = (np.arange(w) + 0.5) / w
    th, ph = np.meshgrid(math.pi * v, 2 * math.pi * (u - 0.5), indexing="ij")
    d = np.stack([np.sin(th) * np.sin(ph), np.cos(th), -np.sin(th) * np.cos(ph)], axis=-1)
    L = env_radiance(d)
    return np.repeat(L[..., None], 3, axis=2)


def equal_area(n):
    """pbrt-v4's EqualAreaSquareToSphere at the texel centres of an n x n square (light space = world)."""
    p = (np.arange(n) + 0.5) / n
    py, px = np.meshgrid(p, p, indexing="ij")  # row j is uv.y
    u, v = 2 * px - 1, 2 * py - 1
    up, vp = abs(u), abs(v)
    sd = 1 - (up + vp)
    r = 1 - abs(sd)
    phi = np.where(r == 0, 1.0, (vp - up) / np.where(r == 0, 1, r) + 1) * math.pi / 4
    z = np.copysign(1 - r * r, sd)
    cphi, sphi = np.copysign(np.cos(phi), u), np.copysign(np.sin(phi), v)
    s = r * np.sqrt(np.clip(2 - r * r, 0, None))
    d = np.stack([cphi * s, sphi * s, z], axis=-1)
    L = env_radiance(d)
    return np.repeat(L[..., None], 3, axis=2)


def fmt(v):
    return " ".join("%.9g" % x for x in v)


def quad_mesh(c, u, v):
    c, u, v = map(np.asarray, (c, u, v))
    p = [c - u - v, c + u - v, c + u + v, c - u + v]
    return ('Shape "trianglemesh" "integer indices" [ 0 1 2 0 2 3 ] "point3 P" [ %s ]'
            % " ".join(fmt(x) for x in p))


def box_mesh(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    c, h = (lo + hi) / 2, (hi - lo) / 2
    X, Y, Z = np.array([h[0], 0, 0]), np.array([0, h[1], 0]), np.array([0, 0, h[2]])
    faces = [(c + X, Y, Z), (c - X, Z, Y), (c + Y, Z, X), (c - Y, X, Z), (c + Z, X, Y), (c - Z, Y, X)]
    pts, idx = [], []
    for k, (fc, fu, fv) in enumerate(faces):
        pts += [fc - fu - fv, fc + fu - fv, fc + fu + fv, fc - fu + fv]
        idx += [4 * k, 4 * k + 1, 4 * k + 2, 4 * k, 4 * k + 2, 4 * k + 3]
    return ('Shape "trianglemesh" "integer indices" [ %s ] "point3 P" [ %s ]'
            % (" ".join(map(str, idx)), " ".join(fmt(x) for x in pts)))


CAM = dict(origin=(0, 1.0, 4.0), at=(0, 0.6, 0), up=(0, 1, 0), fov=35.0)
# The envmap scene is seen from above, floor and sphere filling the image: pixels that see the map
# directly would compare the two tabulations themselves (nearly noise-free, so any texel difference is
# many sigma), where lit surfaces compare the lights.
CAM_ENV = dict(origin=(0, 3.2, 2.4), at=(0, 0.4, 0), up=(0, 1, 0), fov=35.0)


def write_envmap(out, res, spp):
    exrio.write(os.path.join(out, "env_latlong.exr"), latlong(256, 128), half=False, zip=True)
    exrio.write(os.path.join(out, "env_equalarea.exr"), equal_area(256), half=False, zip=True)
    murk = f"""murk: 1
render: {{ resolution: [{res}, {res}], spp: {spp}, sampler: independent }}
camera: {{ from: [{fmt(CAM_ENV['origin']).replace(' ', ', ')}], at: [{fmt(CAM_ENV['at']).replace(' ', ', ')}], up: [0, 1, 0], fov: {CAM_ENV['fov']} }}
integrator: {{ type: path, max_depth: 5 }}
materials:
  grey: {{ type: diffuse, albedo: 0.5 }}
  floor: {{ type: diffuse, albedo: 0.3 }}
lights:
  - {{ type: envmap, file: env_latlong.exr }}
shapes:
  - {{ type: sphere, center: [0, 0.6, 0], radius: 0.6, material: grey }}
  - {{ type: quad, center: [0, 0, 0], u: [6, 0, 0], v: [0, 0, -6], material: floor }}
"""
    pbrt = f"""Scale -1 1 1
LookAt {fmt(CAM_ENV['origin'])}  {fmt(CAM_ENV['at'])}  {fmt(CAM_ENV['up'])}
Camera "perspective" "float fov" [ {CAM_ENV['fov']} ]
Sampler "independent" "integer pixelsamples" [ {spp} ] "integer seed" [ SEED ]
Integrator "path" "integer maxdepth" [ 5 ] "bool regularize" false
PixelFilter "box" "float xradius" [ 0.5 ] "float yradius" [ 0.5 ]
Film "rgb" "string filename" [ "OUTFILE" ] "integer xresolution" [ {res} ] "integer yresolution" [ {res} ]
WorldBegin
AttributeBegin
  LightSource "infinite" "string filename" [ "env_equalarea.exr" ]
AttributeEnd
AttributeBegin
  Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
  Translate 0 0.6 0
  Shape "sphere" "float radius" [ 0.6 ]
AttributeEnd
AttributeBegin
  Material "diffuse" "rgb reflectance" [ 0.3 0.3 0.3 ]
  {quad_mesh((0, 0, 0), (6, 0, 0), (0, 0, -6))}
AttributeEnd
"""
    return murk, pbrt


def write_sunmedium(out, res, spp):
    murk = f"""murk: 1
render: {{ resolution: [{res}, {res}], spp: {spp}, sampler: independent }}
camera: {{ from: [{fmt(CAM['origin']).replace(' ', ', ')}], at: [{fmt(CAM['at']).replace(' ', ', ')}], up: [0, 1, 0], fov: {CAM['fov']} }}
integrator: {{ type: volpath_nee, max_depth: 16 }}
materials:
  floor: {{ type: diffuse, albedo: 0.5 }}
media:
  fog: {{ type: delta, density: {{ constant: 1 }}, sigma_a: 0.1, sigma_s: 1.9, g: 0.3 }}
lights:
  - {{ type: distant, direction: [{fmt(SUN).replace(' ', ', ')}], irradiance: 3 }}
shapes:
  - {{ type: quad, center: [0, 0, 0], u: [3, 0, 0], v: [0, 0, -3], material: floor }}
  - {{ type: box, min: [-0.6, 0.05, -0.6], max: [0.6, 1.25, 0.6], interior: fog }}
"""
    pbrt = f"""Scale -1 1 1
LookAt {fmt(CAM['origin'])}  {fmt(CAM['at'])}  {fmt(CAM['up'])}
Camera "perspective" "float fov" [ {CAM['fov']} ]
Sampler "independent" "integer pixelsamples" [ {spp} ] "integer seed" [ SEED ]
Integrator "volpath" "integer maxdepth" [ 16 ] "bool regularize" false
PixelFilter "box" "float xradius" [ 0.5 ] "float yradius" [ 0.5 ]
Film "rgb" "string filename" [ "OUTFILE" ] "integer xresolution" [ {res} ] "integer yresolution" [ {res} ]
WorldBegin
LightSource "distant" "point3 from" [ {fmt(SUN)} ] "point3 to" [ 0 0 0 ] "rgb L" [ 3 3 3 ]
MakeNamedMedium "fog" "string type" "homogeneous" "rgb sigma_a" [ 0.1 0.1 0.1 ] "rgb sigma_s" [ 1.9 1.9 1.9 ] "float scale" [ 1 ] "float g" [ 0.3 ]
AttributeBegin
  Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
  {quad_mesh((0, 0, 0), (3, 0, 0), (0, 0, -3))}
AttributeEnd
AttributeBegin
  Material "interface"
  MediumInterface "fog" ""
  {box_mesh((-0.6, 0.05, -0.6), (0.6, 1.25, 0.6))}
AttributeEnd
"""
    return murk, pbrt


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    img = data.reshape(h, w, 3 if kind == b"PF" else 1)
    return np.flipud(img).astype(np.float64)  # PFM rows run bottom to top


def render_all(a, name, murk_text, pbrt_text):
    out = a.outdir
    yaml = os.path.join(out, name + ".yaml")
    open(yaml, "w").write(murk_text)
    imgs = {"murk": [], "pbrt": []}
    for k in range(a.seeds):
        exr = os.path.join(out, "%s_murk_%d.exr" % (name, k))
        subprocess.run([a.murk, "render", yaml, "-o", exr, "--quiet", "--threads", "2", "--set",
                        "render.seed=%d" % (1000 + k)], check=True)
        imgs["murk"].append(exrio.read(exr).astype(np.float64))
        pf = "%s_pbrt_%d.pfm" % (name, k)
        scene = os.path.join(out, "%s_%d.pbrt" % (name, k))
        open(scene, "w").write(pbrt_text.replace("SEED", str(2000 + k)).replace("OUTFILE", pf))
        subprocess.run([a.pbrt, "--quiet", "--nthreads", "2", os.path.basename(scene)], cwd=out, check=True)
        imgs["pbrt"].append(read_pfm(os.path.join(out, pf)))
    return imgs


def blocks(stack, b):
    """Per block and channel: the mean over seeds of the block mean, and its standard error."""
    s = np.asarray(stack)  # K, h, w, 3
    K, h, w, _ = s.shape
    bm = s[:, :h - h % b, :w - w % b].reshape(K, h // b, b, w // b, b, 3).mean(axis=(2, 4))
    return bm.mean(axis=0), bm.std(axis=0, ddof=1) / math.sqrt(K)


def compare(name, imgs, b=8):
    mm, sm = blocks(imgs["murk"], b)
    mp, sp = blocks(imgs["pbrt"], b)
    se = np.sqrt(sm ** 2 + sp ** 2)
    ok = se > 0
    z = np.where(ok, (mm - mp) / np.where(ok, se, 1), 0)
    ratio = np.mean(imgs["murk"]) / np.mean(imgs["pbrt"])
    rel_se = math.sqrt(np.sum(sm ** 2) + np.sum(sp ** 2)) / np.sum(mp)
    print("%-10s murk/pbrt mean %.4f (+- %.4f); blocks %dx%d: max |z| %.2f, mean z %+.3f over %d, beyond 3 sigma %.1f%%"
          % (name, ratio, rel_se * ratio, b, b, np.max(abs(z)), np.mean(z), z.size, 100.0 * np.mean(abs(z) > 3)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("pbrt")
    ap.add_argument("murk")
    ap.add_argument("outdir")
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--scenes", default="envmap,sunmedium")
    a = ap.parse_args()
    a.pbrt, a.murk = os.path.abspath(a.pbrt), os.path.abspath(a.murk)
    os.makedirs(a.outdir, exist_ok=True)
    writers = {"envmap": write_envmap, "sunmedium": write_sunmedium}
    for name in a.scenes.split(","):
        murk_text, pbrt_text = writers[name](a.outdir, a.res, a.spp)
        compare(name, render_all(a, name, murk_text, pbrt_text))


if __name__ == "__main__":
    main()
