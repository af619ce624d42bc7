#!/usr/bin/env python3
"""mkedges.py — writes the enhanced-edges scenes of tube74 (scenes/edges-*.s74, paper 002).

Paper 002 shows its method on an example model (Fig. 8), a floppy disk (Fig. 12) and a
telephone (Fig. 13), but the text we have carries no pictures: these models are the
project's own, made in the same spirit. Also: a prism of many sides in a smooth group
beside the same prism not smooth, and edges versions of paper 003's street (Fig. 10) and
interpenetrations (Fig. 7) with intersection lines within one object and between objects.
Turned models use integer rotation matrices (the 3-4-5 triangle), so every face stays
exactly planar on the integer grid. Run from the repository root: python3 tools/mkedges.py
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from s74 import Scene, street_blocks  # noqa: E402


class Model(Scene):
    """A Scene whose vertices pass through an integer linear map and a shift."""

    def __init__(self, title, m=None, shift=(0, 0, 0)):
        super().__init__(title)
        self.m = m or ((1, 0, 0), (0, 1, 0), (0, 0, 1))
        self.shift = shift
        self.objects = []

    def v(self, x, y, z):
        m, s = self.m, self.shift
        p = (x, y, z)
        q = tuple(sum(m[r][c] * p[c] for c in range(3)) + s[r] for r in range(3))
        return super().v(*q)

    def obj(self, faces, smooth=False):
        oid = len(self.objects) + 1
        self.objects.append(oid)
        self.lines.append("object %d %s%s" % (oid, " ".join(map(str, faces)),
                                              " smooth" if smooth else ""))
        return oid

    def prism(self, profile, y0, y1, grey=None):
        """A prism: profile (x, z) counter-clockwise seen from above, from y0 to y1."""
        n = len(profile)
        f = []
        for k in range(n):
            (xa, za), (xb, zb) = profile[k], profile[(k + 1) % n]
            f.append(self.face([[(xa, y0, za), (xb, y0, zb), (xb, y1, zb), (xa, y1, za)]], grey))
        f.append(self.face([[(x, y0, z) for x, z in profile]], grey))
        f.append(self.face([[(x, y1, z) for x, z in profile]], grey))
        return f

    def extrude_x(self, profile, x0, x1, grey=None):
        """A prism along x: profile (y, z) from x0 to x1."""
        n = len(profile)
        f = []
        for k in range(n):
            (ya, za), (yb, zb) = profile[k], profile[(k + 1) % n]
            f.append(self.face([[(x0, ya, za), (x1, ya, za), (x1, yb, zb), (x0, yb, zb)]], grey))
        f.append(self.face([[(x0, y, z) for y, z in profile]], grey))
        f.append(self.face([[(x1, y, z) for y, z in profile]], grey))
        return f


def mul(a, b):
    return tuple(tuple(sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)) for r in range(3))


RY = ((4, 0, 3), (0, 5, 0), (-3, 0, 4))       # turn about y by 36.9 degrees, times 5
RYN = ((4, 0, -3), (0, 5, 0), (3, 0, 4))      # the other way
RX = ((5, 0, 0), (0, 4, 3), (0, -3, 4))       # tip the top towards the eye by 36.9 degrees, times 5


def circle(n, r, cx=0, cz=0):
    return [(cx + round(r * math.cos(2 * math.pi * k / n)), cz + round(r * math.sin(2 * math.pi * k / n)))
            for k in range(n)]


def fig8():
    s = Model("""Enhanced edges (paper 002): a model of the kind of its Fig. 8 (the project's own; the
text has no picture). An L-shaped bracket (concave) with a round post standing on its
foot (a 20-sided prism in a smooth group: its side edges are not drawn, its silhouette
is) and a block lying against the upright. Edges: see --dump tables.""",
              m=mul(RX, RY), shift=(0, 0, 2600))
    s.say("view 0 0 -1000")
    s.say("window -200 -150 200 150")
    s.say("light -3 5 -4")
    s.say("effects edges=on")
    # the bracket: profile in (y, z), extruded along x; the upright at the back
    prof = [(-12, -16), (-12, 16), (16, 16), (16, 10), (-6, 10), (-6, -16)]
    s.obj(s.extrude_x(prof, -14, 14))
    # the post on the foot: x, z around (-6, -6), y from -6 to 8
    s.obj(s.prism([(x, z) for x, z in circle(20, 5, -6, -7)], -6, 8), smooth=True)
    # a block against the upright
    s.obj(s.box(2, -6, 0, 12, 0, 10, [None] * 6))
    s.write("scenes/edges-fig8.s74")


def floppy():
    s = Model("""Enhanced edges (paper 002): a 3.5-inch floppy disk, of the kind of its Fig. 12 (the
project's own model). Body 90 x 94 x 3 mm, a metal shutter and a label standing 0.5 mm
proud, the hub ring on the back seen through the tilt, a write-protect slider.""",
              m=mul(RX, RYN), shift=(0, 0, 7600))
    s.say("view 0 0 -1000")
    s.say("window -200 -150 200 150")
    s.say("light -2 6 -3")
    s.say("effects edges=on")
    u = 1                                      # world units per mm (times 25 by the turn)
    s.obj(s.box(-45 * u, 0, -47 * u, 45 * u, 3 * u, 47 * u, [None] * 6))         # body
    s.obj(s.box(-25 * u, 3 * u, -47 * u, 15 * u, 4 * u, -14 * u, [None] * 6))    # shutter
    s.obj(s.box(-38 * u, 3 * u, 2 * u, 38 * u, 4 * u, 44 * u, [None] * 6))       # label
    s.obj(s.box(30 * u, 3 * u, -44 * u, 38 * u, 4 * u, -38 * u, [None] * 6))     # slider
    s.write("scenes/edges-floppy.s74")


def telephone():
    s = Model("""Enhanced edges (paper 002): a desk telephone, of the kind of its Fig. 13 (the
project's own model). A wedge-shaped base, a handset held by two cradle posts that
stand in the base and reach into it (intersection lines between objects), six keys set into the sloping
front (each cuts through the slope: intersection lines).""",
              m=mul(RX, RY), shift=(0, -60, 4200))
    s.say("view 0 0 -1000")
    s.say("window -200 -150 200 150")
    s.say("light -2 6 -5")
    s.say("effects edges=on")
    # base: profile (y, z) from the low front to the high back, extruded along x
    s.obj(s.extrude_x([(0, -24), (0, 24), (14, 24), (14, 8), (6, -24)], -18, 18))
    # cradle posts standing in the base's flat top (y = 14), and the handset on them
    s.obj(s.box(-16, 10, 12, -12, 19, 18, [None] * 6))
    s.obj(s.box(12, 10, 12, 16, 19, 18, [None] * 6))
    s.obj(s.box(-22, 17, 10, 22, 23, 20, [None] * 6))            # handset, the posts in it
    # keys on the slope y = 6 + (z + 24) / 4 (z from -24 to 8): a 3 x 2 grid
    for row in range(2):
        z0 = -19 + 10 * row
        for col in range(3):
            x0 = -9 + 7 * col
            ylo = 6 + (z0 + 24) // 4 - 2
            yhi = 6 + (z0 + 5 + 24 + 3) // 4 + 2
            s.obj(s.box(x0, ylo, z0, x0 + 5, yhi, z0 + 5, [None] * 6))
    s.write("scenes/edges-telephone.s74")


def prisms():
    s = Model("""Enhanced edges (paper 002 §3.2, e'1 and e'2): a 32-sided prism in a smooth group
(left: the edges between its sides are not drawn, its two silhouettes and rims are)
beside the same prism not smooth (right: every edge between sides seen is an inner edge).""")
    s.say("view 0 300 -1000")
    s.say("window -200 -150 200 150")
    s.say("light -3 4 -5")
    s.say("effects edges=on")
    s.obj(s.prism(circle(32, 80, -100, 400), -200, 0), smooth=True)
    s.obj(s.prism(circle(32, 80, 100, 400), -200, 0))
    s.write("scenes/edges-prism.s74")


def street():
    s = Model("""Enhanced edges (paper 002) on the street of paper 003's Fig. 10: each building is an
object (a closed box: silhouettes are outlines, edges between walls seen are inner), the
road and the windows are faces in no object (each its own part: its edges are outlines).""")
    s.say("view 0 60 -1400")
    s.say("window -400 -300 400 300")
    s.say("background harbour.pgm")
    s.say("effects halftone=4x4 pattern=dispersed edges=on")
    street_blocks(s, each_box=s.obj)      # each building one object
    s.write("scenes/edges-street.s74")


def fig7():
    s = Model("""Enhanced edges (paper 002, e4) on paper 003's Fig. 7: intersection lines between
objects (a box driven through another box: outlines) and within one object (two plates of
one object crossing each other: inner).""",
              m=RY, shift=(0, 0, 300))
    s.say("view 0 120 -1000")
    s.say("window -200 -150 200 150")
    s.say("light -3 5 -4")
    s.say("effects edges=on")
    s.obj(s.box(-30, -20, -14, -2, 8, 14, [None] * 6))
    s.obj(s.box(-12, -10, -6, 22, 2, 6, [None] * 6))
    a = s.face([[(4, -24, 16), (28, -24, 16), (28, 12, 16), (4, 12, 16)]], None)
    b = s.face([[(16, -24, 6), (16, -24, 26), (16, 12, 26), (16, 12, 6)]], None)
    s.obj([a, b])
    s.write("scenes/edges-fig7.s74")


if __name__ == "__main__":
    os.makedirs("scenes", exist_ok=True)
    fig8()
    floppy()
    telephone()
    prisms()
    street()
    fig7()
