"""docs/python.md's worked example: calibrate the MUKCa Franka Panda from its CSV files
(artcal.import_readings, as `artcal import-readings`), verify the calibrated machine on the
position it never saw, export the calibrated URDF, and plot the held-out deviations (matplotlib
only if installed). Run from the repository root:

  PYTHONPATH=build/python /usr/bin/python3 docs/examples/panda_python.py
"""

import tempfile
from pathlib import Path

import numpy as np

import artcal

MUKCA = "tests/data/mukca/mukca"  # MIT licence: tests/data/mukca/mukca/LICENSE
ROBOT = dict(urdf=f"{MUKCA}/urdf/panda.urdf", base="panda_link0", tip="ball_link",
             ball_bar=50, probe=0.12, encoder=0.005)

# 1. The plans: one placement per sub-folder of CSV files (joint angles in rad, one posture per
#    row), the chain imported from the URDF (mm, deg). `high` is left out (its socket moved
#    during the run, see the data's README); `back_left` is held out for verification.
everything = artcal.import_readings(f"{MUKCA}/panda_2", **ROBOT)
document = everything.to_dict()
document["placements"] = [p for p in document["placements"]
                          if p["name"] not in ("high", "back_left")]
training = artcal.Plan.from_dict(document, source="training")
held_out = artcal.import_readings(f"{MUKCA}/panda_2/back_left", **ROBOT)
joints, features = training.readings(0)
print(f"training: {training.placement_count} placements; the first: {joints.shape[0]} readings "
      f"of {joints.shape[1]} joints (deg), features {sorted(set(features.tolist()))}")

# 2. Calibrate (GIL released): the same document as `artcal calibrate --json`.
result = training.calibrate()
print(f"converged: {result.converged}, chi2/dof = {result['chi2_per_dof']:.3f}")
u = np.sqrt(np.diag(result.covariance))
worst = int(np.argmax(u))
print(f"{len(result.estimates)} parameters; least determined: {result.parameter_names[worst]} "
      f"u = {u[worst]:.4f}")

# 3. Verify on the held-out position with the calibrated machine (and its covariance).
verified = held_out.verify(result.machine)["verify"]
nominal = held_out.verify()["verify"]
print(f"held-out spread RMS: nominal {nominal['spread_rms']:.3f} mm -> calibrated "
      f"{verified['spread_rms']:.3f} mm (predicted {verified['predicted_spread_rms']:.3f} mm)")

# 4. The calibrated URDF (as `artcal export-urdf`): written atomically, warnings as Python's.
with tempfile.TemporaryDirectory() as folder:
    urdf = artcal.export_urdf(result.machine, ROBOT["urdf"], output=Path(folder, "calibrated.urdf"))
    print(f"calibrated URDF: {len(urdf.splitlines())} lines")


def feature_spread(verification):
    """Each held-out feature's spread RMS (mm)."""
    return [f["spread_rms"] for p in verification["placements"] for f in p["features"]]


# 5. Plot the held-out features' spread, nominal against calibrated (optional).
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib not installed: no figure")
else:
    x = np.arange(len(feature_spread(nominal)))
    plt.bar(x - 0.2, feature_spread(nominal), 0.4, label="nominal")
    plt.bar(x + 0.2, feature_spread(verified), 0.4, label="calibrated")
    plt.xticks(x, [f"back_left socket {k}" for k in x])
    plt.ylabel("spread RMS (mm)")
    plt.legend()
    plt.tight_layout()
    plt.savefig("panda-held-out.png")
    print("figure: panda-held-out.png")
