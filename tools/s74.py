"""s74.py — writing .s74 scene files from Python (shared by tools/mkscenes.py and mkedges.py).

Scene collects the lines of a scene file: numbered vertices (one per position, reused),
faces with holes (`*` between rings) and an optional grey, boxes, and the statements the
caller says. street_blocks draws paper 003's Fig. 10 street (road, six buildings, their
windows), used by scenes/street.s74 and by its enhanced-edges version.
"""


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


def street_blocks(s, each_box=None):
    """The road, buildings and windows of the Fig. 10 street; each_box(faces) is called
    with each building's six faces right after they are written."""
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
        faces = s.box(x0, ground, z0, x1, y1, z1, [gf, gs, gt, gs, gs, 60])
        if each_box:
            each_box(faces)
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
