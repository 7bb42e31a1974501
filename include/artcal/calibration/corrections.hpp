#pragma once
// Corrections a metrologist would not believe (docs/calibration.md, "Warnings"). A calibration
// may converge to corrections that only a model mismatch or a bad reading explains: a 5 deg tilt
// of a robot's base, a joint origin moved by 48 mm. Such an estimate is reported, with a
// warning naming the parameter, in calibrate, the report and export-urdf.
//
// The tolerance of a parameter, in this order:
// - its prior (machine.prior, the nominal tolerances the user stated): |correction| > 5 sigma;
// - otherwise, for a geometric length (mm): 5 % of the machine's mean link length or of the
//   parameter's own nominal value, whichever is larger; the mean link length is the length of
//   the machine's skeleton at zero joints over its number of segments;
// - for a geometric angle (deg): 2 deg.
// Coefficients in other units (a Cartesian CMM's error functions, um and um/m) have no default:
// only a prior bounds them.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/plan/plan.hpp"

namespace artcal {

struct CorrectionTolerance {
  double length_fraction = 0.05;  ///< of the mean link length (or the nominal value)
  double angle = 2.0 * kDegree;   ///< rad
  double prior_multiple = 5.0;    ///< times the parameter's prior standard deviation
};

struct ImplausibleCorrection {
  int parameter = 0;        ///< index into the model's parameters
  double correction = 0.0;  ///< estimate - nominal, internal units
  double limit = 0.0;       ///< the tolerance it exceeds, internal units
  bool from_prior = false;  ///< the limit is prior_multiple times the prior
};

/// The calibrated parameters of `machine` whose correction `p - nominal` exceeds its tolerance.
std::vector<ImplausibleCorrection> implausibleCorrections(
    const Machine& machine, const Eigen::VectorXd& nominal, const Eigen::VectorXd& p,
    const CorrectionTolerance& tolerance = {});

/// One sentence naming the parameter, its correction and the limit, in file units.
std::string describeCorrection(const Machine& machine, const ImplausibleCorrection& correction);

}  // namespace artcal
