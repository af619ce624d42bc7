#!/usr/bin/env python3
"""mkscenes.py — writes the shipped scenes of tube74 (scenes/*.s74).

Recreations of paper 003's cases: the simple polygons of Fig. 5, the face with a hole and
several concave vertices of Fig. 6, the two kinds of interpenetration of Fig. 7, and a
street of buildings with windows in front of a background picture, like Fig. 10.
Run from the repository root: python3 tools/mkscenes.py
"""
import os


class Scene:
    def __init__(self, title):
        self.lines = ["# " + line for line in title.strip().splitlines()]
        self.nv = 0
        self.nf = 0
        self.index = {}

    def say(self, text):
        self.lines.append(text)

    def v(self, x, y, z):
        key = (x, y, z)
        if key in self.index:
            return self.index[key]
        self.nv += 1
        self.index[key] = self.nv
        self.lines.append("vertex %d %d %d %d" % (self.nv, x, y, z))
        return self.nv

    def face(self, rings, grey=None, fid=None):
        """rings: list of point lists; the first is the boundary, the rest holes."""
        if fid is None:
            self.nf += 1
            fid = self.nf
        else:
            self.nf = max(self.nf, fid)
        ids = []
        for k, ring in enumerate(rings):
            if k:
                ids.append("*")
            ids.extend(str(self.v(*p)) for p in ring)
        tail = "" if grey is None else " grey %d" % grey
        self.lines.append("face %d %s%s" % (fid, " ".join(ids), tail))
        return fid

    def box(self, x0, y0, z0, x1, y1, z1, greys):
        """An axis-aligned box; greys: front, right, top, left, back, bottom."""
        f = []
        P = lambda x, y, z: (x, y, z)
        f.append(self.face([[P(x0, y0, z0), P(x1, y0, z0), P(x1, y1, z0), P(x0, y1, z0)]], greys[0]))
        f.append(self.face([[P(x1, y0, z0), P(x1, y0, z1), P(x1, y1, z1), P(x1, y1, z0)]], greys[1]))
        f.append(self.face([[P(x0, y1, z0), P(x1, y1, z0), P(x1, y1, z1), P(x0, y1, z1)]], greys[2]))
        f.append(self.face([[P(x0, y0, z1), P(x0, y0, z0), P(x0, y1, z0), P(x0, y1, z1)]], greys[3]))
        f.append(self.face([[P(x1, y0, z1), P(x0, y0, z1), P(x0, y1, z1), P(x1, y1, z1)]], greys[4]))
        f.append(self.face([[P(x0, y0, z1), P(x1, y0, z1), P(x1, y0, z0), P(x0, y0, z0)]], greys[5]))
        return f

    def write(self, path):
        with open(path, "w") as fh:
            fh.write("\n".join(self.lines) + "\n")


def flat(points, z=0):
    return [(x, y, z) for x, y in points]


def fig5():
    s = Scene("""Fig. 5 of paper 003: the simple concave polygons whose cuts are the rewrite rules
(a) XaAb -> aAb, abX      (b) XaAcBb -> aAc, cBb, abX
(b') XaAbYd -> aAb, abX, dbY      (c) XaAb*Ye -> aAb, aeYebX
Each lies flat on the plane z = 0 and is seen straight on.""")
    s.say("view 0 0 -1000")
    s.say("window -200 -150 200 150")
    # (a) a notch in the left side: one concave vertex, one lower and one upper piece
    s.face([flat([(-190, 10), (-110, 10), (-110, 140), (-190, 140), (-150, 75)])], 255)
    # (b) a notch from below (concave vertex c pointing up): two lower pieces
    s.face([flat([(-90, 10), (-50, 10), (-30, 70), (-10, 10), (30, 10), (30, 140), (-90, 140)])], 200)
    # (b') a notch from above (concave vertex b pointing down): two upper pieces
    s.face([flat([(60, 10), (190, 10), (190, 140), (150, 140), (125, 60), (100, 140), (60, 140)])], 160)
    # (c) a face with a hole: the cut through the hole's lowest vertex e joins it to the boundary
    s.face([flat([(-190, -140), (-20, -140), (-20, -10), (-190, -10)]),
            flat([(-105, -110), (-60, -75), (-105, -40), (-150, -75)])], 230)
    # several concave vertices on one horizontal line: a comb
    comb = [(10, -140), (190, -140), (190, -10)]
    for k in range(4):
        x = 170 - 40 * k
        comb += [(x, -10), (x - 10, -90), (x - 20, -10)]
    comb += [(10, -10)]
    s.face([flat(comb)], 180)
    s.write("scenes/fig5.s74")


