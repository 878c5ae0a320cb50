#!/usr/bin/python3
"""make_textures.py — writes the image textures of scenes/axe_room.yaml from procedural patterns.

Usage: /usr/bin/python3 tools/make_textures.py [OUTDIR]      (default: scenes/axe next to this tool)

Writes four 8-bit sRGB PNGs (colours are authored in sRGB; the scene reads them with srgb: true):
  bricks.png   256x256  running-bond brick wall, 4 courses x 2 bricks per tile, grey mortar
  planks.png   256x256  floor boards: 4 planks across, staggered butt joints, wood grain
  plaster.png  128x128  off-white plaster with low-frequency blotches and fine grain
  wood.png      64x256  handle wood: grain running along v (the handle's length), u around it
Every texture tiles seamlessly (the noise lattice wraps at the tile size). Only the standard library
is used (zlib + struct write the PNG) and all randomness is an integer hash of lattice coordinates,
so every run writes the same bytes.
"""
import functools
import math
import os
import struct
import sys
import zlib

SIZES = {"bricks": (256, 256), "planks": (256, 256), "plaster": (128, 128), "wood": (64, 256)}


# Cached: the noise asks for the same lattice points over and over (each pixel's octaves read four corners
# each); a pure function of its integers, so the bytes written do not change. test_gallery runs this twice.
@functools.lru_cache(maxsize=None)
def hash01(*ints):
    """A deterministic hash of integers to [0, 1) (a 32-bit integer mixer; no global random state)."""
    h = 0x9E3779B9
    for i in ints:
        h ^= (i & 0xFFFFFFFF) + 0x7F4A7C15 + ((h << 6) & 0xFFFFFFFF) + (h >> 2)
        h &= 0xFFFFFFFF
        h ^= h >> 16
        h = (h * 0x85EBCA6B) & 0xFFFFFFFF
        h ^= h >> 13
        h = (h * 0xC2B2AE35) & 0xFFFFFFFF
        h ^= h >> 16
    return h / 4294967296.0


def value_noise(x, y, px, py, seed):
    """Smooth value noise on an integer lattice that wraps with period (px, py)."""
    x0, y0 = math.floor(x), math.floor(y)
    fx, fy = x - x0, y - y0
    sx, sy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)
    a = hash01(seed, x0 % px, y0 % py)
    b = hash01(seed, (x0 + 1) % px, y0 % py)
    c = hash01(seed, x0 % px, (y0 + 1) % py)
    d = hash01(seed, (x0 + 1) % px, (y0 + 1) % py)
    return (a + (b - a) * sx) + ((c + (d - c) * sx) - (a + (b - a) * sx)) * sy


def fbm(u, v, fx, fy, octaves, seed):
    """Fractal sum of value noise over the unit tile (u, v in [0, 1)), fx x fy cells at the base octave."""
    s, amp, norm = 0.0, 1.0, 0.0
    for o in range(octaves):
        k = 1 << o
        s += amp * value_noise(u * fx * k, v * fy * k, fx * k, fy * k, seed + 101 * o)
        norm += amp
        amp *= 0.5
    return s / norm


def clamp8(c):
    return max(0, min(255, int(round(c * 255.0))))


def mix(a, b, t):
    return [a[i] + (b[i] - a[i]) * t for i in range(3)]


def bricks(w, h):
    rows, cols, mortar = 4, 2, 0.035   # courses per tile, bricks per course, mortar width (tile units)
    px = []
    for y in range(h):
        v = (y + 0.5) / h
        row = int(v * rows)
        for x in range(w):
            u = (x + 0.5) / w
            shift = 0.5 / cols if row % 2 else 0.0
            bu = (u + shift) % 1.0
            col = int(bu * cols)
            du = min(bu * cols - col, col + 1 - bu * cols) / cols      # distance to a vertical joint
            dv = min(v * rows - row, row + 1 - v * rows) / rows        # distance to a horizontal joint
            grain = fbm(u, v, 16, 16, 3, 7)
            if min(du, dv) < mortar * 0.5:
                g = 0.62 + 0.12 * grain
                px.append([g, g * 0.98, g * 0.93])
            else:
                tone = hash01(11, row, col % cols)                      # each brick its own shade
                base = mix([0.58, 0.25, 0.17], [0.72, 0.38, 0.24], tone)
                blot = fbm(u, v, 8, 8, 4, 13)
                px.append([c * (0.78 + 0.4 * blot) for c in base])
    return px


def planks(w, h):
    n = 4                                   # planks across u; grain runs along v
    px = []
    for y in range(h):
        v = (y + 0.5) / h
        for x in range(w):
            u = (x + 0.5) / w
            k = int(u * n)
            fu = u * n - k
            joint_v = hash01(23, k)                                    # staggered butt joint
            dv = abs(((v - joint_v + 0.5) % 1.0) - 0.5)
            tone = hash01(29, k)
            rings = fbm(u, v, 32, 2, 3, 31 + k)
            grain = 0.5 + 0.5 * math.sin(2 * math.pi * (fu * 3.0 + 4.0 * rings))
            base = mix([0.55, 0.36, 0.20], [0.70, 0.50, 0.30], tone)
            c = [b * (0.82 + 0.22 * grain) for b in base]
            if min(fu, 1 - fu) < 0.025 or dv < 0.004:
                c = [b * 0.35 for b in c]                              # dark gap between boards
            px.append(c)
    return px


def plaster(w, h):
    px = []
    for y in range(h):
        v = (y + 0.5) / h
        for x in range(w):
            u = (x + 0.5) / w
            blot = fbm(u, v, 4, 4, 4, 41)
            fine = hash01(43, x, y)
            g = 0.80 + 0.10 * blot + 0.03 * (fine - 0.5)
            px.append([g, g * 0.97, g * 0.91])
    return px


def wood(w, h):
    px = []
    for y in range(h):
        v = (y + 0.5) / h
        for x in range(w):
            u = (x + 0.5) / w
            warp = fbm(u, v, 4, 2, 3, 53)
            grain = 0.5 + 0.5 * math.sin(2 * math.pi * (u * 6.0 + 2.5 * warp))
            streak = fbm(u, v, 16, 4, 2, 59)
            base = [0.66, 0.45, 0.26]
            px.append([b * (0.70 + 0.25 * grain + 0.15 * streak) for b in base])
    return px


def png_bytes(w, h, px):
    """An 8-bit RGB PNG with an sRGB chunk; rows unfiltered, zlib level 9 (deterministic)."""
    raw = bytearray()
    for y in range(h):
        raw.append(0)
        for x in range(w):
            raw.extend(clamp8(c) for c in px[y * w + x])

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
            chunk(b"sRGB", b"\x00") + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                                              "scenes", "axe")
    os.makedirs(out, exist_ok=True)
    makers = {"bricks": bricks, "planks": planks, "plaster": plaster, "wood": wood}
    for name, (w, h) in SIZES.items():
        path = os.path.join(out, name + ".png")
        tmp = path + ".tmp"
        with open(tmp, "wb") as f:
            f.write(png_bytes(w, h, makers[name](w, h)))
        os.replace(tmp, path)
        print(f"{path}: {w}x{h}")


if __name__ == "__main__":
    main()
