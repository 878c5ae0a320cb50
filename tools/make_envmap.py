#!/usr/bin/python3
"""make_envmap.py — writes scenes/env/studio.exr, the lat-long environment of scenes/envmap_spheres.yaml.

Usage: /usr/bin/python3 tools/make_envmap.py [OUT.exr]      (default: scenes/env/studio.exr)

A 256 x 128 RGB half-float EXR (ZIP; tools/exrio.py writes it), radiances in murk's linear RGB, in murk's
lat-long mapping (core/render/envmap.h: row 0 is +y, the centre column looks along -z, u grows towards
+x). Made from closed forms only, so every run writes the same bytes:
  sky      above the horizon: a warm horizon (1.1, 1.0, 0.85) blending into a blue zenith (0.25, 0.45,
           0.95) by cos(theta)^0.6
  ground   below it: a dark earth (0.22, 0.19, 0.15), darker towards the nadir
  lamps    two soft boxes, a warm one (radiance 12, 10, 8) left of centre and high, a cool one
           (5, 7, 10) to the right and lower: small, bright texels that importance sampling must find
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import exrio  # noqa: E402

W, H = 256, 128


def studio():
    v = (np.arange(H) + 0.5) / H
    u = (np.arange(W) + 0.5) / W
    theta = math.pi * v[:, None] * np.ones((1, W))
    img = np.zeros((H, W, 3), np.float32)
    ct = np.cos(theta)
    t = np.clip(ct, 0.0, 1.0) ** 0.6
    horizon, zenith = np.array([1.1, 1.0, 0.85]), np.array([0.25, 0.45, 0.95])
    sky = horizon[None, None, :] * (1 - t[..., None]) + zenith[None, None, :] * t[..., None]
    ground = np.array([0.22, 0.19, 0.15])[None, None, :] * (0.5 + 0.5 * (1 + ct[..., None]))
    img[:] = np.where((ct > 0)[..., None], sky, ground)
    uu = u[None, :] * np.ones((H, 1))
    vv = v[:, None] * np.ones((1, W))
    warm = (abs(uu - 0.40) < 0.06) & (abs(vv - 0.22) < 0.06)
    cool = (abs(uu - 0.68) < 0.04) & (abs(vv - 0.36) < 0.04)
    img[warm] = [12.0, 10.0, 8.0]
    img[cool] = [5.0, 7.0, 10.0]
    return img


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "scenes", "env", "studio.exr")
    exrio.write(out, studio(), half=True, zip=True)
    print("%s: %d x %d, %d bytes" % (out, W, H, os.path.getsize(out)))


if __name__ == "__main__":
    main()
