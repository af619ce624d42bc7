#!/usr/bin/env python3
"""mkbackground.py — draw scenes/harbour.pgm, the demo background picture.

This file contains code to make, from nothing but arithmetic, the grey picture that
tube74's demo scenes put behind everything (`background scenes/harbour.pgm`; CONTRACT.md).
In 1974 such a picture came off the drum scanner as 8-bit samples (paper 003; see
docs/hardware.md); here it is drawn procedurally so the project ships no
borrowed material: a sky brightening toward the horizon with soft clouds, two ranges of
hills, a calm sea with ripples and a reflection of the sun, a breakwater with a
lighthouse, and a few moored boats. The output is deterministic (a fixed hash, no
random module), 200 x 150, 8-bit binary PGM (P5, maxval 255).

Usage: python3 tools/mkbackground.py [OUT]      (default scenes/harbour.pgm)
Python 3 standard library only.
"""
import math
import sys

W, H = 200, 150          # picture size (stretched over the window when sampled)
HORIZON = 92             # first row of sea (rows counted from the top)


def hash01(ix, iy, seed):
    """A repeatable pseudo-random value in [0, 1) for integer lattice point (ix, iy)."""
    h = (ix * 374761393 + iy * 668265263 + seed * 2246822519) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    return ((h ^ (h >> 16)) & 0xFFFFFF) / float(1 << 24)


def value_noise(x, y, seed):
    """Smooth noise: hashed lattice values blended with a smoothstep."""
    ix, iy = math.floor(x), math.floor(y)
    fx, fy = x - ix, y - iy
    sx, sy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)
    a, b = hash01(ix, iy, seed), hash01(ix + 1, iy, seed)
    c, d = hash01(ix, iy + 1, seed), hash01(ix + 1, iy + 1, seed)
    return (a + (b - a) * sx) + ((c + (d - c) * sx) - (a + (b - a) * sx)) * sy


def fbm(x, y, seed, octaves=4):
    """Fractal noise in about [0, 1]: octaves of value noise, each half the last."""
    total, amp, norm = 0.0, 1.0, 0.0
    for k in range(octaves):
        total += amp * value_noise(x, y, seed + k)
        norm += amp
        x, y, amp = x * 2, y * 2, amp / 2
    return total / norm


def far_hills(x):
    """Top row of the far range at column x (smaller = higher)."""
    return HORIZON - 14 - 8 * math.sin(x * 0.045 + 0.6) - 4 * math.sin(x * 0.13 + 2.0)


def near_hill(x):
    """Top row of the near headland on the left, or None where it has ended."""
    if x > 95:
        return None
    return HORIZON + 1 - 30 * math.cos(x / 95 * math.pi / 2) ** 1.5 + 2 * math.sin(x * 0.3)


def sky(x, y):
    g = 120 + 110 * (y / HORIZON) ** 1.3                  # darker overhead, bright horizon
    sun_x, sun_y = 150, 40
    d = math.hypot(x - sun_x, y - sun_y)
    g += 60 * math.exp(-(d / 18) ** 2)                    # glow around the sun
    if d < 6:
        g = 255                                           # the sun's disc
    c = fbm(x / 28, y / 10, 11) - 0.52                    # clouds: stretched sideways
    if c > 0:
        band = math.exp(-((y - 30) / 18) ** 2)            # mostly in one band of sky
        g += 260 * c * band
    return g


def sea(x, y):
    depth = (y - HORIZON) / (H - HORIZON)
    g = 140 - 70 * depth                                  # darker toward the viewer
    ripple = math.sin(y * 1.7 + 3 * math.sin(x * 0.07 + y * 0.4))
    g += 10 * ripple * (0.4 + depth)
    if abs(x - 150) < 6 + 20 * depth and ripple > 0.2:    # sun's reflection: broken glitter
        g += 90 * (1 - depth * 0.5)
    return g


def draw():
    img = [[0.0] * W for _ in range(H)]
    for y in range(H):
        for x in range(W):
            img[y][x] = sky(x, y) if y < HORIZON else sea(x, y)
    for x in range(W):                                    # far hills: misty mid grey
        for y in range(int(far_hills(x)), HORIZON):
            img[y][x] = 150 - 25 * fbm(x / 9, y / 9, 31) + (y - far_hills(x)) * 0.4
    for x in range(W):                                    # near headland: dark, wooded
        top = near_hill(x)
        if top is None:
            continue
        for y in range(int(top), HORIZON + 3):
            img[y][x] = 55 + 30 * fbm(x / 5, y / 5, 47)
    for y in range(HORIZON + 3, HORIZON + 12):            # headland's reflection
        for x in range(0, 90):
            if near_hill(x) is not None and y - HORIZON < (HORIZON - near_hill(x)) * 0.35:
                img[y][x] = 0.6 * img[y][x] + 0.4 * 60
    for y in range(104, 109):                             # breakwater from the right edge
        for x in range(118, W):
            img[y][x] = 45 + (12 if y == 104 else 0)
    for y in range(72, 104):                              # lighthouse: white tower ...
        half = 3 + (y - 72) // 12
        for x in range(128 - half, 128 + half + 1):
            stripe = 200 if (y // 6) % 2 == 0 else 235
            img[y][x] = stripe - (25 if x > 128 else 0)   # shaded on the side away from the sun
    for y in range(64, 72):                               # ... lantern room and roof
        for x in range(124, 133):
            img[y][x] = 250 if y >= 67 else 40
    boats = [(40, 118, 22), (78, 112, 14), (100, 128, 28), (165, 122, 18)]
    for bx, by, length in boats:                          # hull, mast, reflection
        for y in range(by, by + 4):
            inset = y - by
            for x in range(bx + inset, bx + length - inset):
                img[y][x] = 35
        for y in range(by - length, by):
            img[y][bx + length // 2] = 40
        for y in range(by + 4, min(H, by + 9)):
            for x in range(bx + 2, bx + length - 2):
                if (y + x // 3) % 2 == 0:
                    img[y][x] = 0.5 * img[y][x] + 0.5 * 60
    return img


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/harbour.pgm"
    img = draw()
    data = bytes(max(0, min(255, int(round(v)))) for row in img for v in row)
    with open(out, "wb") as f:
        f.write(b"P5\n# harbour: drawn by tools/mkbackground.py\n%d %d\n255\n" % (W, H))
        f.write(data)


if __name__ == "__main__":
    main()