def fig6():
    s = Scene("""Fig. 6 of paper 003, the paper's own worked example: outer boundary 1..5 with a
notch at 3 between the legs 2 and 4, a hole 6..10 whose bottom vertices 10 and 8 lie on the
first cut line and whose vertex 9 rises between them. The first cut (through 10 and 8)
makes crossing points 11, 12, 13, 14, and the tables of Fig. 6 (a)-(d): PBS, IPL, LWS,
UPS. See them with --dump tables=FILE. (The test face of tests/test_segment.c, 0..100,
mapped by x' = 3x - 150, y' = 2.5y - 125.)""")
    s.say("view 0 0 -1000")
    s.say("window -200 -150 200 150")
    P = lambda x, y: (3 * x - 150, (5 * y) // 2 - 125)
    outer = [P(0, 100), P(10, 0), P(50, 40), P(90, 0), P(100, 100)]
    hole = [P(20, 80), P(80, 80), P(80, 20), P(50, 50), P(20, 20)]
    s.face([flat(outer), flat(hole)], 220)
    s.write("scenes/fig6.s74")


def fig7():
    a = Scene("""Fig. 7 (a) of paper 003: two faces that cut through each other completely;
each is split along the intersection line (eq. (5)).""")
    a.say("view 0 0 -1000")
    a.say("window -200 -150 200 150")
    a.face([[(-150, -100, 100), (100, -100, 100), (100, 100, 100), (-150, 100, 100)]], 240)
    a.face([[(-100, -130, -100), (150, -130, 300), (150, 130, 300), (-100, 130, -100)]], 120)
    a.write("scenes/fig7a.s74")
    b = Scene("""Fig. 7 (b) of paper 003: a face pokes through another without cutting it in
two; the intersection line is extended to reduce the case to (a).""")
    b.say("view 0 0 -1000")
    b.say("window -200 -150 200 150")
    b.face([[(-150, -120, 100), (150, -120, 100), (150, 120, 100), (-150, 120, 100)]], 240)
    b.face([[(-60, -40, 0), (60, -40, 0), (60, -40, 200), (-60, -40, 200)]], 110)
    b.face([[(-60, 40, 20), (60, 40, 20), (0, 90, 260)]], 170)
    b.write("scenes/fig7b.s74")


def street():
    s = Scene("""A street in the manner of Fig. 10 of paper 003: computer-made buildings with
windows in front of a background picture (scenes/harbour.pgm, lowest priority).
Windows are faces lying on their walls; a coplanar face with the larger number is in front.""")
    s.say("view 0 60 -1400")
    s.say("window -400 -300 400 300")
    s.say("background harbour.pgm")
    s.say("effects halftone=4x4 pattern=dispersed")
    ground = -120
    # road and pavement
    s.face([[(-700, ground, 0), (700, ground, 0), (700, ground, 3000), (-700, ground, 3000)]], 70)
    buildings = [
        # x0, x1, z0, z1, height, front grey, side grey, top grey
        (-330, -170, 0, 260, 210, 200, 130, 240),
        (-360, -200, 420, 700, 300, 185, 120, 235),
        (-390, -230, 860, 1200, 180, 175, 110, 225),
        (160, 320, 80, 380, 260, 190, 135, 240),
        (190, 350, 560, 820, 340, 180, 125, 235),
        (220, 380, 1000, 1400, 230, 170, 115, 225),
    ]
    for (x0, x1, z0, z1, h, gf, gs, gt) in buildings:
        y1 = ground + h
        left_side = x1 < 0
        side_windows = z0 < 500
        s.box(x0, ground, z0, x1, y1, z1, [gf, gs, gt, gs, gs, 60])
        # windows on the front wall (z = z0), then on the side facing the street
        wy = ground + 30
        while wy + 34 <= y1 - 20:
            wx = x0 + 18
            while wx + 26 <= x1 - 14:
                s.face([[(wx, wy, z0), (wx + 26, wy, z0), (wx + 26, wy + 34, z0), (wx, wy + 34, z0)]], 40)
                wx += 44
            xs = x1 if left_side else x0
            wz = z0 + 30
            while side_windows and wz + 50 <= z1 - 20:
                if left_side:
                    pts = [(xs, wy, wz + 50), (xs, wy, wz), (xs, wy + 34, wz), (xs, wy + 34, wz + 50)]
                else:
                    pts = [(xs, wy, wz), (xs, wy, wz + 50), (xs, wy + 34, wz + 50), (xs, wy + 34, wz)]
                s.face([pts], 30)
                wz += 80
            wy += 60
    s.write("scenes/street.s74")


def crossing():
    s = Scene("""Two squares that cross each other: the smallest interpenetration case.""")
    s.say("view 0 0 -1000")
    s.say("window -200 -150 200 150")
    s.face([[(-100, -100, 0), (100, -100, 0), (100, 100, 0), (-100, 100, 0)]], 100)
    s.face([[(-50, -50, -100), (150, -50, 100), (150, 150, 100), (-50, 150, -100)]], 200)
    s.write("scenes/crossing.s74")


if __name__ == "__main__":
    os.makedirs("scenes", exist_ok=True)
    fig5()
    fig6()
    fig7()
    street()
    crossing()
