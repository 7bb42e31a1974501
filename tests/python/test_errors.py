"""Bad input raises artcal.InputError (or RunError) whose message is the command line's error line;
the interpreter survives every case (the hardening inputs of tests/data included)."""

import json
from pathlib import Path

import pytest

import artcal
from conftest import ROOT, cli_error, cli_json, run_cli

BAD_PLANS = ["tests/data/broken-joints.json", "tests/data/no-such-plan.json", "/dev/zero",
             "tests/data/mukca/mukca/urdf/panda.urdf"]


@pytest.mark.parametrize("plan", BAD_PLANS)
def test_bad_plan_raises_the_cli_message(plan):
    expected = cli_error("check", plan)
    with pytest.raises(artcal.InputError) as raised:
        artcal.Plan(plan).check()
    assert str(raised.value) == expected


@pytest.mark.parametrize("plan", sorted(str(p.relative_to(ROOT)) for p in
                                        (ROOT / "tests/data/fuzz-regressions").glob("*.json")))
def test_fuzz_regressions_answer_as_the_cli(plan):
    done = run_cli("evaluate", plan, "--json", expect=(0, 1, 2))
    if done.returncode == 2 or not done.stdout:
        with pytest.raises(artcal.Error) as raised:
            artcal.Plan(plan).evaluate()
        assert "error: " + str(raised.value) in done.stderr
    else:
        assert artcal.Plan(plan).evaluate() == json.loads(done.stdout)


@pytest.mark.parametrize("urdf, base, tip", [
    ("tests/data/hostile/two-parents.urdf", "base", "tip"),
    ("tests/data/hostile/cycle.urdf", "base", "a"),
    ("tests/data/hostile/mimic-of-missing-joint.urdf", "base", "tip"),
    ("tests/data/hostile/mimic-cycle.urdf", "base", "tip"),
    ("tests/data/hostile/huge-limit-and-axis.urdf", "base", "tip"),
    ("tests/data/mukca/mukca/urdf/panda.urdf", "panda_link0", "no_such_link"),
])
def test_hostile_urdf_raises_the_cli_message(urdf, base, tip):
    expected = cli_error("import-urdf", urdf, "--base", base, "--tip", tip)
    with pytest.raises(artcal.InputError) as raised:
        artcal.import_urdf(urdf, base, tip)
    assert str(raised.value) == expected


def test_bad_machine_file_raises_the_cli_message(tmp_path):
    machine = tmp_path / "machine.json"
    machine.write_text('{"parameters": {"no_such_parameter": 1}}')
    plan = "plans/paper-2r-5bars.json"
    expected = cli_error("verify", plan, "--machine", str(machine))
    with pytest.raises(artcal.InputError) as raised:
        artcal.Plan(plan).verify(str(machine))
    assert str(raised.value) == expected


def test_bad_dict_names_its_source_and_pointer():
    document = json.loads((ROOT / "plans/paper-2r-5bars.json").read_text())
    document["placements"][0]["measurements"][0]["joints"] = [1.0, 2.0, 3.0]
    with pytest.raises(artcal.InputError) as raised:
        artcal.Plan.from_dict(document, source="mine")
    assert str(raised.value).startswith("mine: /placements/0/measurements/0/joints: ")


def test_unencodable_dict_and_nan_raise_not_crash():
    with pytest.raises(TypeError):
        artcal.Plan.from_dict({"format": {1, 2}})
    with pytest.raises(ValueError):
        artcal.Plan.from_dict({"format": float("nan")})
    with pytest.raises(artcal.InputError):
        artcal.Plan.from_dict({})


def test_bad_options_raise():
    plan = artcal.Plan("plans/paper-2r-5bars.json")
    with pytest.raises(artcal.InputError):
        plan.confirm(trials=0)
    with pytest.raises(artcal.InputError):
        plan.acceptance_length("not an mpe")
    with pytest.raises(artcal.InputError):
        plan.evaluate(profile_steps=1)
    with pytest.raises(artcal.InputError):
        artcal.optimize("plans/paper-2r-5bars.json")  # no design block


def test_plan_object_stays_usable_after_an_error():
    plan = artcal.Plan("plans/paper-2r-5bars.json")
    with pytest.raises(artcal.InputError):
        plan.verify("tests/data/no-such-machine.json")
    assert plan.check() == cli_json("check", "plans/paper-2r-5bars.json", "--json")
