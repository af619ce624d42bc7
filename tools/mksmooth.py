#!/usr/bin/env python3
"""mksmooth.py — writes the scenes of paper 004's Table 1 (scenes/t1-a.s74 .. t1-j.s74)
and a many-triangle model (scenes/sphere.s74), for smooth= and contour= (README
"Smooth shading (paper 004)", docs/smooth.md).

Object 1 is the paper's 六角錐柱, built as a hexagonal prism with a hexagonal pyramid on
top (錐 pyramid + 柱 prism: a "pyramid-prism", like a sharpened pencil): a plain prism
would be 六角柱 and a plain pyramid 六角錐; the compound names a solid with both, which
also gives the pictures flat sides, a ridge ring and an apex to smooth. Every face is made
of triangles (the paper's triangle patch model): the bottom hexagon a fan of 6 round its
centre, each side rectangle 2, the pyramid 6, 24 in all. Object 2 is a cube of two
triangles a face (12). The sphere is an icosahedron subdivided twice (320
triangles) on the integer grid.
Run from the repository root: python3 tools/mksmooth.py
"""
import math
import os

VIEW = "view 0 0 -1000"
WINDOW = "window -200 -150 200 150"
LIGHT = "light -45 60 -80"


def rot(p, ax, ay):
    """Rotate about x by ax, then about y by ay (degrees)."""
    x, y, z = p
    a = math.radians(ax)
    y, z = y * math.cos(a) - z * math.sin(a), y * math.sin(a) + z * math.cos(a)
    b = math.radians(ay)
    x, z = x * math.cos(b) + z * math.sin(b), -x * math.sin(b) + z * math.cos(b)
    return x, y, z


class Scene:
    def __init__(self, title):
        self.lines = ["# " + t for t in title.strip().splitlines()]
        self.lines += [VIEW, WINDOW, LIGHT]
        self.nv = 0
        self.nf = 0
        self.index = {}
        self.faces = []

    def v(self, p):
        key = tuple(int(round(c)) for c in p)
        if key not in self.index:
            self.nv += 1
            self.index[key] = self.nv
            self.lines.append("vertex %d %d %d %d" % ((self.nv,) + key))
        return self.index[key]

    def tri(self, a, b, c):
        self.nf += 1
        self.lines.append("face %d %d %d %d" % (self.nf, a, b, c))
        self.faces.append(self.nf)

    def write(self, path, effects):
        self.lines.append("object 1 " + " ".join(str(f) for f in self.faces))
        self.lines.append("effects " + effects)
        with open(path, "w") as f:
            f.write("\n".join(self.lines) + "\n")


def place(p, ax, ay, centre):
    q = rot(p, ax, ay)
    return (q[0] + centre[0], q[1] + centre[1], q[2] + centre[2])


def pencil(s, ax=-25, ay=20, centre=(0, -10, 500)):
    """Hexagonal prism (radius 145, height 225) under a pyramid (height 120)."""
    r, y0, y1, y2 = 145, -160, 65, 185
    ring0 = [s.v(place((r * math.cos(math.radians(30 + 60 * k)), y0,
                        r * math.sin(math.radians(30 + 60 * k))), ax, ay, centre)) for k in range(6)]
    ring1 = [s.v(place((r * math.cos(math.radians(30 + 60 * k)), y1,
                        r * math.sin(math.radians(30 + 60 * k))), ax, ay, centre)) for k in range(6)]
    bot = s.v(place((0, y0, 0), ax, ay, centre))
    apex = s.v(place((0, y2, 0), ax, ay, centre))
    for k in range(6):
        a, b = k, (k + 1) % 6
        s.tri(bot, ring0[b], ring0[a])
        s.tri(ring0[a], ring0[b], ring1[b])
        s.tri(ring0[a], ring1[b], ring1[a])
        s.tri(ring1[a], ring1[b], apex)


