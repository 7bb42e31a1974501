"""Hardening III (issue 32, docs/hardening.md): the Python entry points against hostile dtypes and
values. A property test (hypothesis, Debian's python3-hypothesis) over the arrays and numbers the
plan builders and the predictions take: every answer is a result or artcal.InputError naming
what is wrong; never a bare ValueError, a silently converted value or a non-finite number in a
result."""

import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import artcal

REF = "tests/data/ref-2r-5bars.json"
TRACKER = "plans/tracker-arm6-2stations.json"
SETTINGS = settings(max_examples=60, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])


def two_link_plan(placements):
    document = json.load(open(REF))
    return artcal.Plan(machine=document["machine"], noise=document["noise"],
                       artifacts=document["artifacts"], placements=placements)


def finite_numbers(value):
    """Every number of a JSON-like value is finite."""
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, dict):
        return all(finite_numbers(v) for v in value.values())
    if isinstance(value, list):
        return all(finite_numbers(v) for v in value)
    return True


# Joint arrays of every dtype numpy has, with hostile values among them.
VALUES = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-400, 400),
                   st.booleans(), st.complex_numbers(max_magnitude=1e3), st.text(max_size=3))
DTYPES = st.sampled_from(["float64", "float32", "int64", "uint8", "bool", "complex128",
                          "object", "U4"])


@SETTINGS
@given(values=st.lists(VALUES, min_size=2, max_size=2), dtype=DTYPES)
def test_joint_arrays_are_real_finite_numbers_or_an_input_error(values, dtype):
    try:
        with np.errstate(all="ignore"):  # float32 of 1e300: inf, which artcal must refuse
            joints = np.asarray([values, [-126.8, 143.6]], dtype=dtype)
    except (TypeError, ValueError, OverflowError):
        return  # numpy itself refuses the array: nothing reaches artcal
    try:
        plan = two_link_plan([artcal.placement("bar80", joints, [0, 1])])
        result = plan.check()
    except artcal.InputError as error:
        message = str(error)
        assert message and "\n" not in message
        # Named: the array (joints ...) or the reading's JSON pointer in the plan.
        assert "joints" in message or "/placements/" in message or "feature" in message, message
        return
    # Accepted: only real, finite readings, and a result without NaN or inf.
    assert joints.dtype.kind in "iuf"
    assert np.all(np.isfinite(joints.astype(float)))
    assert finite_numbers(dict(result))


@SETTINGS
@given(feature=st.one_of(st.integers(-3, 5), st.floats(allow_nan=True), st.booleans(),
                         st.complex_numbers(max_magnitude=5), st.text(max_size=2)))
def test_feature_indices_are_whole_numbers_or_an_input_error(feature):
    joints = np.asarray([[-93.2, 116.4], [-126.8, 143.6]])
    try:
        plan = two_link_plan([artcal.placement("bar80", joints, np.asarray([feature, 1],
                                                                           dtype=object))])
        plan.check()
    except artcal.InputError as error:
        assert "feature" in str(error), str(error)
        return
    # Accepted: a whole number that the plan reader then took as an index in range.
    assert not isinstance(feature, bool) and float(feature).is_integer() and 0 <= feature <= 1


@SETTINGS
@given(x=st.floats(allow_nan=True, allow_infinity=True, width=64))
def test_a_nan_or_inf_anywhere_in_a_plan_dict_is_named_by_its_pointer(x):
    document = json.load(open(REF))
    document["placements"][0]["measurements"][1]["joints"][0] = x
    try:
        artcal.Plan.from_dict(document, source="p.json").check()
    except artcal.InputError as error:
        message = str(error)
        if not math.isfinite(x):
            assert message.startswith("p.json: /placements/0/measurements/1/joints/0: expected "
                                      "a finite number"), message
        return
    assert math.isfinite(x)


