#!/usr/bin/python3
"""make_axe.py — writes the axe of scenes/axe_room.yaml as two OBJ meshes built from primitives.

Usage: /usr/bin/python3 tools/make_axe.py [OUTDIR]      (default: scenes/axe next to this tool)

Axe frame (metres): the handle stands along +y from y = 0 to y = HANDLE_LEN, the head sits on its top
with the blade pointing along +x and its flat faces facing +-z.

  axe_head.obj    a bevelled wedge lofted through sections along x, from the poll (back, x < 0) to the
                  cutting edge: each section is an octagon (a rectangle with bevelled corners) whose
                  height flares towards the blade and whose thickness tapers to a thin edge; both ends
                  are capped, so the mesh is closed (every edge shared by exactly two faces, wound
                  outwards). Flat-shaded (no vn). uv: u around the section, v along x.
  axe_handle.obj  a tapered cylinder (a slight knob at the bottom, a waist, a swell under the head),
                  capped at both ends, with smooth normals. uv: u around (a texture seam where u jumps
                  from 1 back to 0: the seam column's positions are shared, its vt are duplicated),
                  v along the length; the caps map a disc into the texture.

Only the standard library is used and every number is printed with a fixed format, so every run
writes the same bytes.
"""
import math
import os
import sys

HANDLE_LEN = 0.76
HEAD_Y = 0.70          # centre height of the head on the handle


def fmt(x):
    s = "%.6f" % x
    return "0.000000" if s == "-0.000000" else s


class Obj:
    def __init__(self, comment):
        self.lines = ["# " + c for c in comment] if comment else []
        self.v, self.vt, self.vn, self.f = [], [], [], []

    def add_v(self, p):
        self.v.append(p)
        return len(self.v)

    def add_vt(self, t):
        self.vt.append(t)
        return len(self.vt)

    def add_vn(self, n):
        self.vn.append(n)
        return len(self.vn)

    def text(self):
        out = list(self.lines)
        out += ["v %s %s %s" % tuple(fmt(c) for c in p) for p in self.v]
        out += ["vt %s %s" % tuple(fmt(c) for c in t) for t in self.vt]
        out += ["vn %s %s %s" % tuple(fmt(c) for c in n) for n in self.vn]
        for face in self.f:
            out.append("f " + " ".join(corner_text(*c) for c in face))
        return "\n".join(out) + "\n"


def corner_text(v, t, n):
    if n is not None:
        return "%d/%s/%d" % (v, "" if t is None else str(t), n)
    return "%d/%d" % (v, t) if t is not None else str(v)


def corner(v, t=None, n=None):
    return (v, t, n)


def head():
    """Lofted bevelled wedge: sections at x = XS, each an octagon in the (y, z) plane."""
    o = Obj(["axe head: bevelled wedge, closed, flat shaded (tools/make_axe.py)"])
    nx = 18
    x0, x1 = -0.055, 0.150
    xs = [x0 + (x1 - x0) * i / (nx - 1) for i in range(nx)]

    def height(x):     # half height of the section
        s = min(1.0, max(0.0, (x - 0.02) / (x1 - 0.02)))
        return 0.034 + 0.052 * s ** 1.6

    def thick(x):      # half thickness
        s = min(1.0, max(0.0, (x - 0.015) / (x1 - 0.015)))
        return 0.024 * (1.0 - s) ** 1.15 + 0.0015

    def yc(x):         # the blade's bearded drop: its centre sinks a little towards the edge
        s = min(1.0, max(0.0, (x - 0.02) / (x1 - 0.02)))
        return -0.012 * s * s

    rings = []
    for i, x in enumerate(xs):
        hy, hz, c = height(x), thick(x), yc(x)
        b = 0.35 * min(hy, hz)           # bevel of each corner
        # octagon: the (y, z) corners of a bevelled rectangle (the side faces are wound outwards below)
        pts = [(hy - b, hz), (-hy + b, hz), (-hy, hz - b), (-hy, -hz + b),
               (-hy + b, -hz), (hy - b, -hz), (hy, -hz + b), (hy, hz - b)]
        ring = []
        for k, (y, z) in enumerate(pts):
            vi = o.add_v((x, HEAD_Y + c + y, z))
            ti = o.add_vt((k / 8.0, i / (nx - 1)))
            ring.append((vi, ti))
        rings.append(ring)
    # sides: quads between consecutive rings, split into triangles, wound outwards
    for i in range(nx - 1):
        a, b = rings[i], rings[i + 1]
        for k in range(8):
            k1 = (k + 1) % 8
            p00, p01, p10, p11 = a[k], a[k1], b[k], b[k1]
            o.f.append([corner(*p00), corner(*p11), corner(*p10)])
            o.f.append([corner(*p00), corner(*p01), corner(*p11)])
    # caps: a fan around the section's centre (poll facing -x, edge facing +x)
    for ring, x, outward in ((rings[0], xs[0], -1), (rings[-1], xs[-1], 1)):
        ci = o.add_v((x, HEAD_Y + yc(x), 0.0))
        cti = o.add_vt((0.5, 0.0 if outward < 0 else 1.0))
        for k in range(8):
            k1 = (k + 1) % 8
            if outward > 0:
                o.f.append([corner(ci, cti), corner(*ring[k]), corner(*ring[k1])])
            else:
                o.f.append([corner(ci, cti), corner(*ring[k1]), corner(*ring[k])])
    return o


