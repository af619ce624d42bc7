#!/usr/bin/env python3
"""mkgrowth.py N [SEED] — a scene of about N faces for measuring growth (make bench).

Boxes of 6 faces on a jittered grid at random depths, so that faces overlap on the
perspective plane at every size (and some boxes interpenetrate). Deterministic.
"""
import random
import sys

n = int(sys.argv[1])
random.seed(int(sys.argv[2]) if len(sys.argv) > 2 else 1)
out = ["# %d faces for make bench (tools/mkgrowth.py)" % n,
       "view 0 0 -2000", "window -400 -300 400 300"]
vid = face = 0
nboxes = max(1, (n + 5) // 6)
side = int(nboxes ** 0.5) + 1
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
        out.append("vertex %d %d %d %d" % ((vid,) + p))
    base = vid - 8
    for f in [(0, 1, 2, 3), (1, 5, 6, 2), (3, 2, 6, 7), (4, 0, 3, 7), (5, 4, 7, 6), (4, 5, 1, 0)]:
        if face == n:
            break
        face += 1
        out.append("face %d %s grey %d" % (face, " ".join(str(base + 1 + i) for i in f),
                                           random.randint(60, 255)))
print("\n".join(out))
