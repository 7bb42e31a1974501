"""tools/mukca_figures.py, the held-out figures of the MUKCa robots as a new user measures them:
its nominal columns equal those of the data's README (an independent implementation), and the
plain calibration's held-out figures are those docs/calibrate-your-robot.md states."""

import json
import subprocess
import sys

from conftest import ROOT, cli_path


def figures(robot, mode):
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "mukca_figures.py"), cli_path(),
                           robot, mode, "--json"], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def triple(figures_of_a_side):
    return [figures_of_a_side[f] for f in ("spread_mean", "spread_rms", "length_error_mean_abs")]


def test_gen3_lite_leave_one_out_beats_nominal_and_the_independent_calibration():
    result = figures("dinova_1", "loo")
    assert len(result["folds"]) == 4
    assert all(fold["termination"] == "converged" for fold in result["folds"])
    # The README's nominal column: 6.21 / 6.66 / 1.08 mm.
    for value, readme in zip(triple(result["mean"]["nominal"]), (6.21, 6.66, 1.08)):
        assert abs(value - readme) < 0.005
    mae, rms, distance = triple(result["mean"]["calibrated"])
    assert mae < 3.50 and rms < 3.86  # the independent calibration's 3.50 / 3.86 mm
    assert distance < 1.01 * 0.90     # its 0.90 mm within 1 % (0.906 measured)
    for fold in result["folds"]:
        assert fold["calibrated"]["spread_mean"] < fold["nominal"]["spread_mean"]


def test_gen3_lite_trained_on_front_alone():
    result = figures("dinova_1", "front")
    (fold,) = result["folds"]
    assert fold["termination"] == "converged"
    assert fold["held_out"] == ["left", "lower_left", "raised_back"]
    for value, readme in zip(triple(fold["nominal"]), (6.57, 6.92, 1.29)):
        assert abs(value - readme) < 0.005
    mae, rms, _ = triple(fold["calibrated"])
    assert mae < 8.07 and rms < 8.75  # the independent calibration's, worse than nominal's


def test_an_unknown_position_is_refused_naming_the_positions():
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "mukca_figures.py"), cli_path(),
                           "dinova_1", "nowhere"], capture_output=True, text=True, check=False)
    assert done.returncode == 2
    assert "error: nowhere: not a position of dinova_1 (front, left, lower_left, raised_back)" in done.stderr
