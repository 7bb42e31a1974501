"""import_readings and export_urdf equal `artcal import-readings` and `artcal export-urdf`; a bad
input raises the command line's message."""

import json
import math
import warnings

import pytest

import artcal
from conftest import cli_error, cli_json, run_cli

MUKCA = "tests/data/mukca/mukca"
URDF = f"{MUKCA}/urdf/panda.urdf"
CHAIN = ["--urdf", URDF, "--base", "panda_link0", "--tip", "ball_link"]
MACHINE = "plans/panda-8positions.machine.json"


def test_import_readings_equals_cli():
    expected = cli_json("import-readings", f"{MUKCA}/panda_2", *CHAIN, "--ball-bar", "50",
                        "-o", "-")
    plan = artcal.import_readings(f"{MUKCA}/panda_2", urdf=URDF, base="panda_link0",
                                  tip="ball_link", ball_bar=50)
    assert plan.to_dict() == expected
    assert plan.placement_count == len(expected["placements"])
    joints, _ = plan.readings(0)
    assert joints.shape[1] == 7


def test_import_readings_of_instrument_stations_equals_cli():
    options = ["--machine", "plans/tracker-arm6-2stations.json", "--unit", "deg",
               "--point-unit", "m"]
    expected = cli_json("import-readings", "plans/tracker-arm6", *options, "--instrument", "0.02",
                        "-o", "-")
    plan = artcal.import_readings("plans/tracker-arm6", machine="plans/tracker-arm6-2stations.json",
                                  unit="deg", point_unit="m", instrument=0.02)
    assert plan.to_dict() == expected
    assert expected["noise"]["probe"] == "estimate"
    assert [p["name"] for p in expected["placements"]] == ["station1", "station2"]


def test_import_readings_of_pose_stations_equals_cli(tmp_path):
    # A 6-DOF tracker's export: per station the joints, then x, y, z and the rotation vector.
    simulated = tmp_path / "sim.json"
    run_cli("simulate", "plans/tracker-arm6-pose.json", "--truth", "plans/tracker-arm6/truth.json",
            "--seed", "5", "-o", str(simulated))
    plan = json.loads(simulated.read_text())
    (tmp_path / "machine.json").write_text(json.dumps(plan["machine"]))
    folder = tmp_path / "poses"
    folder.mkdir()
    for j, station in enumerate(plan["placements"]):
        rows = ["j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg,x_mm,y_mm,z_mm,rx_rad,ry_rad,rz_rad"]
        for m in station["measurements"]:
            x = m["point"]
            values = m["joints"] + x[:3] + [math.radians(w) for w in x[3:]]
            rows.append(",".join(repr(v) for v in values))
        (folder / f"station{j + 1}.csv").write_text("\n".join(rows) + "\n")
    machine = str(tmp_path / "machine.json")
    expected = cli_json("import-readings", str(folder), "--machine", machine, "--instrument",
                        "0.02", "--instrument-angle", "0.005", "-o", "-")
    imported = artcal.import_readings(folder, machine=machine, instrument=0.02,
                                      instrument_angle=0.005)
    assert imported.to_dict() == expected
    assert expected["artifacts"]["instrument"]["measures"] == "pose"
    assert expected["placements"][0]["measurements"][0]["orientation_unit"] == "rad"
    # Without instrument_angle the pose rows are refused with the command line's message.
    message = cli_error("import-readings", str(folder), "--machine", machine, "--instrument",
                        "0.02", "-o", "-")
    assert "give --instrument-angle" in message
    with pytest.raises(artcal.InputError) as raised:
        artcal.import_readings(folder, machine=machine, instrument=0.02)
    assert str(raised.value) == message


def test_import_readings_written_equals_cli_file(tmp_path):
    cli_out, py_out = tmp_path / "cli.json", tmp_path / "py.json"
    args = ["--probe", "0.12", "--encoder", "0.005", "--u-length", "0.001"]
    run_cli("import-readings", f"{MUKCA}/panda_2/back_left", "--machine", MACHINE,
            "--ball-bar", "50", *args, "-o", str(cli_out))
    plan = artcal.import_readings(f"{MUKCA}/panda_2/back_left", machine=MACHINE, ball_bar=50,
                                  probe=0.12, encoder=0.005, u_length=0.001, output=py_out)
    assert py_out.read_bytes() == cli_out.read_bytes()
    assert plan.evaluate() == cli_json("evaluate", str(cli_out), "--json")


@pytest.mark.parametrize("folder, options, kwargs", [
    ("tests/data/no-such-folder", [*CHAIN, "--ball-bar", "50"],
     dict(urdf=URDF, base="panda_link0", tip="ball_link", ball_bar=50)),
    (f"{MUKCA}/panda_2", ["--urdf", URDF, "--base", "panda_link0", "--tip", "no_link",
                          "--ball-bar", "50"],
     dict(urdf=URDF, base="panda_link0", tip="no_link", ball_bar=50)),
    (f"{MUKCA}/panda_2", [*CHAIN, "--ball-bar", "50", "--unit", "deg", "--keep-limits"],
     dict(urdf=URDF, base="panda_link0", tip="ball_link", ball_bar=50, unit="deg",
          keep_limits=True)),
])
def test_import_readings_bad_input_raises_the_cli_message(folder, options, kwargs):
    expected = cli_error("import-readings", folder, *options, "-o", "-")
    with pytest.raises(artcal.InputError) as raised:
        artcal.import_readings(folder, **kwargs)
    assert str(raised.value) == expected