def handle():
    o = Obj(["axe handle: tapered cylinder, capped, smooth normals, uv seam at u = 0/1 (tools/make_axe.py)"])
    nu, nv = 24, 24

    def radius(y):
        t = y / HANDLE_LEN
        knob = 0.004 * math.exp(-((t - 0.03) / 0.03) ** 2)          # knob at the bottom end
        swell = 0.003 * math.exp(-((t - 0.85) / 0.10) ** 2)         # swell under the head
        return 0.0145 + 0.0025 * (1 - t) * (1 - t) + knob + swell

    def dradius(y, e=1e-4):
        return (radius(y + e) - radius(y - e)) / (2 * e)

    ys = [HANDLE_LEN * j / (nv - 1) for j in range(nv)]
    grid = []           # grid[j][i] = (v index, vn index) for i in 0..nu-1 (positions shared across the seam)
    for y in ys:
        r, dr = radius(y), dradius(y)
        row = []
        for i in range(nu):
            a = 2 * math.pi * i / nu
            ca, sa = math.cos(a), math.sin(a)
            # the oval section of a real handle: 1.25x deeper along x (the blade's direction)
            p = (1.25 * r * ca, y, r * sa)
            n = (ca / 1.25, -dr, sa)
            ln = math.sqrt(sum(c * c for c in n))
            row.append((o.add_v(p), o.add_vn(tuple(c / ln for c in n))))
        grid.append(row)
    # vt: nu + 1 columns so the seam column has u = 0 and u = 1
    vt = [[o.add_vt((i / nu, j / (nv - 1))) for i in range(nu + 1)] for j in range(nv)]
    for j in range(nv - 1):
        for i in range(nu):
            i1 = (i + 1) % nu
            c00 = corner(grid[j][i][0], vt[j][i], grid[j][i][1])
            c10 = corner(grid[j][i1][0], vt[j][i + 1], grid[j][i1][1])
            c01 = corner(grid[j + 1][i][0], vt[j + 1][i], grid[j + 1][i][1])
            c11 = corner(grid[j + 1][i1][0], vt[j + 1][i + 1], grid[j + 1][i1][1])
            # outward winding: angle grows from +x towards +z, y grows upwards
            o.f.append([c00, c01, c11])
            o.f.append([c00, c11, c10])
    for j, y, sgn in ((0, 0.0, -1), (nv - 1, HANDLE_LEN, 1)):
        ci = o.add_v((0.0, y, 0.0))
        ni = o.add_vn((0.0, float(sgn), 0.0))
        cti = o.add_vt((0.5, 0.5))
        tis = []
        for i in range(nu):
            a = 2 * math.pi * i / nu
            tis.append(o.add_vt((0.5 + 0.45 * math.cos(a), 0.5 + 0.45 * math.sin(a))))
        for i in range(nu):
            i1 = (i + 1) % nu
            a, b = corner(grid[j][i][0], tis[i], ni), corner(grid[j][i1][0], tis[i1], ni)
            if sgn > 0:
                o.f.append([corner(ci, cti, ni), b, a])
            else:
                o.f.append([corner(ci, cti, ni), a, b])
    return o


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                                              "scenes", "axe")
    os.makedirs(out, exist_ok=True)
    for name, mesh in (("axe_head.obj", head()), ("axe_handle.obj", handle())):
        path = os.path.join(out, name)
        tmp = path + ".tmp"
        with open(tmp, "w", newline="\n") as f:
            f.write(mesh.text())
        os.replace(tmp, path)
        print(f"{path}: {len(mesh.v)} vertices, {len(mesh.f)} triangles")


if __name__ == "__main__":
    main()
