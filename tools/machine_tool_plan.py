#!/usr/bin/env python3
"""Writes a machine-tool plan whose readings are the nominal ones (docs/five-axis.md): every
sphere probed at every pair of rotary positions. The nominal inverse kinematics in closed form:
trunnion-AC  t = Rx(a) Rz(c) w,  (X, Y, Z) = t + (0, 0, L);
head-B-table-C  t = Rz(c) w,  (X, Y, Z) = t - (0, 0, P) - Ry(b) (0, 0, -(P + L)).
Usage: machine_tool_plan.py CONFIG.json > PLAN.json, CONFIG = {"name", "machine", "noise",
"spheres": [[x, y, z], ...], "r1": [deg, ...], "r2": [deg, ...], "workspace"}."""
import json
import math
import re
import sys


def rx(a, v):
    c, s = math.cos(a), math.sin(a)
    return [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]]


def ry(a, v):
    c, s = math.cos(a), math.sin(a)
    return [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]


def rz(a, v):
    c, s = math.cos(a), math.sin(a)
    return [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]


def readings(machine, w, r1, r2):
    a, c = math.radians(r1), math.radians(r2)
    L = machine["tool_length"]
    if machine["configuration"] == "trunnion-AC":
        t = rx(a, rz(c, w))
        xyz = [t[0], t[1], t[2] + L]
    else:
        P = machine["pivot_length"]
        t = rz(c, w)
        arm = ry(a, [0.0, 0.0, -(P + L)])
        xyz = [t[0] - arm[0], t[1] - arm[1], t[2] - P - arm[2]]
    return [round(v, 9) for v in xyz] + [r1, r2]


def main():
    config = json.load(open(sys.argv[1]))
    machine = config["machine"]
    plan = {"format": "artcal-plan/1", "name": config["name"],
            "description": config.get("description", ""), "machine": machine,
            "noise": config["noise"], "artifacts": {}, "placements": []}
    for i, w in enumerate(config["spheres"]):
        sid = "sphere%d" % (i + 1)
        plan["artifacts"][sid] = {"type": "sphere", "diameter": 25.0}
        ms = [{"feature": 0, "joints": readings(machine, w, r1, r2)}
              for r1 in config["r1"] for r2 in config["r2"]]
        plan["placements"].append({"artifact": sid, "measurements": ms})
    plan["workspace"] = config.get("workspace", {"samples": 4096, "seed": 1})
    text = json.dumps(plan, indent=1)
    # Arrays of numbers on one line.
    text = re.sub(r"\[\s*([-0-9.eE,\s]+?)\s*\]",
                  lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]", text)
    sys.stdout.write(text + "\n")


if __name__ == "__main__":
    main()
