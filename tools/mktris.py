#!/usr/bin/env python3
"""mktris.py N [SEED] — N large interpenetrating triangles for `tube74 bench speed`.

Each triangle spans a good part of the window at a random slant in depth, so that nearly
every pair overlaps on the perspective plane and many pairs pierce each other in space:
the Segment Generator's and the priority matrix's worst case (issue 12). Deterministic.
"""
import random
import sys

n = int(sys.argv[1])
random.seed(int(sys.argv[2]) if len(sys.argv) > 2 else 1)
out = ["# %d interpenetrating triangles for tube74 bench speed (tools/mktris.py)" % n,
       "view 0 0 -3000", "window -400 -300 400 300"]
for t in range(n):
    cx, cy = random.randint(-250, 250), random.randint(-180, 180)
    r = random.randint(120, 260)
    for k in range(3):
        x = cx + random.randint(-r, r)
        y = cy + random.randint(-r, r)
        z = random.randint(500, 2500)
        out.append("vertex %d %d %d %d" % (3 * t + k + 1, x, y, z))
    out.append("face %d %d %d %d grey %d" % (t + 1, 3 * t + 1, 3 * t + 2, 3 * t + 3,
                                              random.randint(60, 255)))
print("\n".join(out))
