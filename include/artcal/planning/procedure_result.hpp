#pragma once
// The operator's procedure (planning/procedure.hpp computes it, report/procedure.hpp prints it):
// plain result types, so that the report includes no computation. Readings, placements and
// postures are numbered from 0, as in the plan file.

#include <Eigen/Core>
#include <vector>

#include "artcal/plan/plan.hpp"

namespace artcal {

struct ProcedureReading {
  int feature = 0;
  int posture = 0;  ///< the k-th reading of this feature in its placement, from 0
  int stylus = 0;
  Eigen::VectorXd position;     ///< the placed feature, machine frame, mm
  Eigen::VectorXd target;       ///< joints putting the probe on `position` (internal units)
  double planned_offset = 0.0;  ///< |f(nominal, plan reading) - position|, mm
};

struct ProcedurePlacement {
  int artifact = 0;
  Pose pose;                    ///< internal units
  bool pose_from_plan = false;  ///< false: fitted to the readings
  Eigen::MatrixXd features;     ///< every feature of the artifact at `pose`, machine frame, mm
  std::vector<ProcedureReading> readings;
};

struct Procedure {
  std::vector<ProcedurePlacement> placements;
};

}  // namespace artcal
