#pragma once
// A mechanism with its nominal parameters, the calibrated subset and its joint limits: the
// immutable model every numerical module reads (internal units: mm, rad).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "artcal/model/mechanism.hpp"

namespace artcal {

/// A mechanism with its nominal parameters, the calibrated subset and its joint limits.
struct Machine {
  MechanismPtr mechanism;
  Eigen::VectorXd nominal;      ///< every parameter of the model, internal units
  std::vector<int> calibrated;  ///< indices into nominal, in the plan's order
  /// `"calibrate": "identifiable"`: `calibrated` lists the candidates in preferred order until
  /// the plan's readings decide (resolveCalibratedSet, estimation/identifiability.hpp).
  bool calibrate_identifiable = false;
  std::vector<std::array<double, 2>> joint_limits;  ///< per joint, internal units
  /// The limits are the plan's (`joint_limits`, or the model's own such as a CMM's axis ranges),
  /// so a reading outside them is refused; the default revolute range only wraps.
  bool limits_stated = false;
  /// `machine.prior` (docs/plan-format.md): the standard deviation of each parameter's nominal
  /// value (its tolerance), internal units, one per parameter of the model; 0 (or an empty
  /// vector) means no prior. Enters N_red as Sigma_p0^-1 (estimation/normal_matrix.hpp).
  Eigen::VectorXd prior_sigma;

  int dimension() const { return mechanism->dimension(); }
  int jointCount() const { return mechanism->jointCount(); }
  int calibratedCount() const { return static_cast<int>(calibrated.size()); }
  const ParameterInfo& calibratedInfo(int k) const {
    return mechanism->parameters()[calibrated[k]];
  }
  /// The calibrated subset of a full parameter vector.
  Eigen::VectorXd calibratedValues(const Eigen::VectorXd& full) const;
  /// `full` with the calibrated subset replaced by `values`.
  Eigen::VectorXd withCalibrated(const Eigen::VectorXd& full, const Eigen::VectorXd& values) const;
  bool withinLimits(const Eigen::VectorXd& q) const;
};

}  // namespace artcal