def cube(s, ax=-25, ay=30, centre=(0, 0, 500), h=115):
    c = [s.v(place((x * h, y * h, z * h), ax, ay, centre))
         for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    # corners: index = 4*(x>0) + 2*(y>0) + (z>0); quads listed outward
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    for a, b, cc, d in quads:
        s.tri(c[a], c[b], c[cc])
        s.tri(c[a], c[cc], c[d])


def lprism(s, ax=-30, ay=25, centre=(0, 0, 500), u=80, depth=80):
    """An L-shaped prism (concave outline: one concave contour vertex at least)."""
    ring = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    pts = [((x - 1) * u, (y - 1) * u) for x, y in ring]
    front = [s.v(place((x, y, -depth), ax, ay, centre)) for x, y in pts]
    back = [s.v(place((x, y, depth), ax, ay, centre)) for x, y in pts]
    for k in range(1, 5):            # fan from corner 0: the L is star-shaped from it
        s.tri(front[0], front[k + 1], front[k])
        s.tri(back[0], back[k], back[k + 1])
    for k in range(6):
        a, b = k, (k + 1) % 6
        s.tri(front[a], front[b], back[b])
        s.tri(front[a], back[b], back[a])


def icosphere(s, radius=125, centre=(0, 0, 500), levels=3):
    t = (1 + 5 ** 0.5) / 2
    vs = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
          (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    vs = [tuple(c / math.sqrt(sum(x * x for x in v)) for c in v) for v in vs]
    fs = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
          (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
          (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        mid = {}

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = [(vs[a][k] + vs[b][k]) / 2 for k in range(3)]
                n = math.sqrt(sum(x * x for x in p))
                vs.append(tuple(x / n for x in p))
                mid[key] = len(vs) - 1
            return mid[key]
        nf = []
        for a, b, c in fs:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        fs = nf
    ids = [s.v(tuple(radius * v[k] + centre[k] for k in range(3))) for v in vs]
    for a, b, c in fs:
        s.tri(ids[a], ids[b], ids[c])


def uvsphere(s, nlon, nlat, radius=125, centre=(0, 0, 500), ax=-20, far=None):
    """A globe of nlon meridians and nlat bands: 2 nlon (nlat - 1) triangles, the ones
    wholly farther than centre + far left out."""
    def pos(i, j):
        th = math.pi * j / nlat
        ph = 2 * math.pi * i / nlon
        q = (radius * math.sin(th) * math.cos(ph), radius * math.cos(th),
             radius * math.sin(th) * math.sin(ph))
        return place(q, ax, 10, centre)

    def tri(*ij):
        ps = [pos(i, j) for i, j in ij]
        # the far side (every corner behind the plane z = centre + far) is left out:
        # it is hidden anyway, and the whole globe would not fit 16 kW
        if far is not None and all(q[2] > centre[2] + far for q in ps):
            return
        s.tri(*[s.v(q) for q in ps])
    for i in range(nlon):
        a = i
        b = (i + 1) % nlon
        tri((0, 0), (b, 1), (a, 1))
        tri((0, nlat), (a, nlat - 1), (b, nlat - 1))
        for j in range(1, nlat - 1):
            tri((a, j), (b, j), (b, j + 1))
            tri((a, j), (b, j + 1), (a, j + 1))


NLON, NLAT = int(os.environ.get("NLON", 16)), int(os.environ.get("NLAT", 8))
FAR = int(os.environ.get("FAR", 30))

ROWS = [
    ("a", 1, "smooth=fixed:0.05", "fixed width 0.05, no contour smoothing"),
    ("b", 1, "smooth=prop:0.05", "proportional width 0.05, no contour smoothing"),
    ("c", 1, "smooth=fixed:0.15", "fixed width 0.15, no contour smoothing"),
    ("d", 1, "smooth=prop:0.15", "proportional width 0.15, no contour smoothing"),
    ("e", 1, "smooth=prop:0.15 contour=0.5", "proportional 0.15, contour 0.5"),
    ("f", 1, "smooth=phong contour=1.0", "whole smoothing, contour 1.0"),
    ("g", 2, "smooth=phong contour=0.5", "whole smoothing, contour 0.5"),
    ("h", 2, "smooth=phong contour=1.0", "whole smoothing, contour 1.0"),
    ("i", 2, "smooth=phong contour=0.0", "whole smoothing, contour 0.0 (a visible case)"),
    ("j", 2, "smooth=prop:0.15 contour=0.5", "proportional 0.15, contour 0.5, turned 45 degrees"),
]


def main():
    os.makedirs("scenes", exist_ok=True)
    for row, obj, eff, what in ROWS:
        s = Scene("Paper 004 Table 1 row %s: object %d (%s), %s.\n"
                  "Written by tools/mksmooth.py." %
                  (row, obj, "hexagonal prism under a pyramid" if obj == 1 else
                   "cube of two triangles a face", what))
        if obj == 1:
            pencil(s)
        elif row == "j":
            cube(s, ay=30 + 45)
        else:
            cube(s)
        s.write("scenes/t1-%s.s74" % row, "halftone=3x3 " + eff)
    s = Scene("A concave object for contour=: an L-shaped prism (20 triangles); its\n"
              "concave contour vertices stay sharp. Written by tools/mksmooth.py.")
    lprism(s)
    s.write("scenes/lprism.s74", "halftone=3x3 smooth=phong contour=1.0")
    s = Scene("A many-triangle model for smooth=: the front of a globe of %d meridians and\n"
              "%d bands on the integer grid (its far side, hidden, left out to fit 16 kW).\n"
              "Written by tools/mksmooth.py." % (NLON, NLAT))
    uvsphere(s, NLON, NLAT, far=FAR)
    s.write("scenes/sphere.s74", "halftone=3x3 smooth=phong contour=1.0")


if __name__ == "__main__":
    main()
