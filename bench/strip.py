#!/usr/bin/python3
"""Puts PNG renders side by side with a caption under each: bench/strip.py OUT.png A.png:caption B.png:caption ...
Needs Debian's python3-matplotlib."""
import sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.image as mpimg
import matplotlib.pyplot as plt

items = [a.split(":", 1) for a in sys.argv[2:]]
fig, axes = plt.subplots(1, len(items), figsize=(3.2 * len(items), 3.5))
for ax, (path, caption) in zip(axes if len(items) > 1 else [axes], items):
    ax.imshow(mpimg.imread(path))
    ax.set_title(caption, fontsize=10)
    ax.axis("off")
plt.tight_layout()
plt.savefig(sys.argv[1], dpi=100)
