"""The acceptance prediction from a calibrated machine (`artcal acceptance MACHINE --plan PLAN
[--posterior] --json`), the machine as a file or as calibrate().machine; bad input raises the
command line's message."""

import json

import pytest

import artcal
from conftest import cli_error, cli_json, run_cli

PLAN = "plans/cmm-plate-xy.json"
LENGTH = ["--test", "iso10360-2", "--mpe", "3 + L/300", "--trials", "2000"]
PANDA, PANDA_MACHINE = "plans/panda-8positions.json", "plans/panda-8positions.machine.json"
POSE = ["--test", "iso9283", "--cube", "200", "--center", "500,0,400", "--trials", "500"]


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    """A CMM calibrated on simulated readings: the plan, the machine file and its dict."""
    folder = tmp_path_factory.mktemp("cmm")
    truth, simulated, machine = folder / "truth.json", folder / "sim.json", folder / "m.json"
    truth.write_text(json.dumps({"parameters": {"y.tx.1": 0.003}}))
    run_cli("simulate", PLAN, "--truth", str(truth), "--seed", "3", "-o", str(simulated))
    run_cli("calibrate", str(simulated), "--json", "--write-machine", str(machine))
    return str(simulated), str(machine)


@pytest.mark.parametrize("posterior", [False, True])
def test_length_test_of_a_machine_equals_cli(calibrated, posterior):
    plan, machine = calibrated
    flag = ["--posterior"] if posterior else []
    expected = cli_json("acceptance", machine, "--plan", plan, *LENGTH, *flag, "--json")
    result = artcal.Plan(plan).acceptance_length("3 + L/300", trials=2000, machine=machine,
                                                 posterior=posterior)
    assert result == expected
    # The machine as the dict calibrate() returns: the same prediction.
    as_dict = artcal.Plan(plan).calibrate().machine
    assert as_dict == json.loads(open(machine).read())
    assert artcal.Plan(plan).acceptance_length("3 + L/300", trials=2000, machine=as_dict,
                                               posterior=posterior) == expected


def test_pose_test_of_a_machine_equals_cli():
    expected = cli_json("acceptance", PANDA_MACHINE, "--plan", PANDA, *POSE, "--json")
    result = artcal.Plan(PANDA).acceptance_pose(200, (500, 0, 400), trials=500,
                                                machine=PANDA_MACHINE)
    assert result == expected
    assert result != artcal.Plan(PANDA).acceptance_pose(200, (500, 0, 400), trials=500)


def test_posterior_without_birge_ratio_raises_the_cli_message():
    expected = cli_error("acceptance", PANDA_MACHINE, "--plan", PANDA, *POSE, "--posterior")
    with pytest.raises(artcal.InputError) as raised:
        artcal.Plan(PANDA).acceptance_pose(200, (500, 0, 400), trials=500,
                                           machine=PANDA_MACHINE, posterior=True)
    assert str(raised.value) == expected


def test_posterior_with_a_plan_raises_the_cli_message():
    expected = cli_error("acceptance", PLAN, *LENGTH, "--posterior")
    with pytest.raises(artcal.InputError) as raised:
        artcal.Plan(PLAN).acceptance_length("3 + L/300", trials=2000, posterior=True)
    assert str(raised.value) == expected


def test_machine_without_covariance_raises_the_cli_message(tmp_path):
    machine = tmp_path / "machine.json"
    document = json.loads(open(PANDA_MACHINE).read())
    del document["covariance"]
    machine.write_text(json.dumps(document))
    expected = cli_error("acceptance", str(machine), "--plan", PANDA, *POSE)
    with pytest.raises(artcal.InputError) as raised:
        artcal.Plan(PANDA).acceptance_pose(200, (500, 0, 400), trials=500, machine=machine)
    assert str(raised.value) == expected