def test_import_readings_warnings_are_the_cli_warnings():
    done = run_cli("import-readings", f"{MUKCA}/panda_2", *CHAIN, "--ball-bar", "50", "--unit",
                   "deg", "-o", "-")
    expected = [line[len("warning: "):] for line in done.stderr.splitlines()
                if line.startswith("warning: ")]
    plan = artcal.import_readings(f"{MUKCA}/panda_2", urdf=URDF, base="panda_link0",
                                  tip="ball_link", ball_bar=50, unit="deg")
    assert expected and plan.warnings == expected
    assert plan.to_dict() == json.loads(done.stdout)


@pytest.mark.parametrize("options, kwargs", [
    (["--ball-bar", "50"], dict(ball_bar=50)),
    (CHAIN, dict(urdf=URDF, base="panda_link0", tip="ball_link")),
    (["--urdf", URDF, "--ball-bar", "50"], dict(urdf=URDF, ball_bar=50)),
])
def test_import_readings_missing_options_raise_the_cli_line(options, kwargs):
    done = run_cli("import-readings", f"{MUKCA}/panda_2", *options, expect=(2,))
    with pytest.raises(artcal.InputError) as raised:
        artcal.import_readings(f"{MUKCA}/panda_2", **kwargs)
    # The command line's one line without its "error: " and its pointer to --help.
    line = done.stderr.splitlines()[0]
    assert line.startswith("error: ") and line.endswith(" (artcal --help; artcal COMMAND --help)")
    assert str(raised.value) == line[len("error: "):-len(" (artcal --help; artcal COMMAND --help)")]


def test_export_urdf_equals_cli_bytes(tmp_path):
    cli_out, py_out = tmp_path / "cli.urdf", tmp_path / "py.urdf"
    cli_warnings = run_cli("export-urdf", "--machine", MACHINE, "--urdf", URDF, "-o",
                           str(cli_out)).stderr
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        text = artcal.export_urdf(MACHINE, URDF, output=py_out)
    assert py_out.read_bytes() == cli_out.read_bytes()
    assert text == cli_out.read_text()
    assert ["warning: " + str(w.message) for w in caught] == cli_warnings.splitlines()
    # The machine as a dict (calibrate().machine's form) gives the same file; and the exported
    # chain's forward kinematics is the machine's: imported back, it is the same chain.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert artcal.export_urdf(json.loads(open(MACHINE).read()), URDF) == text
    assert (artcal.import_urdf(py_out, "panda_link0", "ball_link")
            == cli_json("import-urdf", str(cli_out), "--base", "panda_link0", "--tip",
                        "ball_link"))


def test_export_urdf_bad_machine_raises_the_cli_message(tmp_path):
    machine = tmp_path / "machine.json"
    machine.write_text(json.dumps({"model": "planar2r", "parameters": {"l1": 1}}))
    expected = cli_error("export-urdf", "--machine", str(machine), "--urdf", URDF, "-o",
                         str(tmp_path / "out.urdf"))
    with pytest.raises(artcal.InputError) as raised:
        artcal.export_urdf(machine, URDF, output=tmp_path / "py.urdf")
    assert str(raised.value) == expected
    assert not (tmp_path / "py.urdf").exists()


def test_export_urdf_never_replaces_its_input(tmp_path):
    urdf = tmp_path / "panda.urdf"
    urdf.write_text(open(URDF).read())
    expected = cli_error("export-urdf", "--machine", MACHINE, "--urdf", str(urdf), "-o",
                         str(urdf))
    with pytest.raises(artcal.InputError) as raised:
        artcal.export_urdf(MACHINE, urdf, output=urdf)
    assert str(raised.value) == expected


def test_import_urdf_with_several_tips_equals_cli():
    # One machine, both arms of the test humanoid from its left sole (docs/urdf.md): the shared
    # leg and torso joints once, each tip's path named; the same document as the command's.
    humanoid = "tests/data/urdf/humanoid-small.urdf"
    tips = ["gripper_left_base_link", "gripper_right_base_link"]
    machine = artcal.import_urdf(humanoid, "left_sole_link", tips)
    assert machine == cli_json("import-urdf", humanoid, "--base", "left_sole_link",
                               "--tip", tips[0], "--tip", tips[1])
    assert len(machine["joints"]) == 19
    assert [t["name"] for t in machine["tips"]] == tips
    assert machine["joints"][0] == {**machine["joints"][0], "reversed": True}
    assert "tips" not in artcal.import_urdf(humanoid, "left_sole_link", tips[0])


def test_exports_equal_cli_bytes_and_json(tmp_path):
    """export_xacro, export_ur and export_linuxcnc write the command's bytes and return its --json
    summary (docs/exports.md)."""
    ur5 = "tests/data/ur5-tracker/ur5.machine.json"
    trunnion = tmp_path / "trunnion.json"
    trunnion.write_text(json.dumps(json.load(open("plans/machine-tool-trunnion/machine.json"))))
    cases = [
        (["export-xacro", "--machine", MACHINE, "--urdf", URDF],
         lambda out: artcal.export_xacro(MACHINE, URDF, output=out)),
        (["export-ur", "--machine", ur5], lambda out: artcal.export_ur(ur5, output=out)),
        (["export-linuxcnc", "--machine", str(trunnion), "--pivot", "1", "2", "3"],
         lambda out: artcal.export_linuxcnc(str(trunnion), [1, 2, 3], output=out)),
    ]
    for k, (arguments, export) in enumerate(cases):
        cli_out, py_out = tmp_path / f"cli{k}", tmp_path / f"py{k}"
        summary = json.loads(run_cli(*arguments, "-o", str(cli_out), "--json").stdout)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            text, py_summary = export(py_out)
        assert py_out.read_bytes() == cli_out.read_bytes(), arguments[0]
        assert text == cli_out.read_text()
        assert py_summary == summary, arguments[0]
    with pytest.raises(artcal.InputError):
        artcal.export_linuxcnc(ur5, [0, 0, 0])
