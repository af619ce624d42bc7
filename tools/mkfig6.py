#!/usr/bin/env python3
"""tools/mkfig6.py — the two scenes after Fig. 6 of paper 000 (Nishita & Nakamae):
scenes/fig6-building.s74 (a building with windows as patterns on its walls, lit by the sun
and a street lamp, casting shadows) and scenes/fig6-room.s74 (a room with a textured wall,
after the Japanese room of Fig. 6 (e), (f)), plus the wall's picture scenes/fig6-fusuma.pgm.
Run from the repository root: python3 tools/mkfig6.py
"""

def box(out, ids, x0, y0, z0, x1, y1, z1, fid):
    """Vertices and the five faces (no bottom) of a box; returns the next face id and the
    vertex ids of the front face (z = z0) corners (lower-left, lower-right, upper-right,
    upper-left) and the right face (x = x1)."""
    v = {}
    for name, (x, y, z) in {
        'a': (x0, y0, z0), 'b': (x1, y0, z0), 'c': (x1, y1, z0), 'd': (x0, y1, z0),
        'e': (x0, y0, z1), 'f': (x1, y0, z1), 'g': (x1, y1, z1), 'h': (x0, y1, z1)}.items():
        ids[0] += 1
        v[name] = ids[0]
        out.append(f"vertex {ids[0]} {x} {y} {z}")
    faces = {'front': 'abcd', 'right': 'bfgc', 'back': 'fehg', 'left': 'eadh', 'top': 'dcgh'}
    fids = {}
    for k, ring in faces.items():
        out.append(f"face {fid} " + " ".join(str(v[c]) for c in ring))
        fids[k] = fid
        fid += 1
    return fid, fids

def rect(out, ids, pts):
    vs = []
    for p in pts:
        ids[0] += 1
        vs.append(ids[0])
        out.append(f"vertex {ids[0]} {p[0]} {p[1]} {p[2]}")
    return vs

def building():
    out = ["# A building with windows and shadows, after Fig. 6 (a)-(d) of paper 000",
           "# (Nishita & Nakamae): windows are patterns lying on the walls (`on F`, drawn over",
           "# the wall whatever the numbering: they are numbered before it here), the sun",
           "# (a parallel light) and a street lamp (a point light) cast the building's",
           "# shadows on the ground, and the low annex's on the tower's foot.",
           "# Made by tools/mkfig6.py.",
           "view -900 1400 -5000",
           "window -560 -140 940 985",
           "light -3 2 -2",
           "light point 900 500 -200",
           "effects shadows=on"]
    ids = [0]
    # ground
    g = rect(out, ids, [(-1400, 0, -400), (1400, 0, -400), (1400, 0, 3000), (-1400, 0, 3000)])
    out.append(f"face 100 {g[0]} {g[3]} {g[2]} {g[1]}")
    wins = []
    fid, tower = box(out, ids, -250, 0, 400, 150, 900, 800, 101)
    fid, annex = box(out, ids, 150, 0, 200, 650, 260, 800, fid)
    # windows on the tower's front (z = 400) and right side (x = 150, above the annex)
    wid = 1
    for row in range(6):
        y = 330 + row * 95
        for col in range(3):
            x = -210 + col * 125
            p = rect(out, ids, [(x, y, 400), (x + 70, y, 400), (x + 70, y + 55, 400), (x, y + 55, 400)])
            out.append(f"face {wid} {p[0]} {p[1]} {p[2]} {p[3]} on {tower['front']} grey 40")
            wid += 1
    for row in range(3):
        y = 620 + row * 95
        for col in range(2):
            z = 470 + col * 170
            p = rect(out, ids, [(150, y, z), (150, y, z + 90), (150, y + 55, z + 90), (150, y + 55, z)])
            out.append(f"face {wid} {p[0]} {p[1]} {p[2]} {p[3]} on {tower['right']} grey 40")
            wid += 1
    # the annex's door and shop windows
    p = rect(out, ids, [(250, 0, 200), (330, 0, 200), (330, 170, 200), (250, 170, 200)])
    out.append(f"face {wid} {p[0]} {p[1]} {p[2]} {p[3]} on {annex['front']} grey 30"); wid += 1
    p = rect(out, ids, [(400, 60, 200), (600, 60, 200), (600, 190, 200), (400, 190, 200)])
    out.append(f"face {wid} {p[0]} {p[1]} {p[2]} {p[3]} on {annex['front']} grey 60"); wid += 1
    return "\n".join(out) + "\n"

