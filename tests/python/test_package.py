"""The package's surface: the stubs name what the module has, docstrings are there, the prepared
evaluator agrees with evaluate."""

import ast
import inspect
from pathlib import Path

import pytest

import artcal

STUBS = Path(artcal.__file__).with_name("__init__.pyi")


def stub_names():
    tree = ast.parse(STUBS.read_text())
    names = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        elif isinstance(node, ast.FunctionDef):
            names[node.name] = set()
    return names


def test_every_public_name_has_a_stub_and_a_docstring():
    stubs = stub_names()
    for name in artcal.__all__:
        assert name in stubs, name
        obj = getattr(artcal, name)
        if inspect.isclass(obj) and not issubclass(obj, Exception):
            assert obj.__doc__, name
            for member, value in vars(obj).items():
                if member.startswith("_") or not callable(value):
                    continue
                assert member in stubs[name], f"{name}.{member} has no stub"
                assert value.__doc__, f"{name}.{member} has no docstring"
        elif callable(obj) and not inspect.isclass(obj):
            assert obj.__doc__, name


def test_errors_derive_from_value_error():
    assert issubclass(artcal.InputError, artcal.Error)
    assert issubclass(artcal.RunError, artcal.Error)
    assert issubclass(artcal.Error, ValueError)


def test_prepared_evaluator_agrees_with_evaluate():
    plan = artcal.Plan("plans/paper-2r-5bars.json")
    worst, mean, rms = artcal.Evaluator(plan).tip()
    tip = plan.evaluate(per_configuration=False)["tip"]
    assert worst == pytest.approx(tip["worst"]["total"], rel=1e-9)
    assert mean == pytest.approx(tip["mean"], rel=1e-9)
    assert rms == pytest.approx(tip["rms"], rel=1e-9)
