#!/usr/bin/env python3
"""Writes plans/hexapod-10bars.json (a hand-made plan) and plans/hexapod-10bars.spec.json (its
optimization spec) for the Stewart-Gough hexapod of docs/models.md section 3. The readings are the
closed-form inverse kinematics q_i = |t + R a_i - b_i| (offsets 0), t = x* - R probe."""
import json
import math
import os

BASE_R, PLATFORM_R = 400.0, 150.0
BASE_ANGLES = [10, 110, 130, -130, -110, -10]
PLATFORM_ANGLES = [50, 70, 170, -170, -70, -50]
PROBE = [0.0, 0.0, -100.0]
HOME_Z = 600.0
LIMITS = [450.0, 800.0]
BAR = 200.0
TILT = 15.0  # deg, the hand-made postures' platform tilt


def point(radius, deg):
    a = math.radians(deg)
    return [round(radius * math.cos(a), 6), round(radius * math.sin(a), 6), 0.0]


BASE = [point(BASE_R, a) for a in BASE_ANGLES]
PLATFORM = [point(PLATFORM_R, a) for a in PLATFORM_ANGLES]


def axis_angle(axis, deg):
    x, y, z = axis
    n = math.sqrt(x * x + y * y + z * z)
    x, y, z = x / n, y / n, z / n
    a = math.radians(deg)
    c, s, C = math.cos(a), math.sin(a), 1 - math.cos(a)
    return [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
            [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
            [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]


def mul(R, v):
    return [sum(R[i][k] * v[k] for k in range(3)) for i in range(3)]


def legs(target, R):
    t = [target[i] - mul(R, PROBE)[i] for i in range(3)]
    out = []
    for a, b in zip(PLATFORM, BASE):
        Ra = mul(R, a)
        out.append(math.sqrt(sum((t[i] + Ra[i] - b[i]) ** 2 for i in range(3))))
    return out


# Three postures per ball: the platform tilted by TILT about horizontal axes 120 deg apart.
POSTURES = [axis_angle([math.cos(math.radians(d)), math.sin(math.radians(d)), 0.0], TILT)
            for d in (0, 120, 240)]


def bar(center, direction):
    n = math.sqrt(sum(d * d for d in direction))
    d = [x / n for x in direction]
    start = [center[i] - 0.5 * BAR * d[i] for i in range(3)]
    end = [start[i] + BAR * d[i] for i in range(3)]
    measurements = []
    for feature, target in ((0, start), (1, end)):
        for R in POSTURES:
            q = legs(target, R)
            assert all(LIMITS[0] + 1 < v < LIMITS[1] - 1 for v in q), (target, q)
            measurements.append({"feature": feature, "joints": [round(v, 9) for v in q]})
    return {"artifact": "bar200",
            "pose": {"center": [round(v, 6) for v in start],
                     "direction": [round(v, 9) for v in d]},
            "measurements": measurements}


def hand_made_placements():
    out = []
    # Four level bars low in the volume, each centred off the axis towards its own quadrant,
    # four more high in it turned by 45 deg, two crossing 45 deg diagonals through the middle.
    for k in range(4):
        a = math.radians(90 * k)
        c = [40 * math.cos(a + math.pi / 4), 40 * math.sin(a + math.pi / 4), 410]
        out.append(bar(c, [math.cos(a), math.sin(a), 0]))
    for k in range(4):
        a = math.radians(90 * k + 45)
        c = [40 * math.cos(a + math.pi / 4), 40 * math.sin(a + math.pi / 4), 500]
        out.append(bar(c, [math.cos(a), math.sin(a), 0]))
    out.append(bar([0, 0, 455], [1, 0, 1]))
    out.append(bar([0, 0, 455], [0, 1, -1]))
    return out


# The 33 parameters "calibrate": "identifiable" keeps (docs/models.md section 3; the reference case
# tests/data/ref-hexapod-6bars-identifiable): the base frame fixed by b4.z, b5.y, b5.z, b6.*,
# the platform frame by a5.z, a6.y, a6.z and the probe.
DROPPED = {"b4.z", "b5.y", "b5.z", "a5.z", "b6.x", "b6.y", "b6.z", "a6.y", "a6.z", "probe.x",
           "probe.y", "probe.z"}
CALIBRATED = [f"{k}{leg}.{c}" for leg in range(1, 7) for k, cs in (("b", "xyz"), ("a", "xyz"),
                                                                    ("l", ["offset"]))
              for c in cs if f"{k}{leg}.{c}" not in DROPPED]


def machine():
    return {"model": "hexapod", "base": BASE, "platform": PLATFORM, "probe": PROBE,
            "home": {"xyz": [0.0, 0.0, HOME_Z], "rpy": [0.0, 0.0, 0.0]},
            "joint_limits": [LIMITS] * 6, "calibrate": CALIBRATED}


WORKSPACE = {"region": {"box": [[-150, -150, 400], [150, 150, 540]]}, "samples": 4096, "seed": 1,
             "tilt": 10}
NOISE = {"probe": 0.002, "encoder": 0.001}
DESCRIPTION = ("Stewart-Gough hexapod: base joints on r 400 mm in pairs at 10 deg either side of "
               "0/120/240 deg, platform joints on r 150 mm turned by 60 deg, probe 100 mm below the "
               "platform, home 600 mm up, legs 450..800 mm; leg encoders 1 um, probing 2 um. ")


def main():
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plans")
    plan = {"format": "artcal-plan/1", "name": "hexapod-10bars",
            "description": DESCRIPTION + "Hand-made: a 200 mm ball bar in 10 placements , each ball read with the "
            "platform tilted 10 deg about three horizontal axes 120 deg apart.",
            "machine": machine(), "noise": NOISE, "artifacts": {"bar200": {"type": "ball_bar",
                                                                         "length": BAR}},
            "placements": hand_made_placements(), "workspace": WORKSPACE}
    spec = {"format": "artcal-plan/1", "name": "hexapod-10bars-optimized",
            "description": DESCRIPTION + "Optimization spec: 10 placements of the 200 mm ball bar, "
            "3 platform tilts (within 15 deg of home) per ball, worst-case tip uncertainty over "
            "the task-space workspace.",
            "machine": machine(), "noise": NOISE,
            "artifacts": {"bar200": {"type": "ball_bar", "length": BAR}},
            "workspace": WORKSPACE,
            "design": {"artifact": "bar200", "placements": 10, "postures": 3,
                       "region": {"box": [[-160, -160, 390], [160, 160, 550]]},
                       "criterion": "worst-tip", "seed": 1, "starts": 32, "pool": 1200,
                       "evaluations": 12000, "polish": 4, "kicks": 16, "time_limit": 60,
                       "joint_margin": 10}}
    for name, doc in (("hexapod-10bars.json", plan), ("hexapod-10bars.spec.json", spec)):
        with open(os.path.join(root, name), "w") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
