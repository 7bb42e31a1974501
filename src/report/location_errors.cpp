#include "artcal/report/location_errors.hpp"

#include <sstream>
#include <vector>

#include "artcal/core/units.hpp"
#include "artcal/report/text_format.hpp"

namespace artcal {

namespace {

using nlohmann::json;
using report_text::format;

constexpr double kMicroradiansPerRadian = 1e6;

// E_<error>0<axis>: the axis letter and the error letter; false for other names (L).
bool splitName(const std::string& name, char& error, char& axis) {
  if (name.size() != 5 || name.compare(0, 2, "E_") != 0 || name[3] != '0') return false;
  error = name[2];
  axis = name[4];
  return true;
}

// "offset" (X, Y, Z of a rotary axis), "zero" (a rotary axis about itself), "squareness"
// (a linear axis), "orientation".
std::string kindOf(char error, char axis) {
  const bool linear_axis = axis == 'X' || axis == 'Y' || axis == 'Z';
  if (linear_axis) return "squareness";
  if (error == 'X' || error == 'Y' || error == 'Z') return "offset";
  return error == axis ? "zero" : "orientation";
}

struct AxisRow {
  char axis;
  double offset[3] = {0.0, 0.0, 0.0};       // X, Y, Z, mm
  double orientation[3] = {0.0, 0.0, 0.0};  // about A, B, C, deg
};

std::vector<AxisRow> controllerRows(const Plan& plan, const Eigen::VectorXd& parameters) {
  std::vector<AxisRow> rows;
  const auto& infos = plan.machine.mechanism->parameters();
  for (std::size_t i = 0; i < infos.size(); ++i) {
    char error = 0, axis = 0;
    if (!splitName(infos[i].name, error, axis)) continue;
    AxisRow* row = nullptr;
    for (AxisRow& r : rows)
      if (r.axis == axis) row = &r;
    if (!row) {
      rows.push_back({axis});
      row = &rows.back();
    }
    const double value = toFileUnit(infos[i].quantity, parameters[static_cast<int>(i)]);
    if (error >= 'X' && error <= 'Z')
      row->offset[error - 'X'] = value;
    else if (error >= 'A' && error <= 'C')
      row->orientation[error - 'A'] = value;
  }
  return rows;
}

}  // namespace

json locationErrorsToJson(const Plan& plan, const ParameterCovariance& covariance,
                          const Eigen::VectorXd* estimate) {
  const Machine& machine = plan.machine;
  json out = json::array();
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    const ParameterInfo& info = machine.calibratedInfo(k);
    const bool angle = info.quantity == Quantity::Angle;
    const double u = covariance.u[k];
    char error = 0, axis = 0;
    const bool located = splitName(info.name, error, axis);
    json row = {{"name", info.name},
                {"axis", located ? std::string(1, axis) : std::string("tool")},
                {"kind", located ? kindOf(error, axis) : std::string("tool length")},
                {"u", toFileUnit(info.quantity, u)},
                {"unit", std::string(unitName(info.quantity))},
                {"u_fine", angle ? u * kMicroradiansPerRadian : u * 1e3},
                {"unit_fine", angle ? "urad" : "um"},
                {"confounding_index", covariance.confounding[k]}};
    if (estimate) {
      const double value = (*estimate)[machine.calibrated[static_cast<std::size_t>(k)]];
      row["estimate"] = toFileUnit(info.quantity, value);
      row["estimate_fine"] = angle ? value * kMicroradiansPerRadian : value * 1e3;
    }
    out.push_back(row);
  }
  return out;
}

std::string locationErrorTable(const Plan& plan, const ParameterCovariance& covariance,
                               const Eigen::VectorXd* estimate) {
  std::ostringstream out;
  out << "\nLocation errors (ISO 230-7)" << (estimate ? ", estimate and u" : ", u")
      << "; F = u / u(alone), F <= 2: well separated\n";
  out << "  name    axis  kind          " << (estimate ? "      estimate            " : "")
      << "          u                       F\n";
  for (const json& row : locationErrorsToJson(plan, covariance, estimate)) {
    const bool angle = row["unit"] == "deg";
    out << format("  %-6s  %-4s  %-12s", row["name"].get<std::string>().c_str(),
                  row["axis"].get<std::string>().c_str(), row["kind"].get<std::string>().c_str());
    if (estimate) {
      out << format(angle ? "  %+11.6f deg %+8.1f urad" : "  %+11.4f mm  %+8.1f um  ",
                    row["estimate"].get<double>(), row["estimate_fine"].get<double>());
    }
    out << format(angle ? "  %10.6f deg %7.2f urad" : "  %10.4f mm  %7.2f um  ",
                  row["u"].get<double>(), row["u_fine"].get<double>());
    out << format("  %6.2f\n", row["confounding_index"].get<double>());
  }
  return out.str();
}

json controllerTableToJson(const Plan& plan, const Eigen::VectorXd& parameters) {
  json rows = json::array();
  for (const AxisRow& r : controllerRows(plan, parameters)) {
    rows.push_back({{"axis", std::string(1, r.axis)},
                    {"offset_mm", {{"X", r.offset[0]}, {"Y", r.offset[1]}, {"Z", r.offset[2]}}},
                    {"orientation_deg",
                     {{"A", r.orientation[0]}, {"B", r.orientation[1]}, {"C", r.orientation[2]}}}});
  }
  const int l = plan.machine.mechanism->parameterIndex("L");
  json out = {{"axes", rows},
              {"sign",
               "actual location of each axis in the machine frame (ISO 230-7), "
               "docs/five-axis.md"}};
  if (l >= 0) out["tool_length_mm"] = parameters[l];
  return out;
}

std::string controllerTable(const Plan& plan, const Eigen::VectorXd& parameters) {
  std::ostringstream out;
  out << "\nController table (actual axis locations, ISO 230-7 sign; docs/five-axis.md)\n";
  out << "  axis      X mm        Y mm        Z mm       A deg       B deg       C deg\n";
  for (const AxisRow& r : controllerRows(plan, parameters)) {
    out << format("  %c     %+10.4f  %+10.4f  %+10.4f  %+10.6f  %+10.6f  %+10.6f\n", r.axis,
                  r.offset[0], r.offset[1], r.offset[2], r.orientation[0], r.orientation[1],
                  r.orientation[2]);
  }
  const int l = plan.machine.mechanism->parameterIndex("L");
  if (l >= 0) out << format("  tool length L = %.4f mm\n", parameters[l]);
  return out.str();
}

}  // namespace artcal
