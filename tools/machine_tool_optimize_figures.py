#!/usr/bin/env python3
"""Optimised against equally spaced probing positions on the example machine tools
(docs/five-axis.md, "Planning the probing"). For each configuration and each number of probings N
(two spheres, N / 2 probings each): the worst-case tip uncertainty G over the plan's workspace of
  - the equally spaced grids: R1 at n1 equally spaced positions (over the example plan's span, or
    over the axis' whole range less the joint margin) times C at n2 positions equally spaced over
    a turn, n1 x n2 = N / 2, the spheres where the example plan has them; the best grid is the
    pattern to beat;
  - the same grids at the spheres the optimiser placed (the rotary positions' own share);
  - `artcal optimize` of plans/machine-tool-<config>-<N>probings.spec.json (written here from the
    example plan when absent: 2 placements of the sphere, N / 2 postures, heights 50..150 mm).
Usage: machine_tool_optimize_figures.py ARTCAL [OUT_DIR]   (default OUT_DIR /tmp/artcal-mt-figures)
Prints a markdown table; the plans and specs it ran are left in OUT_DIR."""
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from machine_tool_plan import readings  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONFIGS = {
    "trunnion": {"plan": "machine-tool-trunnion-2spheres.json", "span": (-90.0, 0.0)},
    "head-table": {"plan": "machine-tool-head-table-2spheres.json", "span": (-60.0, 60.0)},
}
SPHERES = [[150.0, 0.0, 50.0], [-80.0, 120.0, 150.0]]  # the example plans' sphere centres
COUNTS = (8, 12, 16)
MARGIN_MM, MARGIN_DEG = 1.0, 2.0  # the planner's default joint margin


def run(args):
    return subprocess.run(args, check=True, capture_output=True, text=True).stdout


def evenly(lo, hi, n, closed=True):
    if n == 1:
        return [0.5 * (lo + hi)]
    return [lo + (hi - lo) * i / (n - 1 if closed else n) for i in range(n)]


def within(machine, q):
    for i, (lo, hi) in enumerate(machine["joint_limits"]):
        m = MARGIN_MM if i < 3 else MARGIN_DEG
        if i == 4 and hi - lo >= 360:
            m = 0.0
        if q[i] < lo + m - 1e-9 or q[i] > hi - m + 1e-9:
            return False
    return True


def grid_plan(base, spheres, r1, r2):
    plan = {k: v for k, v in base.items() if k not in ("placements", "design", "predicted")}
    plan["placements"] = []
    plan["artifacts"] = {"sphere1": {"type": "sphere", "diameter": 25.0}}
    for w in spheres:
        ms = []
        for a in r1:
            for c in r2:
                # C's representative within its limits (they span more than a turn).
                lo, hi = base["machine"]["joint_limits"][4]
                c = c if c <= hi else c - 360.0
                ms.append({"feature": 0, "joints": readings(base["machine"], w, a, c)})
        plan["placements"].append({"artifact": "sphere1", "measurements": ms})
    return plan


def worst(artcal, path):
    out = json.loads(run([artcal, "evaluate", path, "--json"]))
    if not out["identifiable"]:
        return math.inf
    return out["tip"]["worst"]["total"] * 1000.0


def best_grid(artcal, base, span, spheres, n, out_dir, tag):
    machine = base["machine"]
    lo1, hi1 = machine["joint_limits"][3]
    best = (math.inf, "")
    for n1 in range(2, n + 1):
        if n % n1:
            continue
        n2 = n // n1
        if n2 < 2:
            continue
        for span_name, (a, b) in (("span", span),
                                  ("range", (lo1 + MARGIN_DEG, hi1 - MARGIN_DEG))):
            r1 = [round(x, 6) for x in evenly(a, b, n1)]
            r2 = [round(x, 6) for x in evenly(0.0, 360.0, n2, closed=False)]
            plan = grid_plan(base, spheres, r1, r2)
            if not all(within(machine, m["joints"])
                       for p in plan["placements"] for m in p["measurements"]):
                continue
            path = os.path.join(out_dir, "%s-grid-%d-%dx%d-%s.json" % (tag, 2 * n, n1, n2,
                                                                       span_name))
            json.dump(plan, open(path, "w"), indent=1)
            g = worst(artcal, path)
            label = "%d x %d, R1 %s..%s" % (n1, n2, r1[0], r1[-1])
            if g < best[0]:
                best = (g, label)
    return best


def spec_for(base, count, path):
    spec = {k: v for k, v in base.items() if k not in ("placements", "predicted")}
    spec["name"] = base["name"] + "-%dprobings" % count
    spec["description"] = ("optimization spec: %d probings, 2 placements of the sphere (heights "
                           "50..150 mm, centres within 150 mm of the pivot in X and Y), %d "
                           "rotary positions each; worst-case tip uncertainty" % (count,
                                                                                count // 2))
    spec["artifacts"] = {"sphere1": {"type": "sphere", "diameter": 25.0}}
    spec["design"] = {"artifact": "sphere1", "placements": 2, "postures": count // 2,
                      "region": {"box": [[-150, -150, 50], [150, 150, 150]]},
                      "criterion": "worst-tip", "seed": 1, "starts": 16, "polish": 2,
                      "kicks": 8, "time_limit": 60}
    json.dump(spec, open(path, "w"), indent=1)


def main():
    artcal = sys.argv[1]
    out_dir = sys.argv[2] if len(sys.argv) > 2 else "/tmp/artcal-mt-figures"
    os.makedirs(out_dir, exist_ok=True)
    print("| configuration | probings | equally spaced, best grid (um) | grid | same grid at "
          "the optimised spheres (um) | optimised (um) | optimised / equally spaced |")
    print("|---|---|---|---|---|---|---|")
    for tag, config in CONFIGS.items():
        base = json.load(open(os.path.join(ROOT, "plans", config["plan"])))
        for count in COUNTS:
            spec = os.path.join(ROOT, "plans", "machine-tool-%s-%dprobings.spec.json" % (tag,
                                                                                       count))
            if not os.path.exists(spec):
                spec_for(base, count, spec)
            optimized = os.path.join(out_dir, "%s-%dprobings-optimized.json" % (tag, count))
            run([artcal, "optimize", spec, "-o", optimized, "--quiet", "--threads", "1"])
            g_opt = worst(artcal, optimized)
            centres = [p["pose"]["center"] for p in json.load(open(optimized))["placements"]]
            g_grid, label = best_grid(artcal, base, config["span"], SPHERES, count // 2, out_dir, tag)
            g_there, _ = best_grid(artcal, base, config["span"], centres, count // 2, out_dir, tag + "-opt")
            print("| %s | %d | %.2f | %s | %.2f | %.2f | %.2f |" % (
                tag, count, g_grid, label, g_there, g_opt, g_opt / g_grid))


if __name__ == "__main__":
    main()
