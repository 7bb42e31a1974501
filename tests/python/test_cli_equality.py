"""Every Python result equals the command line's --json document for the same input."""

import json

import numpy as np
import pytest

import artcal
from conftest import ROOT, cli_json

PLANS = ["plans/paper-2r-5bars.json", "plans/panda-8positions.json", "plans/cmm-plate-xy.json"]


@pytest.mark.parametrize("plan", PLANS)
def test_check_equals_cli(plan):
    assert artcal.Plan(plan).check() == cli_json("check", plan, "--json")


@pytest.mark.parametrize("plan", PLANS)
def test_evaluate_equals_cli(plan):
    result = artcal.Plan(plan).evaluate()
    assert result == cli_json("evaluate", plan, "--json")
    # The numpy views agree with the document they came beside.
    assert result.parameter_names == [p["name"] for p in result["parameters"]]
    assert np.array_equal(result.u, [p["u"] for p in result["parameters"]])
    n = len(result.parameter_names)
    assert result.covariance.shape == (n, n)
    assert np.allclose(np.sqrt(np.diag(result.covariance)), result.u, rtol=1e-12, atol=0)
    corr = result.covariance / np.outer(result.u, result.u)
    assert np.allclose(corr, result["correlation"], atol=1e-12)
    tip = result["tip"]
    assert result.tip_total.shape == (tip["configurations"],)
    assert result.tip_total.max() == pytest.approx(tip["worst"]["total"], rel=1e-12)
    assert result.tip_total.mean() == pytest.approx(tip["mean"], rel=1e-9)
    assert np.allclose(result.tip_total ** 2, result.tip_kinematic ** 2 + result.tip_encoder ** 2,
                       rtol=1e-9)
    assert result.tip_joints.shape[0] == tip["configurations"]


def test_plan_from_dict_equals_plan_from_file():
    path = ROOT / "plans" / "paper-2r-5bars.json"
    document = json.loads(path.read_text())
    from_dict = artcal.Plan.from_dict(document)
    assert from_dict.evaluate() == artcal.Plan(path).evaluate()


@pytest.mark.parametrize("plan", ["plans/paper-2r-5bars.json", "plans/panda-8positions.json"])
def test_calibrate_equals_cli(plan):
    result = artcal.Plan(plan).calibrate()
    assert result == cli_json("calibrate", plan, "--json")
    names = [p["name"] for p in result["parameters"]]
    assert result.parameter_names == names
    assert result.estimates.shape == (len(names),)
    if result.covariance is not None:
        assert result.covariance.shape == (len(names), len(names))


def test_calibrated_machine_equals_write_machine(tmp_path):
    plan = "plans/paper-2r-5bars.json"
    machine = tmp_path / "machine.json"
    cli_json("calibrate", plan, "--json", "--write-machine", str(machine))
    assert artcal.Plan(plan).calibrate().machine == json.loads(machine.read_text())


def test_verify_equals_cli():
    plan, machine = "plans/panda-others.json", "plans/panda-8positions.machine.json"
    assert artcal.Plan(plan).verify(machine) == cli_json("verify", plan, "--machine", machine,
                                                         "--json")
    assert artcal.Plan(plan).verify() == cli_json("verify", plan, "--json")


def test_verify_of_instrument_stations_equals_cli(tmp_path):
    # A plan of stations alone gets the stations' figures only, as the command prints them.
    plan = "plans/tracker-arm6-2stations.simulated.json"
    machine = tmp_path / "machine.json"
    cli_json("calibrate", plan, "--json", "--write-machine", str(machine))
    for args in ([], [str(machine)]):
        result = artcal.Plan(plan).verify(*args)
        cli = cli_json("verify", plan, *(["--machine", str(machine)] if args else []), "--json")
        assert result == cli
        assert set(result) == {"plan", "instrument"}
        assert len(result["instrument"]["stations"]) == 2


def test_verify_of_an_estimated_noise_plan_equals_cli(tmp_path):
    # The machine file carries the probe noise the calibration estimated; verify predicts with it.
    truth, simulated = tmp_path / "truth.json", tmp_path / "simulated.json"
    truth.write_text(json.dumps({"parameters": {"l1": 150.02}}))
    cli_json("simulate", "plans/paper-2r-5bars.json", "--truth", str(truth), "--seed", "7", "-o",
             str(simulated), "--json")
    plan = json.loads(simulated.read_text())
    plan["noise"]["probe"] = "estimate"
    estimated, machine = tmp_path / "estimated.json", tmp_path / "machine.json"
    estimated.write_text(json.dumps(plan))
    cli_json("calibrate", str(estimated), "--json", "--write-machine", str(machine))
    assert "probe_noise" in json.loads(machine.read_text())["covariance"]
    assert artcal.Plan(str(estimated)).verify(str(machine)) == cli_json(
        "verify", str(estimated), "--machine", str(machine), "--json")


