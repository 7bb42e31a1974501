#pragma once
// The plausible minimum (docs/calibration.md, "Which minimum"). With `"calibrate": "identifiable"`
// the rank rule keeps, greedily in the listed order, one parameter of every set that moves the
// tip alike at the nominal parameters. The parameter it keeps may describe a small change of the
// machine only through a large correction: a joint frame's rotation about its own axis (a URDF
// chain's pitch when the roll is 90 deg, or the joint's offset) moves a ball that sits a few mm
// off that axis on a circle, so a ball 7 mm off the axis of a Panda's last joint is fitted as a
// 141.8 deg turn (polar coordinates: an angle and a radius) where the frame's x and y (Cartesian
// ones) describe the same machine with corrections of a few mm. Both charts reach the same
// minimum of the readings' cost; only the second is a machine a metrologist believes.
//
// When the converged fit's corrections are flagged (implausibleCorrections, corrections.hpp),
// calibrateReadings searches for a plausible minimum: the flagged parameters are moved to the end
// of the rank rule's order, the rule is run again at the nominal parameters (other parameters
// now take their directions, where any can) and the calibration is repeated from nominal. A fit
// whose corrections are flagged in turn has those moved too (at most kMaxDemotionRounds rounds).
// A converged fit is an alternative when it fits the readings as well
// (its chi2 at the flagged fit's probe noise exceeds the flagged chi2 by at most
// m + 3 sqrt(2 max(1, m)) times the flagged fit's max(1, chi2/dof), m the parameters it holds
// more: the mean plus 3 standard deviations of a chi-square of m degrees of freedom, so a minimum
// of the same cost and not a worse fit that looks better). The search stops at the first
// alternative with no flagged correction, which is chosen, or at one that fits worse. Otherwise
// the flagged fit stands, with its warnings, and the search says why: a correction the readings
// need (a link 24 mm longer than nominal) is no chart's artefact. An alternative that only
// trades flagged corrections for others is not taken (on the Gen3 lite trained on `front`, two
// flags for three moved a held-out distance error by 0.023 mm).
// Either way the calibration carries both (MinimumChoice): the table and JSON show the flagged
// corrections, the chi2 of each fit and which was taken. The search runs only when a fit is
// flagged: a plausible calibration costs nothing more.

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "artcal/calibration/corrections.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

struct Calibration;

/// Rounds of moving flagged parameters to the end of the order (each one calibration).
inline constexpr int kMaxDemotionRounds = 4;

/// A converged fit of the readings: its kept set, estimate and cost.
struct MinimumFit {
  std::vector<int> calibrated;  ///< the kept set, model parameter indices
  Eigen::VectorXd parameters;   ///< full parameter vector, internal units
  double chi2 = 0.0;
  int dof = 0;
  double chi2_per_dof = 0.0;
  double probe = 0.0;                          ///< the probe noise it was whitened with, mm
  std::vector<ImplausibleCorrection> flagged;  ///< its corrections the rule flags
  /// An alternative's chi2 (at the flagged fit's probe noise) minus the flagged fit's, in units
  /// of the flagged fit's max(1, chi2/dof), and the largest increase the same minimum allows.
  double chi2_increase = 0.0;
  double chi2_allowance = 0.0;
};

/// Which minimum calibrateReadings took when the plain fit's corrections were flagged.
struct MinimumChoice {
  /// The calibration is `alternative` (no flagged correction, the same cost), not the plain fit
  /// `flagged`.
  bool alternative_chosen = false;
  MinimumFit flagged;  ///< the plain path's converged fit, whose corrections are flagged
  /// The chosen alternative, or else the last one tried; absent when none ran.
  std::optional<MinimumFit> alternative;
  std::vector<int> demoted;  ///< moved to the end of the rank rule's order, in that order
  /// Calibrations the search ran (each its own rank rule, weak rounds and noise fits); the
  /// result's summary counts the chosen calibration's own work only.
  int fits = 0;
  std::string reason;  ///< one sentence: which minimum was taken and why
};

struct CalibrationRun;  // calibrate_readings.hpp

/// Calibrates a plan as listed (rank rule, weak directions, noise): calibrateReadings' plain path,
/// which returns the plan as it decided (kept set, weak parameters, noise used) with its fit.
using CalibrateAsListed = std::function<CalibrationRun(const Plan&)>;

/// The search above. `before`: the plan as loaded; `fit`: the plain path's run on it. Returns the
/// chosen run (the plain one or an alternative, each with the plan as its calibration decided
/// it); records the choice in the calibration's `minimum` whenever `fit` was flagged. No plan is
/// changed: each alternative is calibrated from its own copy of `before`.
CalibrationRun choosePlausibleMinimum(const Plan& before, CalibrationRun fit,
                                      const CalibrateAsListed& calibrate);

}  // namespace artcal