def room():
    out = ["# A room with a textured wall, after Fig. 6 (e), (f) of paper 000 (a Japanese",
           "# room: the fusuma's flower pattern and the hanging scroll are textures,",
           "# reflectance from a picture). The back wall's sliding doors carry",
           "# scenes/fig6-fusuma.pgm; a low table stands on the floor, lit by a lamp",
           "# (a point light) and the daylight from the left, with its shadows.",
           "# Made by tools/mkfig6.py.",
           "view 0 420 -1500",
           "window -480 -20 480 700",
           "light 4 3 -2",
           "light point -300 650 1200",
           "effects shadows=on"]
    ids = [0]
    W, Hh, D = 900, 700, 1400
    fl = rect(out, ids, [(-W, 0, 0), (W, 0, 0), (W, 0, D), (-W, 0, D)])
    out.append(f"face 1 {fl[0]} {fl[3]} {fl[2]} {fl[1]}")
    bw = rect(out, ids, [(-W, 0, D), (W, 0, D), (W, Hh, D), (-W, Hh, D)])
    out.append(f"face 2 {bw[0]} {bw[1]} {bw[2]} {bw[3]}")
    lw = rect(out, ids, [(-W, 0, 0), (-W, 0, D), (-W, Hh, D), (-W, Hh, 0)])
    out.append(f"face 3 {lw[0]} {lw[1]} {lw[2]} {lw[3]}")
    rw = rect(out, ids, [(W, 0, D), (W, 0, 0), (W, Hh, 0), (W, Hh, D)])
    out.append(f"face 4 {rw[0]} {rw[1]} {rw[2]} {rw[3]}")
    # the fusuma: a pattern on the back wall, its texture's lower-left at its first vertex
    fu = rect(out, ids, [(-700, 0, D), (300, 0, D), (300, 560, D), (-700, 560, D)])
    out.append(f"face 5 {fu[0]} {fu[1]} {fu[2]} {fu[3]} on 2")
    out.append("texture 5 fig6-fusuma.pgm")
    # the scroll on the alcove wall (right of the fusuma)
    sc = rect(out, ids, [(480, 180, D), (640, 180, D), (640, 600, D), (480, 600, D)])
    out.append(f"face 6 {sc[0]} {sc[1]} {sc[2]} {sc[3]} on 2")
    out.append("texture 6 fig6-scroll.pgm")
    fid, t = box(out, ids, -300, 0, 500, 300, 120, 800, 10)
    return "\n".join(out) + "\n"

def pgm(path, w, h, f):
    with open(path, "w") as o:
        o.write(f"P2\n{w} {h}\n255\n")
        for y in range(h):
            o.write(" ".join(str(f(x, y)) for x in range(w)) + "\n")

def fusuma(x, y):
    # four panels with a flower (a ring of petals) each, on a light ground
    import math
    pw = 64
    px, py = x % pw - pw / 2, y - 48
    if x % pw in (0, 1, pw - 1):
        return 60                                    # the panels' frames
    r = math.hypot(px, py)
    a = math.atan2(py, px)
    petal = 14 + 7 * math.cos(5 * a)
    if r < 5:
        return 90
    if r < petal:
        return 150
    if (x // 8 + y // 8) % 2 == 0 and y > 80:
        return 200
    return 235

def scroll(x, y):
    # a scroll: dark rollers, a pale sheet with a column of strokes
    if y < 4 or y > 91:
        return 40
    if 8 <= x <= 23 and 10 <= y <= 85 and (y // 6) % 2 == 0 and abs(x - 16) < 3 + (y % 5):
        return 30
    return 220

if __name__ == "__main__":
    open("scenes/fig6-building.s74", "w").write(building())
    open("scenes/fig6-room.s74", "w").write(room())
    pgm("scenes/fig6-fusuma.pgm", 256, 96, fusuma)
    pgm("scenes/fig6-scroll.pgm", 32, 96, scroll)
