#include "artcal/report/procedure.hpp"
#include "artcal/report/text_format.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string_view>

#include "artcal/report/report.hpp"

namespace artcal {

using nlohmann::json;

namespace {

using report_text::fixed;

std::string vectorText(const Eigen::VectorXd& v, int decimals) {
  std::string out = "[";
  for (int i = 0; i < v.size(); ++i) out += (i ? ", " : "") + fixed(v[i], decimals);
  return out + "]";
}

std::string jointUnit(const Machine& machine, int joint) {
  return std::string(unitName(jointQuantity(machine.mechanism->jointKind(joint))));
}

std::string poseText(const Plan& plan, const ProcedurePlacement& placement) {
  const Pose& pose = placement.pose;
  std::string out = "centre " + vectorText(pose.center, 3) + " mm";
  const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
  if (artifact.translatesOnly()) {  // a sphere or a table ball: its centre is all there is
    out += std::string(" (") + artifact.kind().centre + " in the workpiece frame)";
  } else if (plan.machine.dimension() == 2) {
    out += ", angle " + fixed(radToDeg(pose.angle), 3) + " deg";
  } else {
    out += ", direction " + vectorText(pose.direction.normalized(), 4) + ", roll " +
           fixed(radToDeg(pose.roll), 3) + " deg";
  }
  return out + (placement.pose_from_plan ? "" : " (fitted to the readings)");
}

json poseToJson(const Plan& plan, const ProcedurePlacement& placement) {
  const Pose& pose = placement.pose;
  json out = {
      {"center", std::vector<double>(pose.center.data(), pose.center.data() + pose.center.size())}};
  if (plan.machine.dimension() == 2) {
    out["angle"] = radToDeg(pose.angle);
  } else {
    const Eigen::Vector3d d = pose.direction.normalized();
    out["direction"] = {d.x(), d.y(), d.z()};
    out["roll"] = radToDeg(pose.roll);
  }
  out["source"] = placement.pose_from_plan ? "plan" : "readings";
  return out;
}

}  // namespace

json procedureToJson(const Plan& plan, const Procedure& procedure) {
  const Machine& machine = plan.machine;
  json units = json::array();
  for (int i = 0; i < machine.jointCount(); ++i) units.push_back(jointUnit(machine, i));
  json placements = json::array();
  int readings_total = 0;
  for (std::size_t j = 0; j < procedure.placements.size(); ++j) {
    const ProcedurePlacement& placement = procedure.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    json readings = json::array();
    for (std::size_t k = 0; k < placement.readings.size(); ++k) {
      const ProcedureReading& r = placement.readings[k];
      readings.push_back({{"reading", k},
                          {"feature", r.feature},
                          {"posture", r.posture},
                          {"stylus", r.stylus},
                          {"position", std::vector<double>(r.position.data(),
                                                           r.position.data() + r.position.size())},
                          {"joints", jointsToFile(machine, r.target)},
                          {"planned_offset", finiteOrNull(r.planned_offset)}});
      ++readings_total;
    }
    placements.push_back({{"placement", j},
                          {"artifact", artifact.id},
                          {"kind", artifactTypeName(artifact)},
                          {"pose", poseToJson(plan, placement)},
                          {"readings", readings}});
    if (j < plan.placements.size() && !plan.placements[j].name.empty())
      placements.back()["name"] = plan.placements[j].name;
  }
  return {{"plan", plan.name},
          {"model", machine.mechanism->modelName()},
          {"dimension", machine.dimension()},
          {"joint_units", units},
          {"readings", readings_total},
          {"placements", placements}};
}

std::string procedureTable(const Plan& plan, const Procedure& procedure) {
  const Machine& machine = plan.machine;
  const bool styli = machine.mechanism->stylusCount() > 1;
  std::ostringstream out;
  std::size_t readings = 0;
  for (const auto& placement : procedure.placements) readings += placement.readings.size();
  out << "Procedure for plan " << plan.name << ": " << procedure.placements.size()
      << " placements, " << readings << " readings, in measuring order\n";
  // A station of an instrument (docs/instruments.md): each reading is a point of its own, where
  // the tip goes (no feature, no posture).
  const auto header = [&](bool station) {
    std::string text = station ? "  reading" : "  reading  feature  posture";
    if (styli) text += "  stylus";
    text += station ? "  target position mm " : "  feature position mm";
    text += std::string(machine.dimension() == 2 ? 6 : 16, ' ');
    for (int i = 0; i < machine.jointCount(); ++i) {
      char column[48];
      std::snprintf(column, sizeof column, "%10s %-3s", jointLabel(*machine.mechanism, i).c_str(),
                    jointUnit(machine, i).c_str());
      text += column;
    }
    return text;
  };
  for (std::size_t j = 0; j < procedure.placements.size(); ++j) {
    const ProcedurePlacement& placement = procedure.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    const bool station = artifact.kind().readings_are_features;
    out << "\nPlacement " << placementLabel(plan.placements, j) << ": " << artifact.id << " ("
        << artifactTypeName(artifact) << (station ? " station" : "") << ") at "
        << poseText(plan, placement) << "\n"
        << header(station) << "\n";
    for (std::size_t k = 0; k < placement.readings.size(); ++k) {
      const ProcedureReading& r = placement.readings[k];
      char row[96];
      if (station)
        std::snprintf(row, sizeof row, "  %7zu", k);
      else
        std::snprintf(row, sizeof row, "  %7zu  %7d  %7d", k, r.feature, r.posture);
      out << row;
      if (styli) out << "  " << std::string(6 - std::to_string(r.stylus).size(), ' ') << r.stylus;
      const std::string position = vectorText(r.position, 3);
      const std::size_t width = machine.dimension() == 2 ? 25 : 35;
      out << "  " << position
          << std::string(position.size() < width ? width - position.size() : 1, ' ');
      const std::vector<double> joints = jointsToFile(machine, r.target);
      for (const double value : joints) {
        std::snprintf(row, sizeof row, "%14.4f", value);
        out << row;
      }
      out << "\n";
    }
  }
  return out.str();
}

/// A text field of the CSV (RFC 4180): quoted when it holds a comma, a quote or a line break
/// (quotes doubled), and a leading =, +, -, @, tab or carriage return neutralised by a ' so that a
/// spreadsheet shows it as text instead of running it as a formula (OWASP, CSV injection).
std::string csvTextField(const std::string& text) {
  std::string field = text;
  if (!field.empty() && std::string_view("=+-@\t\r").find(field.front()) != std::string::npos) {
    field.insert(field.begin(), '\'');
  }
  if (field.find_first_of(",\"\r\n") == std::string::npos) return field;
  std::string quoted = "\"";
  for (const char c : field) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

std::string procedureCsv(const Plan& plan, const Procedure& procedure) {
  const Machine& machine = plan.machine;
  const char* axes[] = {"x", "y", "z"};
  std::ostringstream out;
  out << "placement,artifact,reading,feature,posture,stylus";
  for (int d = 0; d < machine.dimension(); ++d) out << "," << axes[d] << "_mm";
  for (int i = 0; i < machine.jointCount(); ++i)
    out << "," << jointLabel(*machine.mechanism, i) << "_" << jointUnit(machine, i);
  out << "\n";
  char number[40];
  for (std::size_t j = 0; j < procedure.placements.size(); ++j) {
    const ProcedurePlacement& placement = procedure.placements[j];
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placement.artifact)];
    for (std::size_t k = 0; k < placement.readings.size(); ++k) {
      const ProcedureReading& r = placement.readings[k];
      out << csvTextField(placementLabel(plan.placements, j)) << "," << csvTextField(artifact.id)
          << "," << k << "," << r.feature << "," << r.posture << "," << r.stylus;
      for (int d = 0; d < r.position.size(); ++d) {
        std::snprintf(number, sizeof number, ",%.17g", r.position[d]);
        out << number;
      }
      for (const double value : jointsToFile(machine, r.target)) {
        std::snprintf(number, sizeof number, ",%.17g", value);
        out << number;
      }
      out << "\n";
    }
  }
  return out.str();
}

}  // namespace artcal
