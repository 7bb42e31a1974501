"""A plan built in code (artcal.Plan(machine=..., ...), add_artifact, add_placement with (n, k)
joint arrays) is the plan of the same JSON form: the shipped plan rebuilt from its parts
evaluates exactly as the file, and a bad part raises the command line's message for the same
document."""

import json

import numpy as np
import pytest

import artcal
from conftest import ROOT, cli_error, cli_json

SHIPPED = "plans/paper-2r-5bars.json"


def shipped():
    return json.loads((ROOT / SHIPPED).read_text())


def parts(document):
    return {key: document[key] for key in ("machine", "noise", "workspace")}


def test_built_with_add_placement_evaluates_as_the_file():
    document = shipped()
    plan = artcal.Plan(name=document["name"], **parts(document))
    for artifact_id, artifact in document["artifacts"].items():
        plan.add_artifact(artifact_id, **artifact)
    for entry in document["placements"]:
        joints = np.array([m["joints"] for m in entry["measurements"]])  # (n, 2), deg
        features = np.array([m["feature"] for m in entry["measurements"]])
        plan.add_placement(entry["artifact"], joints, features, pose=entry["pose"])
    assert plan.evaluate() == artcal.Plan(SHIPPED).evaluate()
    assert plan.evaluate() == cli_json("evaluate", SHIPPED, "--json")
    assert plan.check() == cli_json("check", SHIPPED, "--json")


def test_built_from_placements_per_feature_equals_the_file_document():
    document = shipped()
    placements = [
        artcal.placement(entry["artifact"],
                         [np.array([m["joints"]]) for m in entry["measurements"]],
                         pose=entry["pose"])
        for entry in document["placements"]]
    plan = artcal.Plan(machine=document["machine"], noise=document["noise"],
                       artifacts=document["artifacts"], placements=placements,
                       workspace=document["workspace"], name=document["name"],
                       description=document["description"])
    assert plan.to_dict() == document
    assert plan.calibrate() == artcal.Plan(SHIPPED).calibrate()


def test_readings_round_trip_through_add_placement():
    source = artcal.Plan("plans/panda-8positions.json")  # CSV readings in rad, read as deg
    joints, features = source.readings(0)
    document = source.to_dict()
    plan = artcal.Plan(machine=document["machine"], noise=document["noise"],
                       artifacts=document["artifacts"], name="one")
    plan.add_placement(document["placements"][0]["artifact"], joints, features)
    again, again_features = plan.readings(0)
    assert np.array_equal(again, joints) and np.array_equal(again_features, features)


def test_a_dict_of_features_and_numpy_scalars_are_taken():
    document = shipped()
    plan = artcal.Plan(machine=document["machine"], noise={"probe": np.float64(0.005),
                                                           "encoder": 0.001},
                       artifacts=document["artifacts"], workspace=document["workspace"],
                       name=document["name"])
    for entry in document["placements"]:
        plan.add_placement(entry["artifact"],
                           {m["feature"]: np.array(m["joints"]) for m in entry["measurements"]})
    assert plan.evaluate()["parameters"] == artcal.Plan(SHIPPED).evaluate()["parameters"]


def test_a_bad_part_raises_the_cli_message(tmp_path):
    document = shipped()
    path = tmp_path / "built.json"
    plan = artcal.Plan(source=str(path), name="built", **parts(document),
                       artifacts=document["artifacts"])
    plan.add_placement("bar80", np.array([[10.0, 20.0, 30.0]]), [0])  # 3 joints, not 2
    path.write_text(json.dumps(plan.to_dict()))
    expected = cli_error("check", str(path))
    with pytest.raises(artcal.InputError) as raised:
        plan.check()
    assert str(raised.value) == expected
    assert "/placements/0/measurements/0/joints" in expected


def test_unknown_artifact_raises_the_cli_message(tmp_path):
    document = shipped()
    path = tmp_path / "built.json"
    plan = artcal.Plan(source=str(path), name="built", **parts(document),
                       artifacts=document["artifacts"])
    plan.add_placement("no_such_bar", [np.array([[10.0, 20.0]]), np.array([[30.0, 40.0]])])
    path.write_text(json.dumps(plan.to_dict()))
    with pytest.raises(artcal.InputError) as raised:
        plan.evaluate()
    assert str(raised.value) == cli_error("evaluate", str(path))


def test_malformed_arrays_raise_value_error():
    with pytest.raises(ValueError):
        artcal.placement("bar80", np.zeros((3, 2)), [0, 1])  # 3 rows, 2 features
    with pytest.raises(ValueError):
        artcal.placement("bar80", [np.zeros((2, 2, 2))])
    with pytest.raises(TypeError):
        artcal.Plan(SHIPPED, name="both")
