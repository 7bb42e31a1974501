"""Plane plans from Python (docs/planes.md): the results equal the command line's --json
documents, and a calibration of simulated touches recovers the truth the readings came from."""

import json

import numpy as np
import pytest

import artcal
from conftest import cli_json, run_cli

ARM6 = "plans/planes/arm6-planes.json"
HUMANOID = "plans/planes/humanoid-table.json"


def test_plane_calibration_equals_cli_and_recovers_the_truth(tmp_path):
    # A truth off nominal by a few hundredths of a millimetre and a thousandth of a degree.
    nominal = {p["name"]: p for p in cli_json("evaluate", ARM6, "--json")["parameters"]}
    rng = np.random.default_rng(3)
    truth = {name: p["nominal"] + rng.choice([-1.0, 1.0]) * (0.05 if p["unit"] == "mm" else 0.005)
             for name, p in nominal.items()}
    truth_file = tmp_path / "truth.json"
    truth_file.write_text(json.dumps({"parameters": truth}))
    readings = tmp_path / "touches.json"
    run_cli("simulate", ARM6, "--truth", str(truth_file), "--seed", "4", "-o", str(readings),
            expect=(0,))
    result = artcal.Plan(readings).calibrate()
    assert result == cli_json("calibrate", str(readings), "--json")
    assert result["converged"]
    by_name = {p["name"]: p for p in result["parameters"]}
    for name, value in truth.items():
        assert abs(by_name[name]["estimate"] - value) < 3.0 * by_name[name]["u"], name
    assert 0.5 < result["chi2_per_dof"] < 1.6


def test_two_tip_plane_evaluation_equals_cli_per_tip():
    result = artcal.Plan(HUMANOID).evaluate()
    assert result == cli_json("evaluate", HUMANOID, "--json")
    tips = result["tips"]
    assert [t["name"] for t in tips] == ["gripper_left_base_link", "gripper_right_base_link"]
    # The first tip's figures are the top-level ones; the tips' worst differ (two arms).
    assert tips[0]["tip"]["worst"]["total"] == pytest.approx(result["tip"]["worst"]["total"],
                                                             rel=1e-15)
    assert tips[0]["tip"]["worst"]["total"] != tips[1]["tip"]["worst"]["total"]
    # The shared parameters (leg, torso) move both tips, each arm's own one tip only.
    left, right = (set(t["parameters"]) for t in tips)
    shared = left & right
    assert shared and all(n.startswith(("leg_left", "torso", "left_sole")) for n in shared)
    assert all("right" not in n for n in left - shared)
    assert all("left" not in n for n in right - shared)


def test_import_of_csv_files_with_two_tips_and_a_prior_equals_cli(tmp_path):
    # Two sessions of flush touches of the humanoid, one file per hand, each on its own table
    # (named columns in rad, a header written 4 fields left of its values), imported and
    # calibrated as the command line does.
    plan = json.loads(open("plans/planes/humanoid-flush.json").read())
    joints = [j["name"] for j in plan["machine"]["joints"] if j["type"] != "fixed"]
    readings = tmp_path / "sim.json"
    run_cli("simulate", "plans/planes/humanoid-flush.json", "--truth",
            "plans/planes/humanoid-table.truth.json", "--seed", "1", "-o", str(readings),
            expect=(0,))
    simulated = json.loads(readings.read_text())
    files = []
    for hand, table in (("left", "table high"), ("right", "table low")):
        rows = ["joint_names," + ",".join(joints) + ",,,,"]
        for placement in simulated["placements"]:
            if placement["name"] != table:
                continue
            for m in placement["measurements"]:
                if m["tip"] == f"gripper_{hand}_base_link":
                    rows.append("gripper,talos,handle,contact,joint_states," +
                                ",".join(repr(np.radians(v)) for v in m["joints"]))
        path = tmp_path / f"{hand}.csv"
        path.write_text("\n".join(rows) + "\n")
        files.append(str(path))
    artifact = tmp_path / "table.json"
    artifact.write_text(json.dumps({"table": simulated["artifacts"]["table"]}))
    tips = ["gripper_left_base_link", "gripper_right_base_link"]
    output = tmp_path / "py.json"
    imported = artcal.import_readings(
        files, urdf="tests/data/urdf/humanoid-small.urdf", base="left_sole_link", tip=tips,
        tip_of={"left": tips[0], "right": tips[1]}, artifact=artifact, unit="rad",
        prior=(5.0, 0.5), output=output)
    cli_output = tmp_path / "cli.json"
    run_cli("import-readings", *files, "--urdf", "tests/data/urdf/humanoid-small.urdf", "--base",
            "left_sole_link", "--tip", tips[0], "--tip", tips[1], "--tip-of", f"left={tips[0]}",
            "--tip-of", f"right={tips[1]}", "--artifact", str(artifact), "--unit", "rad",
            "--prior", "5,0.5", "-o", str(cli_output), expect=(0,))
    assert json.loads(output.read_text()) == json.loads(cli_output.read_text())
    assert imported.calibrate() == cli_json("calibrate", str(cli_output), "--json")
