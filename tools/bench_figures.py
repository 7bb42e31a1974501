#!/usr/bin/env python3
"""Regenerates every benchmark table in docs/ from one run of the Google Benchmark programs.

    cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DARTCAL_UNITY=ON \\
          -DARTCAL_BUILD_BENCHMARKS=ON
    cmake --build build -j 2 --target bench_evaluator bench_panda bench_instrument \\
          bench_calibrator bench_cartesian bench_hexapod bench_acceptance
    python3 tools/bench_figures.py [--build build] [--repetitions 9] [--only bench_evaluator]

Each table sits in its document between the lines `<!-- bench:NAME -->` and `<!-- /bench -->`;
everything between them is rewritten: a line saying how it was measured (the date, the load
average, the repetitions, CPU time: the machine may be shared) and a table of the medians beside
the targets. The benchmarks and their words are listed in BLOCKS below, the only place a
documented figure comes from. A program that is not built leaves its tables as they are (said on
stderr); --only runs one program's benchmarks alone.
"""

import argparse
import datetime
import json
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# block name -> (document, [(program, benchmark name, what it measures, target or "")])
BLOCKS = {
    "evaluate": ("docs/speed.md", [
        ("bench_evaluator", "Seed2R20Bars",
         "the seed's 2R arm, 20 bars, 120 configurations: V_p and the tip summary", "20 us"),
        ("bench_evaluator", "Paper2R5BarsPrepared",
         "plans/paper-2r-5bars.json, workspace prepared once", ""),
        ("bench_evaluator", "Paper2R5BarsEvaluate/1",
         "the same, the whole evaluate with its JSON document", ""),
        ("bench_evaluator", "Aacmm30Bars",
         "6-axis arm, 21 parameters, 30 bars x 2 balls x 3 postures, 10 000 configurations",
         "1 ms"),
        ("bench_panda", "BM_EvaluatePanda10000Samples",
         "7-axis Panda, 25 parameters, 10 000 joint-space samples, prepared once", "5 ms"),
        ("bench_panda", "BM_EvaluatePanda10000TaskSpace",
         "the same over 10 000 task-space samples", "5 ms"),
        ("bench_instrument", "BM_EvaluateTracker300Readings10000TaskSpace",
         "V_p of 6 tracker stations x 50 readings, 10 000 task-space samples", "5 ms"),
        ("bench_cartesian", "Cartesian12Plates2Styli",
         "Cartesian CMM, 12 plates, 2 styli", "2 ms"),
        ("bench_hexapod", "Evaluate30Placements", "hexapod, 30 placements", ""),
        ("bench_plane", "PlaneEvaluate100Touches",
         "6-axis arm, 100 plane touches (3 tables, a gauge block), 10 000 configurations",
         "1.5 x ball bar"),
        ("bench_plane", "BallBarEvaluate100Readings",
         "the same arm, a ball bar plan of 100 readings, 10 000 configurations", ""),
        ("bench_machine_tool", "MachineToolEvaluate100Probings",
         "trunnion five-axis machine, 2 spheres x 50 probings, 10 000 configurations", "5 ms"),
        ("bench_machine_tool", "MachineToolBallBarEvaluate100Readings",
         "the same machine, a table-spindle ball bar, 2 x 50 readings, 10 000 configurations",
         ""),
    ]),
    "calibrate": ("docs/speed.md", [
        ("bench_calibrator", "BM_CalibrateSixAxis100Placements",
         "6-axis arm, 100 placements x 6 readings", "100 ms"),
        ("bench_machine_tool", "MachineToolCalibrate100Probings",
         "trunnion five-axis machine, 2 spheres x 50 probings, from nominal", "10 ms"),
        ("bench_machine_tool", "MachineToolBallBarCalibrate100Readings",
         "the same machine, a table-spindle ball bar, 2 x 50 readings", ""),
        ("bench_calibrator", "BM_Confirm20Bars1000Trials/1/iterations:3/real_time",
         "1000 confirmation trials of plans/paper-2r-20bars.json", "10 s"),
        ("bench_panda", "BM_CalibratePanda8Positions",
         "calibrate panda-8positions (497 readings, 25 parameters)", "50 ms"),
        ("bench_panda", "BM_CalibrateReadingsPanda8Positions",
         "the same, \"identifiable\" and \"probe\": \"estimate\"", ""),
        ("bench_panda", "BM_CalibratePandaRankRule",
         "calibrate's path on the same readings, the rank rule alone", ""),
        ("bench_panda", "BM_CalibratePandaHeldOutChoice",
         "the same with the held-out model choice (the default)", "3 x rank rule"),
        ("bench_instrument", "BM_CalibrateTrackerIdentifiable",
         "40 tracker stations x 50 readings, \"identifiable\" (23 of 25 kept)", "50 ms"),
        ("bench_instrument", "BM_CalibrateTracker40Stations50Readings",
         "the same readings, the 25 parameters forced", "50 ms"),
        ("bench_acceptance", "LengthTestMonteCarlo1e5Trials/1/real_time",
         "ISO 10360-2 prediction, 10^5 Monte-Carlo trials", ""),
    ]),
}


