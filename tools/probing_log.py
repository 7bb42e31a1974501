#!/usr/bin/env python3
"""Writes a machine-tool plan's readings (e.g. `artcal simulate`'s) as one probing log, the way a
controller's probing cycle exports them: a sphere column naming each row's sphere (the
placement's name, else sphere<k>), then the axis readings X_mm, Y_mm, Z_mm and the two rotary
axes in deg (docs/five-axis.md section 3; `artcal import-readings LOG.csv` reads it back, one
placement per sphere). Usage: probing_log.py PLAN.json > LOG.csv"""
import json
import sys


def main():
    plan = json.load(open(sys.argv[1]))
    rotary = "BC" if plan["machine"].get("configuration") == "head-B-table-C" else "AC"
    print("sphere,X_mm,Y_mm,Z_mm,%s_deg,%s_deg" % (rotary[0], rotary[1]))
    for k, placement in enumerate(plan["placements"]):
        name = placement.get("name", "sphere%d" % (k + 1))
        for m in placement["measurements"]:
            x, y, z, r1, r2 = m["joints"]
            print("%s,%.6f,%.6f,%.6f,%.7f,%.7f" % (name, x, y, z, r1, r2))


if __name__ == "__main__":
    main()
