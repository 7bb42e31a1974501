"""calibrate()'s document carries the held-out model choice of `calibrate --json` (issue 29):
the candidates, predicted and observed held-out errors side by side, and the rule that chose."""

import artcal

MUKCA = "tests/data/mukca/mukca"
URDF = f"{MUKCA}/urdf/panda.urdf"


def test_calibrate_reports_the_held_out_choice():
    plan = artcal.import_readings(f"{MUKCA}/panda_2", urdf=URDF, base="panda_link0",
                                  tip="ball_link", ball_bar=50)
    result = plan.calibrate()
    choice = result["model_choice"]
    assert choice["rule"] == "leave-one-placement-out"
    assert choice["folds"] == plan.placement_count
    candidates = choice["candidates"]
    assert candidates[0]["held_at_nominal"] is None
    assert candidates[0]["size"] == choice["rank_rule_size"]
    # Nested smaller sets, then (where the weak-direction rule held any) the rank rule's set with
    # them calibrated again.
    nested = [c for c in candidates if not c["restored"]]
    assert [c["size"] for c in nested] == list(
        range(choice["rank_rule_size"], choice["rank_rule_size"] - len(nested), -1))
    for c in candidates:
        if c["restored"]:
            assert c["size"] == choice["rank_rule_size"] + len(c["restored"])
            assert c["held_at_nominal"] is None
    assert sum(c["chosen"] for c in candidates) == 1
    chosen = next(c for c in candidates if c["chosen"])
    # The calibrated parameters are the chosen candidate's.
    assert len(result["parameters"]) == chosen["size"]
    assert (choice["decided_by"] == "rank rule") == (chosen is candidates[0])
    for c in candidates:
        assert len(c["observed_per_fold"]) == plan.placement_count
        assert c["predicted"] > 0 and c["observed"] > 0
        # Probe noise only (import-readings' 0.1 mm): the rms is sqrt(chi2/dof) times it.
        assert abs(c["observed_rms_mm"] - 0.1 * c["observed"] ** 0.5) < 1e-12
