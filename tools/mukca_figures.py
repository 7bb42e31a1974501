#!/usr/bin/env python3
"""Held-out figures of a plain calibration of the MUKCa robots, as a new user measures them.

For every fold: `artcal import-readings` of the training positions (the URDF as it is,
"identifiable", probe noise 0.1 mm, no prior), `artcal calibrate --write-machine`, and
`artcal verify --machine` of each held-out position on its own (the nominal machine's figures
come from the same run). Figures in mm, MUKCa's definitions (tests/data/mukca/mukca/README.md):
MAE = spread_mean, RMS = spread_rms, distance = length_error_mean_abs; each fold's figure is the
mean over its held-out positions, the last line the mean over the folds.

usage: tools/mukca_figures.py ARTCAL ROBOT {one,loo,POSITION} [--json]
         [--data DIR --urdf URDF --base LINK [--tip LINK] [--ball-bar MM] [--leave-out P ...]]
  The last columns: held-out spread RMS observed / predicted (verify's total, with the unmodelled
  error the calibration estimated by cross-validation; and without it), pooled over the held-out
  positions as sqrt(sum observed^2 / sum predicted^2).
  one: trained on each position alone, the others held out; loo: each position held out,
  trained on the others; POSITION: trained on that position alone. ROBOT is a folder of DIR
  (default: the copied MUKCa data, where panda_2 and dinova_1 need no more options; the Panda's
  `high` position, whose socket moved, see the README, is left out as the authors do). With
  --data, --urdf and --base, any folder of positions in MUKCa's layout is measured the same way.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data", "mukca",
                    "mukca")
ROBOTS = {"panda_2": ("panda.urdf", "panda_link0", ["high"]),
          "dinova_1": ("gen3lite.urdf", "kinova_base_link", [])}
FIGURES = ("spread_mean", "spread_rms", "length_error_mean_abs")


def refuse(message, status=2):
    """One line on stderr, as artcal's own errors: exit status 2 for bad input."""
    print(f"error: {message}", file=sys.stderr)
    sys.exit(status)


def run(artcal, *args):
    done = subprocess.run([artcal, *args], capture_output=True, text=True)
    if done.returncode not in (0, 1):
        refuse(f"artcal {' '.join(args)} failed ({done.returncode}): {done.stderr.strip()}",
               done.returncode)
    return done


class Plans:
    """Imported plans of sets of positions, made once each in a temporary folder."""

    def __init__(self, artcal, setup, folder):
        self.artcal, self.setup, self.folder, self.made = artcal, setup, folder, {}

    def of(self, positions):
        key = tuple(sorted(positions))
        if key not in self.made:
            name = f"plan{len(self.made)}"
            readings = os.path.join(self.folder, name)
            os.makedirs(readings)
            for position in key:
                os.symlink(os.path.join(self.setup.positions, position),
                           os.path.join(readings, position))
            out = os.path.join(self.folder, name + ".json")
            run(self.artcal, "import-readings", readings, "--urdf", self.setup.urdf, "--base",
                self.setup.base, "--tip", self.setup.tip, "--ball-bar", str(self.setup.ball_bar),
                "-o", out)
            self.made[key] = out
        return self.made[key]


def folds(setup, mode):
    robot = os.path.basename(setup.positions)
    positions = sorted(p for p in os.listdir(setup.positions)
                       if os.path.isdir(os.path.join(setup.positions, p))
                       and p not in setup.leave_out)
    if mode == "loo":
        return [([p for p in positions if p != held], [held]) for held in positions]
    if mode == "one":
        return [([t], [p for p in positions if p != t]) for t in positions]
    if mode not in positions:
        refuse(f"{mode}: not a position of {robot} ({', '.join(positions)}); use one, loo or one "
               "of them")
    return [([mode], [p for p in positions if p != mode])]


def measure(artcal, setup, mode, folder):
    plans = Plans(artcal, setup, folder)
    out = []
    for k, (training, held_out) in enumerate(folds(setup, mode)):
        machine = os.path.join(folder, f"machine{k}.json")
        calibration = json.loads(run(artcal, "calibrate", plans.of(training), "--json",
                                     "--write-machine", machine).stdout)
        fold = {"training": training, "held_out": held_out,
                "termination": calibration["termination"],
                "iterations": calibration["iterations"],
                "kept": len(calibration["parameters"]),
                "calibrated": dict.fromkeys(FIGURES, 0.0), "nominal": dict.fromkeys(FIGURES, 0.0),
                "spread_rms_squares": {"observed": 0.0, "predicted": 0.0, "without_unmodelled": 0.0}}
        for position in held_out:
            verify = json.loads(run(artcal, "verify", plans.of([position]), "--json",
                                    "--machine", machine).stdout)["verify"]
            for figure in FIGURES:
                fold["calibrated"][figure] += verify[figure] / len(held_out)
                fold["nominal"][figure] += verify["nominal"][figure] / len(held_out)
            squares = fold["spread_rms_squares"]
            squares["observed"] += verify["spread_rms"] ** 2
            squares["predicted"] += predicted_spread_rms(verify) ** 2
            squares["without_unmodelled"] += predicted_spread_rms(verify, False) ** 2
        out.append(fold)
    return out


