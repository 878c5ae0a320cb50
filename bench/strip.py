#!/usr/bin/python3
"""Puts PNG renders side by side, each shown pixel for pixel with its caption under it:

    bench/strip.py [--title TEXT] OUT.png A.png:caption B.png:caption ...

A caption may hold several lines separated by a literal "\\n" (e.g. 'delta\\n64 spp, 10.1 s\\nrelMSE 0.012').
Images of different sizes are centred in equal-width panels. Needs Debian's python3-matplotlib."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools"))
import pngmeta  # noqa: E402 (tools/pngmeta.py: the murk:commit text key)
import matplotlib
matplotlib.use("Agg")
import matplotlib.image as mpimg
import matplotlib.pyplot as plt

DPI = 100
LINE = 0.17      # inches per caption line
PAD = 0.08       # inches between panels and around the figure

args = sys.argv[1:]
title = None
if len(args) >= 2 and args[0] == "--title":
    title, args = args[1], args[2:]
if len(args) < 2:
    sys.exit(__doc__)
out = args[0]
items = []
for a in args[1:]:
    path, _, caption = a.partition(":")
    items.append((mpimg.imread(path), caption.replace("\\n", "\n")))

pw = max(img.shape[1] for img, _ in items) / DPI
ph = max(img.shape[0] for img, _ in items) / DPI
lines = max(c.count("\n") + 1 for _, c in items)
cap_h = lines * LINE + PAD
title_h = 2 * LINE if title else 0.0
W = len(items) * (pw + PAD) + PAD
H = PAD + title_h + ph + cap_h
fig = plt.figure(figsize=(W, H), dpi=DPI)
if title:
    fig.text(0.5, 1 - (PAD + LINE) / H, title, ha="center", va="center", fontsize=11)
for k, (img, caption) in enumerate(items):
    w, h = img.shape[1] / DPI, img.shape[0] / DPI
    x0 = PAD + k * (pw + PAD) + (pw - w) / 2
    y0 = cap_h + (ph - h)            # top-aligned panels, captions in a row under them
    ax = fig.add_axes([x0 / W, y0 / H, w / W, h / H])
    ax.imshow(img, interpolation="nearest")
    ax.axis("off")
    fig.text((PAD + k * (pw + PAD) + pw / 2) / W, (cap_h - PAD / 2) / H, caption, ha="center", va="top",
             fontsize=9, linespacing=1.25)
fig.savefig(out, dpi=DPI, facecolor="white", metadata=pngmeta.metadata())
