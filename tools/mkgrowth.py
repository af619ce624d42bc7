#!/usr/bin/env python3
"""mkgrowth.py N [SEED] [--obj] — a scene of about N faces for measuring growth (make bench).

Boxes of 6 faces on a jittered grid at random depths, so that faces overlap on the
perspective plane at every size (and some boxes interpenetrate). Deterministic.

As .s74 (the default) a scene holds vertex and face ids 1..65535 (CONTRACT.md), so at
most 8191 boxes (65,528 vertices, about 49,000 faces); beyond that the script refuses
(exit 2) unless --obj is given: the same boxes as a Wavefront .obj (faces numbered in
file order, as the importer does; no greys: the importer shades by its light), which
tube74 maps onto its grid with its own fitted camera (render/import.h). Two vertices no
face uses, at (0, 0, 0) and (0, 0, -3200), make the model's largest extent 3200, so the
importer's scale is exactly 4 and every box face stays exactly planar on the grid (any
other scale would round most of them out of plane and split them into triangles).
100,000 faces (16,667 boxes, 133,336 vertices) need --obj.
"""
import random
import sys

args = [a for a in sys.argv[1:] if a != "--obj"]
obj = "--obj" in sys.argv[1:]
if not args or len(args) > 2:
    sys.exit("usage: mkgrowth.py N [SEED] [--obj]")
n = int(args[0])
random.seed(int(args[1]) if len(args) > 1 else 1)
nboxes = max(1, (n + 5) // 6)
if not obj and 8 * nboxes > 65535:
    sys.stderr.write("mkgrowth.py: %d faces need %d vertices; a .s74 file holds ids up to "
                     "65535: use --obj\n" % (n, 8 * nboxes))
    sys.exit(2)
if obj:
    out = ["# %d faces for make bench (tools/mkgrowth.py --obj)" % n,
           "v 0 0 0", "v 0 0 -3200"]     # extent 3200 in z: the importer's scale is 4
    vid = 2
else:
    out = ["# %d faces for make bench (tools/mkgrowth.py)" % n,
           "view 0 0 -2000", "window -400 -300 400 300"]
face = 0
if not obj:
    vid = 0
side = int(nboxes ** 0.5) + 1
faces = []
for b in range(nboxes):
    gx, gy = b % side, b // side
    s = max(4, 700 // side)
    x0 = -350 + gx * 700 // side + random.randint(0, s // 3)
    y0 = -260 + gy * 520 // side + random.randint(0, s // 3)
    z0 = random.randint(0, 2000)
    x1, y1, z1 = x0 + s, y0 + s, z0 + random.randint(s // 2, 3 * s)
    corners = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
               (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    for p in corners:
        vid += 1
        if obj:
            # the importer turns z (its eye looks along -z of the file): write -z so that
            # near stays near
            out.append("v %d %d %d" % (p[0], p[1], -p[2]))
        else:
            out.append("vertex %d %d %d %d" % ((vid,) + p))
    base = vid - 8
    for f in [(0, 1, 2, 3), (1, 5, 6, 2), (3, 2, 6, 7), (4, 0, 3, 7), (5, 4, 7, 6), (4, 5, 1, 0)]:
        if face == n:
            break
        face += 1
        grey = random.randint(60, 255)
        if obj:
            faces.append("f %s" % " ".join(str(base + 1 + i) for i in f))
        else:
            out.append("face %d %s grey %d" % (face, " ".join(str(base + 1 + i) for i in f), grey))
print("\n".join(out + faces))