def predicted_spread_rms(verify, with_unmodelled=True):
    """verify's prediction of the held-out spread RMS: with the unmodelled error the calibration
    estimated (its total), or without it the posterior one (readings that scatter as the
    training's), else the stated noise's."""
    names = ("predicted_spread_rms_posterior", "predicted_spread_rms")
    for name in (("predicted_spread_rms_total",) if with_unmodelled else ()) + names:
        if verify.get(name):
            return verify[name]
    return 0.0


def observed_over_predicted(folds, prediction="predicted"):
    """sqrt(sum observed spread_rms^2 / sum predicted^2) over the held-out positions."""
    observed = sum(f["spread_rms_squares"]["observed"] for f in folds)
    predicted = sum(f["spread_rms_squares"][prediction] for f in folds)
    return (observed / predicted) ** 0.5 if predicted > 0 else 0.0


def triple(figures):
    return "/".join(f"{figures[f]:.3f}" for f in FIGURES)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("artcal", help="the artcal executable (build/tools/artcal)")
    parser.add_argument("robot", help="the robot's folder of positions in DIR")
    parser.add_argument("mode", help="one, loo or a position's name")
    parser.add_argument("--json", action="store_true", help="one JSON document instead of a table")
    parser.add_argument("--data", help="DIR: the folder of robots (default: the copied MUKCa data)")
    parser.add_argument("--urdf", help="the robot's URDF (default for panda_2, dinova_1)")
    parser.add_argument("--base", help="the URDF's base link (default for panda_2, dinova_1)")
    parser.add_argument("--tip", default="ball_link", help="the ball's link (ball_link)")
    parser.add_argument("--ball-bar", type=float, default=50.0, help="socket distance, mm (50)")
    parser.add_argument("--leave-out", nargs="*", default=None,
                        help="positions never used (panda_2: high)")
    args = parser.parse_args()
    data = os.path.abspath(args.data) if args.data else DATA
    known = ROBOTS.get(args.robot) if not args.data else None
    if not known and not (args.urdf and args.base):
        refuse(f"{args.robot}: give --urdf and --base (defaults exist for "
               f"{', '.join(sorted(ROBOTS))} of the copied data)")
    setup = argparse.Namespace(
        positions=os.path.join(data, args.robot),
        urdf=os.path.abspath(args.urdf) if args.urdf else os.path.join(DATA, "urdf", known[0]),
        base=args.base or known[1], tip=args.tip, ball_bar=args.ball_bar,
        leave_out=args.leave_out if args.leave_out is not None else (known[2] if known else []))
    if not os.path.isdir(setup.positions):
        refuse(f"{setup.positions}: no such folder of positions")
    with tempfile.TemporaryDirectory() as folder:
        result = measure(os.path.abspath(args.artcal), setup, args.mode, folder)
    mean = {side: {f: sum(r[side][f] for r in result) / len(result) for f in FIGURES}
            for side in ("calibrated", "nominal")}
    if args.json:
        json.dump({"robot": args.robot, "mode": args.mode, "folds": result, "mean": mean,
                   "observed_over_predicted_spread_rms": observed_over_predicted(result),
                   "observed_over_predicted_without_unmodelled":
                       observed_over_predicted(result, "without_unmodelled")},
                  sys.stdout, indent=1)
        print()
        return
    print(f"{args.robot}, {args.mode}: held-out MAE / RMS / distance error, mm")
    print(f"{'trained on':40s} {'termination':12s} {'its':>4s} {'kept':>4s}  "
          f"{'nominal':>19s}  {'calibrated':>19s}  {'obs/pred':>8s} {'w/o s_u':>8s}")
    for r in result:
        label = r["training"][0] if len(r["training"]) == 1 else "all but " + "+".join(
            r["held_out"])
        print(f"{label[:40]:40s} {r['termination']:12s} {r['iterations']:4d} "
              f"{r['kept']:4d}  {triple(r['nominal']):>19s}  {triple(r['calibrated']):>19s}  "
              f"{observed_over_predicted([r]):8.2f} "
              f"{observed_over_predicted([r], 'without_unmodelled'):8.2f}")
    print(f"{'mean':40s} {'':12s} {'':4s} {'':4s}  {triple(mean['nominal']):>19s}  "
          f"{triple(mean['calibrated']):>19s}  {observed_over_predicted(result):8.2f} "
          f"{observed_over_predicted(result, 'without_unmodelled'):8.2f}")


if __name__ == "__main__":
    main()
