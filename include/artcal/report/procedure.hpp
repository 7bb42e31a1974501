#pragma once
// The operator's procedure (`artcal procedure`, docs/plan-format.md "artcal procedure"): the plan
// as the sheet a person follows at the machine. For each placement, in the plan's order (the
// measuring order), the artifact and its pose (centre, direction, roll); for each reading the
// feature, its posture (the k-th reading of that feature in the placement) and the target joint
// values that put the probe on the feature at that pose on the nominal machine.
//
// The pose is the plan's `pose`, or, when the plan gives none, the rigid fit of the artifact to
// the nominal forward kinematics of the readings (the fit the evaluator uses, docs/method.md
// section 1). The targets are the inverse kinematics of each placed feature started from the
// plan's reading, so that each reading keeps its posture (elbow branch, arm configuration); for a
// planned plan they are its readings, for a plan of real readings the nominal joints nearest them.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
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
  std::vector<ProcedureReading> readings;
};

struct Procedure {
  std::vector<ProcedurePlacement> placements;
};

/// The procedure of a plan with readings. Throws RunError naming the reading when no joint values
/// within the limits put the probe on a placed feature.
Procedure operatorProcedure(const Plan& plan);

/// `artcal procedure --json`: lengths in mm, angles in deg (joint units in `joint_units`).
nlohmann::json procedureToJson(const Plan& plan, const Procedure& procedure);
/// The table `artcal procedure` prints.
std::string procedureTable(const Plan& plan, const Procedure& procedure);
/// `artcal procedure --csv`: one row per reading, units in the header.
std::string procedureCsv(const Plan& plan, const Procedure& procedure);
/// One text field of procedureCsv: RFC 4180 quoting, a leading =, +, -, @ neutralised with '.
std::string csvTextField(const std::string& text);
/// The "Procedure" section of the HTML report: per placement a block with the pose, a drawing of
/// the mechanism in each posture (Mechanism::skeleton) and the table of readings.
std::string procedureHtml(const Plan& plan, const Procedure& procedure);

}  // namespace artcal
