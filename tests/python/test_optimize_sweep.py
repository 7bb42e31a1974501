"""optimize carries the command's `predicted.optimization` (and `calibrate_resolved_on`), and
optimize_sweep is `artcal optimize SPEC --placements A..B -o DIR --json`: the same summary and
the same files. A small spec, two starts, a fixed seed: each run takes a fraction of a second."""

import json

import pytest

import artcal
from conftest import cli_error, cli_json, run_cli

SPEC = "plans/seed-2r-5bars.spec.json"
SMALL = ["--starts", "2", "--seed", "5", "--threads", "1"]


def test_optimize_resolving_identifiable_equals_cli(tmp_path):
    document = json.loads(open(SPEC).read())
    document["machine"]["calibrate"] = "identifiable"
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(document))
    out = tmp_path / "optimized.json"
    run_cli("optimize", str(spec), *SMALL, "--algorithm", "bobyqa", "--polish", "1", "-o",
            str(out), "--json")
    expected = json.loads(out.read_text())
    assert "calibrate_resolved_on" in expected["predicted"]
    plan = artcal.optimize(spec, starts=2, seed=5, threads=1, algorithm="bobyqa", polish=1)
    assert plan.to_dict() == expected
    assert plan.to_dict()["predicted"]["optimization"]["algorithm"] == "bobyqa"


def without_timings(document, directory):
    text = json.dumps(document).replace(str(directory), "DIR")
    out = json.loads(text)
    for count in out["counts"]:
        count.pop("seconds")
    return out


def test_sweep_equals_cli(tmp_path):
    cli_dir, py_dir = tmp_path / "cli", tmp_path / "py"
    expected = cli_json("optimize", SPEC, *SMALL, "--placements", "2..4", "--target-tip",
                        "0.012", "-o", str(cli_dir), "--json")
    counts = []
    summary = artcal.optimize_sweep(SPEC, "2..4", py_dir, target_tip=0.012, starts=2, seed=5,
                                    threads=1, progress=lambda m, g: counts.append(m))
    assert without_timings(summary, py_dir) == without_timings(expected, cli_dir)
    assert counts == [2, 3, 4]
    names = sorted(p.name for p in cli_dir.iterdir())
    assert names == sorted(p.name for p in py_dir.iterdir())
    for name in names:
        if name.startswith("summary"):
            continue  # timings
        assert (py_dir / name).read_bytes() == (cli_dir / name).read_bytes(), name
    assert sorted(summary.plans) == [3, 4]  # 2 bars cannot identify 3 parameters
    assert summary.plans[4].to_dict() == json.loads((cli_dir / "seed-2r-5bars-4.json").read_text())


@pytest.mark.parametrize("range_", ["4..2", "0..3", "x"])
def test_sweep_bad_range_raises_the_cli_message(tmp_path, range_):
    expected = cli_error("optimize", SPEC, *SMALL, "--placements", range_, "-o",
                         str(tmp_path / "cli"))
    with pytest.raises(artcal.InputError) as raised:
        artcal.optimize_sweep(SPEC, range_, tmp_path / "py", starts=2, seed=5, threads=1)
    assert str(raised.value) == expected
    assert not (tmp_path / "py").exists()


def test_too_few_placements_raise_the_cli_message(tmp_path):
    document = json.loads(open(SPEC).read())
    document["design"]["placements"] = 1  # one bar: 1 equation for 3 parameters
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(document))
    expected = cli_error("optimize", str(spec), *SMALL, "-o", str(tmp_path / "out.json"))
    with pytest.raises(artcal.InputError) as raised:
        artcal.optimize(spec, starts=2, seed=5, threads=1)
    assert str(raised.value) == expected


def test_bad_algorithm_raises():
    with pytest.raises(artcal.InputError):
        artcal.optimize(SPEC, starts=1, algorithm="newton")