@pytest.mark.parametrize("call, option", [
    (lambda p: p.acceptance_pose(float("inf"), (500, 0, 400), trials=10), "--cube"),
    (lambda p: p.acceptance_pose(float("nan"), (500, 0, 400), trials=10), "--cube"),
    (lambda p: p.acceptance_pose(200, (500, float("nan"), 400), trials=10), "--center"),
    (lambda p: p.acceptance_pose(200, (500, 0, 400), mpe=float("inf"), trials=10), "--mpe"),
    (lambda p: p.check(rank_tol=float("nan")), "--rank-tol"),
    (lambda p: p.confirm(trials=2, noise_scale=float("inf")), "--noise-scale"),
])
def test_non_finite_numbers_name_the_option(call, option):
    with pytest.raises(artcal.InputError) as raised:
        call(artcal.Plan("plans/panda-8positions.json"))
    assert str(raised.value).startswith(option + ": "), str(raised.value)
    assert "expected a finite number" in str(raised.value)


@pytest.mark.parametrize("offset", [float("nan"), float("inf"), -150.0])
def test_a_stylus_offset_that_is_not_a_length_names_the_option(offset):
    with pytest.raises(artcal.InputError) as raised:
        artcal.Plan("plans/cmm-plate-xy.json").acceptance_length("3 + L/300", trials=10,
                                                                 stylus_offset=offset)
    assert str(raised.value).startswith("--stylus-offset: expected a finite number"), \
        str(raised.value)


def test_instrument_readings_are_built_with_add_station():
    reference = json.load(open(TRACKER))
    plan = artcal.Plan(machine=reference["machine"], noise=reference["noise"],
                       artifacts=reference["artifacts"], name=reference["name"])
    with pytest.raises(artcal.InputError) as raised:
        plan.add_placement("tracker", np.zeros((3, 6)))
    assert "add_station" in str(raised.value)
    for station in reference["placements"]:
        joints = np.asarray([m["joints"] for m in station["measurements"]])
        points = np.asarray([m["point"] for m in station["measurements"]])
        marks = np.asarray([m.get("stationing", False) for m in station["measurements"]])
        plan.add_station("tracker", joints, points, stationing=marks, name=station["name"])
    built = plan.to_dict()["placements"]
    assert built == [{"artifact": p["artifact"], "name": p["name"],
                      "measurements": p["measurements"]} for p in reference["placements"]]
    assert plan.check() == artcal.Plan(TRACKER).check()


# Issue 44: the Python entry points read numbers and types as the command line does.
MUKCA = "tests/data/mukca/mukca"
PANDA = dict(urdf=f"{MUKCA}/urdf/panda.urdf", base="panda_link0", tip="ball_link", ball_bar=50)


@pytest.mark.parametrize("prior", [(0, 0), (0.0, 0.5), (True, True), (5.0, True), (5.0,),
                                   ("5", "0.5")])
def test_a_prior_the_command_line_refuses_is_refused(prior):
    # (0, 0) dropped the prior (the command line refuses --prior 0,0); True was taken as 1.
    with pytest.raises(artcal.InputError) as raised:
        artcal.import_readings(f"{MUKCA}/panda_2", prior=prior, **PANDA)
    assert str(raised.value).startswith("--prior: "), str(raised.value)
    assert "\n" not in str(raised.value)


@pytest.mark.parametrize("arguments", [dict(ball_bar=True), dict(encoder="0.1"),
                                       dict(u_length=1j), dict(hold={"j4": True})])
def test_a_number_argument_of_another_type_names_it(arguments):
    options = dict(PANDA, **arguments)
    with pytest.raises(artcal.InputError) as raised:
        artcal.import_readings(f"{MUKCA}/panda_2", **options)
    assert "expected a number" in str(raised.value), str(raised.value)


@pytest.mark.parametrize("call", [
    lambda: artcal.import_readings(f"{MUKCA}/panda_2", urdf=f"{MUKCA}/urdf/panda.urdf",
                                   base=7, tip="ball_link", ball_bar=50),
    lambda: artcal.import_urdf(f"{MUKCA}/urdf/panda.urdf", base=["panda_link0"], tip="ball_link"),
    lambda: artcal.Plan(REF).calibrate(max_iterations="ten"),
    lambda: artcal.Plan(REF).confirm(trials=2.5),
])
def test_a_type_error_is_an_input_error_of_one_line_not_a_signature_dump(call):
    with pytest.raises(artcal.InputError) as raised:
        call()
    message = str(raised.value)
    assert "\n" not in message and "incompatible" not in message and len(message) < 200, message
