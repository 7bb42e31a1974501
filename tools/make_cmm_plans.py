#!/usr/bin/env python3
"""Writes the Cartesian CMM example plans plans/cmm-*.json (README, "Cartesian CMMs").

A moving-bridge CMM (bridge y 0..700, carriage x 0..1000, ram z -600..0 mm), error functions of
degree 3 (54 coefficients), probing 0.5 um, scales 0.2 um. A 5 x 5 ball plate (pitch 100 mm,
certificate 0.5 um per coordinate) is laid three times in each of the planes XY, XZ and YZ; a
1000 mm step gauge (faces every 50 mm) along the four space diagonals. Nominal readings are exact:
at nominal the readings are the probe target minus the stylus, resolved along the axes
(docs/models.md section 4). Run from the repository: python3 tools/make_cmm_plans.py
"""
import json
import math
import os

AXES = [{"name": "y", "direction": [0, 1, 0], "range": [0, 700]},
        {"name": "x", "direction": [1, 0, 0], "range": [0, 1000]},
        {"name": "z", "direction": [0, 0, 1], "range": [-600, 0]}]
ONE_STYLUS = [[0, 0, -100]]
TWO_STYLI = [[0, 0, -100], [50, 50, -150]]

PLATE = [[100.0 * i, 100.0 * j, 0.0] for j in range(5) for i in range(5)]
GAUGE = [50.0 * k for k in range(21)]

# (origin of ball 0, plate x direction, roll deg): roll 0 lies in XY, roll 90 about x in XZ,
# roll 90 about y in YZ (the plate's y axis then points up).
PLATE_POSES = {
    "xy": [([60, 60, -690], [1, 0, 0], 0), ([590, 290, -430], [1, 0, 0], 0),
           ([320, 160, -170], [1, 0, 0], 0)],
    "xz": [([60, 60, -690], [1, 0, 0], 90), ([590, 350, -560], [1, 0, 0], 90),
           ([320, 690, -690], [1, 0, 0], 90)],
    "yz": [([60, 60, -690], [0, 1, 0], 90), ([500, 290, -560], [0, 1, 0], 90),
           ([990, 60, -690], [0, 1, 0], 90)],
}
# Space diagonals of the volume the two styli share, each from a low corner upwards.
DIAGONALS = [([100, 80, -690], [900, 680, -160]), ([900, 80, -690], [100, 680, -160]),
             ([100, 680, -690], [900, 80, -160]), ([900, 680, -690], [100, 80, -160])]


def rotate(axis, angle_deg, v):
    """Rodrigues: v turned by angle about the unit axis."""
    a = math.radians(angle_deg)
    c, s = math.cos(a), math.sin(a)
    dot = sum(x * y for x, y in zip(axis, v))
    cross = [axis[1] * v[2] - axis[2] * v[1], axis[2] * v[0] - axis[0] * v[2],
             axis[0] * v[1] - axis[1] * v[0]]
    return [v[i] * c + cross[i] * s + axis[i] * dot * (1 - c) for i in range(3)]


def frame(direction, roll):
    """The plate or gauge frame as placeSpatial builds it (rigid_transform.cpp)."""
    n = math.sqrt(sum(x * x for x in direction))
    ex = [x / n for x in direction]
    ey = [-ex[1], ex[0], 0.0]  # z x ex
    m = math.sqrt(sum(x * x for x in ey))
    ey = [0.0, 1.0, 0.0] if m < 1e-9 else [x / m for x in ey]
    ey = rotate(ex, roll, ey)
    ez = [ex[1] * ey[2] - ex[2] * ey[1], ex[2] * ey[0] - ex[0] * ey[2],
          ex[0] * ey[1] - ex[1] * ey[0]]
    return ex, ey, ez


def to_machine(center, axes, w):
    return [center[i] + sum(axes[k][i] * w[k] for k in range(3)) for i in range(3)]


def readings(x, stylus):
    """Nominal readings (y, x, z order of AXES) that put `stylus` on x; checked within range."""
    u = [x[1] - stylus[1], x[0] - stylus[0], x[2] - stylus[2]]
    for k, axis in enumerate(AXES):
        lo, hi = axis["range"]
        assert lo <= u[k] <= hi, (x, stylus, axis["name"], u[k])
    return [round(v, 9) for v in u]


def plate_placement(center, direction, roll, styli):
    axes = frame(direction, roll)
    measurements = []
    for i, w in enumerate(PLATE):
        x = to_machine(center, axes, w)
        for s, stylus in enumerate(styli):
            m = {"feature": i, "joints": readings(x, stylus)}
            if s:
                m["stylus"] = s
            measurements.append(m)
    return {"artifact": "plate",
            "pose": {"center": center, "direction": direction, "roll": roll},
            "measurements": measurements}


def gauge_placement(start, end):
    d = [e - s for s, e in zip(start, end)]
    n = math.sqrt(sum(x * x for x in d))
    direction = [round(x / n, 12) for x in d]
    axes = frame(direction, 0.0)
    measurements = [{"feature": i, "joints": readings(to_machine(start, axes, [g, 0, 0]),
                                                      ONE_STYLUS[0])}
                    for i, g in enumerate(GAUGE)]
    return {"artifact": "gauge", "pose": {"center": start, "direction": direction, "roll": 0.0},
            "measurements": measurements}


def plan(name, description, planes, styli, diagonals):
    placements = [plate_placement(c, d, r, styli) for p in planes for (c, d, r) in PLATE_POSES[p]]
    artifacts = {"plate": {"type": "ball_plate", "centers": PLATE, "u": 0.0005}}
    if diagonals:
        artifacts["gauge"] = {"type": "step_gauge", "positions": GAUGE, "u": 0.0005}
        placements += [gauge_placement(s, e) for (s, e) in DIAGONALS]
    return {"format": "artcal-plan/1", "name": name, "description": description,
            "machine": {"model": "cartesian", "axes": AXES, "degree": 3, "styli": styli,
                        "calibrate": "identifiable"},
            "noise": {"probe": 0.0005, "encoder": 0.0002},
            "artifacts": artifacts, "placements": placements,
            "workspace": {"samples": 10000, "seed": 1}}


COMMON = ("moving-bridge CMM 1000 x 700 x 600 mm (y bridge, x carriage, z ram), Legendre degree 3, "
          "probing 0.5 um, scales 0.2 um; 5 x 5 ball plate, pitch 100 mm, u 0.5 um")
PLANS = [
    ("cmm-plate-xy", "the plate in the XY plane only (3 heights), one stylus", ["xy"],
     ONE_STYLUS, False),
    ("cmm-plate-3planes", "the plate 3 times in each of XY, XZ, YZ, one stylus",
     ["xy", "xz", "yz"], ONE_STYLUS, False),
    ("cmm-plate-3planes-2styli", "the plate 3 times in each of XY, XZ, YZ, every ball read "
     "with 2 styli", ["xy", "xz", "yz"], TWO_STYLI, False),
    ("cmm-plate-3planes-2styli-diagonals", "the plate 3 times in each of XY, XZ, YZ with 2 "
     "styli, plus a 1000 mm step gauge (u 0.5 um) along the 4 space diagonals",
     ["xy", "xz", "yz"], TWO_STYLI, True),
]

if __name__ == "__main__":
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plans")
    for name, what, planes, styli, diagonals in PLANS:
        doc = plan(name, COMMON + "; " + what + " (tools/make_cmm_plans.py)", planes, styli,
                   diagonals)
        with open(os.path.join(root, name + ".json"), "w") as out:
            json.dump(doc, out, indent=1)
            out.write("\n")
