#pragma once
// The operator's procedure as printed (`artcal procedure`, docs/plan-format.md "artcal
// procedure"): JSON, table, CSV and the report's HTML section of a Procedure that
// planning/procedure.hpp computed (operatorProcedure: poses, inverse kinematics).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "artcal/plan/plan.hpp"
#include "artcal/planning/procedure_result.hpp"

namespace artcal {

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
