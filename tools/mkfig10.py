#!/usr/bin/env python3
"""mkfig10.py — write scenes/fig10a.s74, fig10b.s74, fig10c.s74: computer-made buildings
over real photographs, in the manner of Fig. 10 (a)-(c) of paper 003 ("手前にある建物が計算機
によって生成された図である": the buildings in front are made by the computer).

The paper prints the three pictures but no data for them, so the buildings are the
project's own. They exercise what the paper is about: concave faces (L, U and stepped
outlines, cut by the Segment Generator), faces with holes (walls with openings through
which the photograph shows; `*` in the face statement) and interpenetration (volumes that
cross each other, cut along their intersection lines, eq. (5)). Every building is a prism:
a plane outline (possibly concave, possibly with holes) extruded along z, so every face is
exactly planar. The photographs are scenes/photo-*.pgm (tools/mkphotos.sh; sources and
licences in scenes/README.md).

Usage: python3 tools/mkfig10.py        (writes the three scenes into scenes/)
"""
import os
import sys


class Scene:
    def __init__(self):
        self.v = []          # (x, y, z)
        self.f = []          # (rings, grey)

    def vert(self, p):
        self.v.append(p)
        return len(self.v)

    def face(self, rings, grey):
        self.f.append((rings, grey))

    def prism(self, outer, holes, z0, z1, front, side, back=None):
        """Extrude outline `outer` (list of (x, y)) with `holes` from z0 to z1."""
        rings = [outer] + holes
        f_ids, b_ids = [], []
        for r in rings:
            f_ids.append([self.vert((x, y, z0)) for x, y in r])
            b_ids.append([self.vert((x, y, z1)) for x, y in r])
        self.face(f_ids, front)
        self.face(b_ids, back if back is not None else side)
        for fr, br in zip(f_ids, b_ids):
            n = len(fr)
            for k in range(n):
                a, b = k, (k + 1) % n
                self.face([[fr[a], fr[b], br[b], br[a]]], side)

    def box(self, x0, y0, z0, x1, y1, z1, front, side):
        self.prism([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], [], z0, z1, front, side)

    def write(self, path, head, view, window, background):
        with open(path, "w") as o:
            for line in head:
                o.write("# " + line + "\n")
            o.write("view %d %d %d\nwindow %d %d %d %d\n" % (view + window))
            o.write("background %s\n" % background)
            o.write("effects halftone=4x4 pattern=dispersed\n")
            for k, (x, y, z) in enumerate(self.v):
                o.write("vertex %d %d %d %d\n" % (k + 1, x, y, z))
            for k, (rings, grey) in enumerate(self.f):
                parts = [" ".join(str(i) for i in rings[0])]
                parts += ["* " + " ".join(str(i) for i in r) for r in rings[1:]]
                o.write("face %d %s grey %d\n" % (k + 1, " ".join(parts), grey))


def rect(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def fig10a(s):
    # an L-shaped block (concave front and back), its wall pierced by two window
    # openings (holes), and a tower that passes through its roof (interpenetration)
    L = [(-330, -200), (40, -200), (40, -60), (-180, -60), (-180, 170), (-330, 170)]
    s.prism(L, [rect(-300, -170, -230, -100), rect(-140, -170, -40, -110)], 0, 240, 210, 120, 90)
    s.box(-290, -40, 60, -210, 260, 170, 235, 150)            # the tower through the L
    s.box(120, -200, 100, 300, 20, 300, 180, 100)             # a low house to the right
    s.box(90, -30, 160, 330, 60, 240, 240, 130)               # its roof slab, crossing it


def fig10b(s):
    # a gate (a U outline: concave), a lattice wall (a face with three holes) and two
    # slabs crossing each other in an X (interpenetration)
    U = [(-340, -210), (-120, -210), (-120, 120), (-170, 120), (-170, -80), (-290, -80),
         (-290, 120), (-340, 120)]
    s.prism(U, [], 0, 80, 220, 110, 90)
    s.prism(rect(-60, -210, 160, 60),
            [rect(-40, -150, 10, -80), rect(40, -150, 90, -80), rect(110, -150, 140, 20)],
            40, 100, 190, 100, 70)
    s.prism(rect(200, -210, 330, 140), [], 20, 260, 230, 140)   # slab one ...
    s.prism([(180, 40), (350, 40), (350, 90), (180, 90)], [], -40, 320, 160, 90)  # ... two


def fig10c(s):
    # a stepped facade (concave, three steps), a cross of two blocks that
    # interpenetrate, and a wall with an arch-like opening (a hole of a concave outline)
    steps = [(-350, -220), (-80, -220), (-80, -120), (-160, -120), (-160, -20),
             (-240, -20), (-240, 80), (-350, 80)]
    s.prism(steps, [], 0, 200, 215, 120, 80)
    s.box(20, -220, 60, 320, -60, 200, 200, 110)                # block one ...
    s.box(110, -220, -20, 230, 140, 280, 240, 150)              # ... and two, crossing it
    arch = [(-300, 110), (-200, 110), (-200, 200), (-230, 200), (-230, 150), (-270, 150),
            (-270, 200), (-300, 200)]
    s.prism(rect(-340, 90, -160, 230), [arch], 120, 160, 180, 90)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes"
    common = ["Fig. 10 of paper 003 in tube74's data: computer-made buildings over a real",
              "photograph (lowest priority). Written by tools/mkfig10.py; the photograph:",
              "scenes/README.md (source, licence)."]
    view, window = (-260, 230, -1300), (-400, -300, 400, 300)
    for name, fn, photo, what in (
            ("fig10a", fig10a, "photo-camera.pgm",
             "(a) an L block with window openings (holes), a tower through its roof"),
            ("fig10b", fig10b, "photo-rocket.pgm",
             "(b) a gate (U outline), a lattice wall (three holes), two slabs crossing"),
            ("fig10c", fig10c, "photo-grass.pgm",
             "(c) a stepped facade, two blocks crossing, a wall with an arch opening")):
        s = Scene()
        fn(s)
        s.write(os.path.join(out, name + ".s74"), common + [what], view, window, photo)


if __name__ == "__main__":
    main()