def test_simulate_equals_cli(tmp_path):
    plan = "plans/paper-2r-5bars.json"
    truth = tmp_path / "truth.json"
    truth.write_text(json.dumps({"parameters": {"l1": 150.02}}))
    out = tmp_path / "simulated.json"
    cli_json("simulate", plan, "--truth", str(truth), "--seed", "7", "-o", str(out), "--json")
    simulated = artcal.Plan(plan).simulate(str(truth), seed=7)
    assert simulated.to_dict() == json.loads(out.read_text())
    # The same truth as a dict, and the readings as an (n, joints) array.
    again = artcal.Plan(plan).simulate({"parameters": {"l1": 150.02}}, seed=7)
    assert again.to_dict()["placements"] == simulated.to_dict()["placements"]
    joints, _ = simulated.readings(0)
    assert joints.shape == (len(simulated.to_dict()["placements"][0]["measurements"]), 2)


def test_confirm_equals_cli_with_progress():
    plan = "plans/paper-2r-5bars.json"
    calls = []
    result = artcal.Plan(plan).confirm(trials=20, seed=3, threads=2,
                                       progress=lambda done, total: calls.append((done, total)))
    assert result == cli_json("confirm", plan, "--trials", "20", "--seed", "3", "--threads", "2",
                              "--json")
    assert sorted(calls) == [(k, 20) for k in range(1, 21)]


def test_progress_exception_is_raised_after_the_run():
    def fail(done, total):
        raise KeyError("stop")

    with pytest.raises(KeyError):
        artcal.Plan("plans/paper-2r-5bars.json").confirm(trials=4, threads=1, progress=fail)


def test_optimize_equals_cli(tmp_path):
    spec = "plans/seed-2r-5bars.spec.json"
    out = tmp_path / "optimized.json"
    cli_json("optimize", spec, "--starts", "2", "--seed", "5", "--threads", "1", "-o", str(out),
             "--json")
    expected = json.loads(out.read_text())
    assert "optimization" in expected["predicted"]  # the search's own record, Python's too
    progress = []
    plan = artcal.optimize(spec, starts=2, seed=5, threads=1,
                           progress=lambda *args: progress.append(args))
    assert plan.to_dict() == expected
    assert progress and progress[-1][0] == 2


def test_acceptance_length_equals_cli():
    plan = "plans/cmm-plate-xy.json"
    args = ["--test", "iso10360-2", "--mpe", "3 + L/300", "--trials", "2000"]
    expected = cli_json("acceptance", plan, *args, "--json")
    assert artcal.Plan(plan).acceptance_length("3 + L/300", trials=2000) == expected
    e150 = cli_json("acceptance", plan, *args, "--stylus-offset", "150", "--json")
    assert artcal.Plan(plan).acceptance_length("3 + L/300", trials=2000,
                                               stylus_offset=150) == e150
    assert e150["quantity"] == "E150"


def test_acceptance_pose_equals_cli():
    plan = "plans/panda-8positions.json"
    args = ["--test", "iso9283", "--cube", "200", "--center", "500,0,400", "--trials", "2000"]
    expected = cli_json("acceptance", plan, *args, "--json")
    assert artcal.Plan(plan).acceptance_pose(200, (500, 0, 400), trials=2000) == expected


def test_import_urdf_equals_cli():
    urdf = "tests/data/mukca/mukca/urdf/panda.urdf"
    expected = cli_json("import-urdf", urdf, "--base", "panda_link0", "--tip", "ball_link")
    assert artcal.import_urdf(urdf, "panda_link0", "ball_link") == expected


def test_readings_from_csv_as_arrays():
    plan = artcal.Plan("plans/panda-8positions.json")
    joints, features = plan.readings(0)
    entries = plan.to_dict()["placements"][0]["measurements"]
    expected = [np.degrees(np.loadtxt(ROOT / "plans" / e["csv"], delimiter=",", ndmin=2))
                for e in entries]
    stacked = np.vstack(expected)
    assert joints.shape == stacked.shape == (stacked.shape[0], 7)
    assert np.allclose(joints, stacked, rtol=1e-12, atol=1e-12)
    assert list(features) == sum(([e["feature"]] * len(x) for e, x in zip(entries, expected)),
                                 [])