def load_average():
    try:
        with open("/proc/loadavg") as f:
            return f.read().split()[0]
    except OSError:
        return "unknown"


def run_program(path, names, repetitions):
    pattern = "^(" + "|".join(re.escape(n) for n in names) + ")$"
    out = subprocess.run(
        [path, "--benchmark_filter=" + pattern, "--benchmark_repetitions=%d" % repetitions,
         "--benchmark_format=json"], check=True, capture_output=True, text=True).stdout
    if not out.strip():  # no benchmark of that name: its rows say "not run"
        return {}
    runs = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("run_type") != "iteration":
            continue
        runs.setdefault(b["run_name"], []).append((b["cpu_time"], b["time_unit"]))
    return {name: (statistics.median(t for t, _ in v), v[0][1]) for name, v in runs.items()}


def human(value, unit):
    seconds = value * {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[unit]
    for scale, label in ((1.0, "s"), (1e-3, "ms"), (1e-6, "us")):
        if seconds >= scale:
            return "%.3g %s" % (seconds / scale, label)
    return "%.3g ns" % (seconds / 1e-9)


def render(rows, medians, repetitions, today, load):
    lines = ["Measured by `tools/bench_figures.py` on %s (load average %s; CPU time, median of %d "
             "repetitions; Release build with `-DARTCAL_UNITY=ON -DARTCAL_BUILD_BENCHMARKS=ON`):"
             % (today, load, repetitions), "",
             "| benchmark | what | CPU time | target |", "|---|---|---:|---:|"]
    for program, name, what, target in rows:
        figure = medians.get((program, name))
        lines.append("| `%s` (%s) | %s | %s | %s |" % (
            name, program, what, human(*figure) if figure else "not run", target or "-"))
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--repetitions", type=int, default=9)
    parser.add_argument("--only", help="run this program's benchmarks alone")
    args = parser.parse_args()
    wanted = {}
    for _, rows in BLOCKS.values():
        for program, name, _, _ in rows:
            if not args.only or program == args.only:
                wanted.setdefault(program, []).append(name)
    medians = {}
    for program, names in wanted.items():
        path = os.path.join(args.build, "tests", "bench", program)
        if not os.access(path, os.X_OK):
            print("%s not built: its figures are left as they are" % path, file=sys.stderr)
            continue
        print("running %s (%d benchmarks)" % (program, len(names)), file=sys.stderr)
        for name, figure in run_program(path, names, args.repetitions).items():
            medians[(program, name)] = figure
    today = datetime.date.today().isoformat()
    load = load_average()
    documents = {}
    for block, (document, rows) in BLOCKS.items():
        if not any((program, name) in medians for program, name, _, _ in rows):
            continue
        path = os.path.join(ROOT, document)
        text = documents.get(path) or open(path).read()
        begin, end = "<!-- bench:%s -->" % block, "<!-- /bench -->"
        start = text.index(begin) + len(begin)
        stop = text.index(end, start)
        # Rows not run this time keep the figure the document had.
        old = {}
        for line in text[start:stop].splitlines():
            m = re.match(r"\| `([^`]+)` \(([^)]+)\) \| [^|]* \| ([^|]*) \|", line)
            if m and m.group(3).strip() != "not run":
                old[(m.group(2), m.group(1))] = m.group(3).replace("(earlier run)", "").strip()
        table = render(rows, medians, args.repetitions, today, load)
        for (program, name), figure in old.items():
            if (program, name) not in medians:
                table = re.sub(r"(\| `%s` \(%s\) \| [^|]* \| )not run" % (re.escape(name),
                                                                         re.escape(program)),
                               lambda m: m.group(1) + figure + " (earlier run)", table)
        documents[path] = text[:start] + "\n" + table + "\n" + text[stop:]
    for path, text in documents.items():
        with open(path + ".tmp", "w") as f:
            f.write(text)
        os.replace(path + ".tmp", path)
        print("wrote %s" % os.path.relpath(path, ROOT), file=sys.stderr)


if __name__ == "__main__":
    main()
