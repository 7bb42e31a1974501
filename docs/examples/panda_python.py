"""docs/python.md's worked example: calibrate the MUKCa Panda from its CSV files, verify the
calibrated machine on the positions it never saw, plot the held-out deviations (matplotlib only
if installed). Run from the repository root:

  PYTHONPATH=build/python /usr/bin/python3 docs/examples/panda_python.py
"""

import numpy as np

import artcal

# 1. The plan: the URDF chain (mm, deg) and 8 tool positions whose readings are CSV files of
#    tests/data/mukca (radians, one posture per row).
plan = artcal.Plan("plans/panda-8positions.json")
joints, features = plan.readings(0)
print(f"{plan.name}: {plan.placement_count} placements; the first: {joints.shape[0]} readings "
      f"of {joints.shape[1]} joints (deg), features {sorted(set(features))}")

# 2. Calibrate (GIL released): the same document as `artcal calibrate --json`.
result = plan.calibrate()
print(f"converged: {result.converged}, chi2/dof = {result['chi2_per_dof']:.3f}")
worst = np.argmax(np.sqrt(np.diag(result.covariance)))
print(f"{len(result.estimates)} parameters; least determined: {result.parameter_names[worst]} "
      f"u = {np.sqrt(result.covariance[worst, worst]):.4f}")

# 3. Verify on the held-out positions with the calibrated machine (and its covariance).
held_out = artcal.Plan("plans/panda-others.json")
verified = held_out.verify(result.machine)["verify"]
nominal = held_out.verify()["verify"]
print(f"held-out spread RMS: nominal {nominal['spread_rms']:.3f} mm -> calibrated "
      f"{verified['spread_rms']:.3f} mm (predicted {verified['predicted_spread_rms']:.3f} mm)")



def placement_spread(placement):
    """RMS over a placement's features of each feature's spread (mm)."""
    return float(np.sqrt(np.mean([f["spread_rms"] ** 2 for f in placement["features"]])))


# 4. Plot the held-out placements' spread, nominal against calibrated (optional).
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib not installed: no figure")
else:
    names = [p.get("name", str(i)) for i, p in enumerate(verified["placements"])]
    x = np.arange(len(names))
    plt.bar(x - 0.2, [placement_spread(p) for p in nominal["placements"]], 0.4, label="nominal")
    plt.bar(x + 0.2, [placement_spread(p) for p in verified["placements"]], 0.4, label="calibrated")
    plt.xticks(x, names, rotation=30)
    plt.ylabel("spread RMS (mm)")
    plt.legend()
    plt.tight_layout()
    plt.savefig("panda-held-out.png")
    print("figure: panda-held-out.png")
