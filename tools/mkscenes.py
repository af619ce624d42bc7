#!/usr/bin/env python3
"""mkscenes.py — writes the shipped scenes of tube74 (scenes/*.s74).

Recreations of paper 003's cases: the simple polygons of Fig. 5, the face with a hole and
several concave vertices of Fig. 6, the two kinds of interpenetration of Fig. 7, and a
street of buildings with windows in front of a background picture, like Fig. 10.
Run from the repository root: python3 tools/mkscenes.py
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from s74 import Scene, flat, street_blocks  # noqa: E402


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
    street_blocks(s)
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
