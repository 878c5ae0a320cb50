#!/usr/bin/python3
"""three_pass.py — the reference report's naive baseline as it set it: three renders, one per channel,
put together. Pass c is a render with the medium's tracker `naive_spectral` and `channel: red|green|blue`
(every path tracks channel c and credits it 1x; its other channels are not estimated, and are wrong
wherever a path met the medium), so the image takes channel c from pass c:

    murk render S.yaml -o red.exr   --set media.M.type=naive_spectral --set media.M.channel=red    (green, blue)
    bench/three_pass.py OUT.exr red.exr green.exr blue.exr [--exposure E]

writes OUT.exr (float) and OUT.png (sRGB preview, 2^E exposure, with the PNG text keys murk:commit and
murk:version, tools/pngmeta.py). The passes' render times add up: the baseline's time is their sum.
Needs Debian's python3-numpy and python3-matplotlib."""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools"))
import exrio  # noqa: E402
import pngmeta  # noqa: E402


def srgb8(x):
    x = np.clip(np.nan_to_num(x, nan=0.0), 0.0, 1.0)
    y = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return (y * 255.0 + 0.5).astype(np.uint8)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("passes", nargs=3, metavar="PASS.exr", help="the red, green and blue passes, in this order")
    ap.add_argument("--exposure", type=float, default=0.0)
    a = ap.parse_args()
    imgs = [exrio.read(p) for p in a.passes]
    if any(i.shape != imgs[0].shape for i in imgs):
        sys.exit("three_pass.py: the passes differ in size")
    out = np.stack([imgs[c][:, :, c] for c in range(3)], axis=-1)
    exrio.write(a.out, out, half=False)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    png = os.path.splitext(a.out)[0] + ".png"
    plt.imsave(png, srgb8(out * 2.0 ** a.exposure), metadata=pngmeta.metadata())


if __name__ == "__main__":
    main()
