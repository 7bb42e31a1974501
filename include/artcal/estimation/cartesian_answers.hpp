#pragma once
// What a Cartesian CMM's plan answers about its error functions (docs/models.md section 4;
// error_functions.hpp computes it): plain result types, so that the report (cartesian_report.hpp)
// includes no computation. Internal units (mm, rad).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/model/axis_error_functions.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// One error function of one axis along that axis.
struct ErrorFunctionProfile {
  int axis = 0;
  AxisError error = AxisError::Tx;
  std::string name;     ///< "x.ty"
  std::string meaning;  ///< "straightness in y"
  bool rotation = false;
  std::vector<int> calibrated_degrees;
  std::vector<int> fixed_degrees;  ///< not calibrated (kept at nominal)
  std::vector<double> position;    ///< axis reading u, mm
  std::vector<double> value;       ///< e(u) at the given parameters, internal units (mm, rad)
  std::vector<double> u;           ///< predicted standard uncertainty of e(u), internal units
};

/// A frame rotation the placements absorb.
struct AbsorbedRotation {
  Eigen::Vector3d axis;               ///< unit
  std::vector<std::string> involves;  ///< the squareness coefficients it moves
};

/// The error-function layout of the plan's model (Mechanism::axisErrorFunctions(): a Cartesian
/// CMM's), or null for models without one.
const AxisErrorFunctions* axisErrorFunctionsOf(const Plan& plan);

/// What check and evaluate answer for a Cartesian CMM; empty for other models.
struct CartesianAnswers {
  std::vector<AbsorbedRotation> absorbed;
  std::vector<std::string> held_by_frame;  ///< per absorbed rotation, the parameter it fixes
  struct Unseparated {
    std::string function;  ///< "z.rx"
    std::string meaning;   ///< "tilt about x"
    std::vector<int> degrees;
  };
  std::vector<Unseparated> unseparated;
  std::vector<ErrorFunctionProfile> profiles;  ///< evaluate only (needs V_p)
};

/// The error functions along the axes, as `artcal report` draws them (errorFunctionBands).
struct ErrorFunctionBands {
  bool calibrated = false;  ///< profiles at a calibrated estimate (else at nominal)
  std::vector<ErrorFunctionProfile> profiles;
  std::vector<ErrorFunctionProfile> truth;  ///< the same functions at the truth; empty: none
};

}  // namespace artcal
