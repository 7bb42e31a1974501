#include "artcal/report/location_errors.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "artcal/core/units.hpp"
#include "artcal/report/report.hpp"
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

std::string entryStatusName(EntryStatus status) {
  switch (status) {
    case EntryStatus::Determined:
      return "determined";
    case EntryStatus::Dropped:
      return "dropped";
    case EntryStatus::Held:
      return "held";
  }
  return "held";
}

namespace {

// "Y offset", "tilt about Y", "zero", "squareness about Z", "tool length".
std::string entryName(const std::string& name) {
  char error = 0, axis = 0;
  if (!splitName(name, error, axis)) return "tool length";
  const std::string kind = kindOf(error, axis);
  const char about = error >= 'A' && error <= 'C' ? static_cast<char>('X' + (error - 'A')) : 0;
  if (kind == "offset") return std::string(1, error) + " offset";
  if (kind == "zero") return "zero";
  if (kind == "squareness") return std::string("squareness about ") + about;
  return std::string("tilt about ") + about;
}

// The kept parameters of a dropped one's tie (the tie lists the dropped one first).
std::vector<std::string> tiedNames(const Plan& plan,
                                   const std::vector<std::pair<int, double>>& tie) {
  std::vector<std::string> names;
  const auto& infos = plan.machine.mechanism->parameters();
  for (std::size_t i = 1; i < tie.size(); ++i)
    names.push_back(infos[static_cast<std::size_t>(tie[i].first)].name);
  return names;
}

// Status and note of a parameter the calibration did not estimate.
void describeUncalibrated(const Plan& plan, int index, ControllerEntry& e) {
  e.status = EntryStatus::Held;
  e.note = "fixed by the plan's calibrate list: the plan's value, not measured here";
  if (!plan.calibrate_resolution) return;
  const CalibratedSetResolution& r = *plan.calibrate_resolution;
  for (std::size_t d = 0; d < r.dropped.size(); ++d) {
    if (r.dropped[d] != index) continue;
    e.status = EntryStatus::Dropped;
    e.tied_to = tiedNames(plan, r.ties[d]);
    e.note = e.tied_to.empty()
                 ? "not observed by these readings (absorbed by the placements' unknown positions)"
                 : "tied to kept ones, its effect is in them: " + tieText(plan, r.ties[d]);
    return;
  }
  for (std::size_t w = 0; w < r.weak.size(); ++w) {
    if (r.weak[w] != index) continue;
    e.note = format(
        "weakly determined (surviving fraction %.2g of its information): held at its "
        "nominal value",
        r.weak_fraction[w]);
  }
}

// A determined parameter that a dropped one is tied to carries it: "estimated together with
// dropped L (+1 L  -0.92 E_Z0A ...)" (docs/five-axis.md section 4).
std::string carriedNote(const Plan& plan, int index) {
  if (!plan.calibrate_resolution) return {};
  const CalibratedSetResolution& r = *plan.calibrate_resolution;
  const auto& infos = plan.machine.mechanism->parameters();
  std::string note;
  for (std::size_t d = 0; d < r.dropped.size(); ++d) {
    for (std::size_t i = 1; i < r.ties[d].size(); ++i) {
      if (r.ties[d][i].first != index) continue;
      note += std::string(note.empty() ? "" : "; ") + "estimated together with dropped " +
              infos[static_cast<std::size_t>(r.dropped[d])].name + " (" + tieText(plan, r.ties[d]) +
              ")";
    }
  }
  return note;
}

// Position of model parameter `index` among the calibrated ones, or -1.
int calibratedPosition(const Machine& machine, int index) {
  for (std::size_t k = 0; k < machine.calibrated.size(); ++k)
    if (machine.calibrated[k] == index) return static_cast<int>(k);
  return -1;
}

// A linear combination of parameters, sum c_i p_i, and its u over the calibrated ones (docs/
// five-axis.md: the chained form's differences of line positions).
struct ChainedEntry {
  std::string axis, entry;
  std::vector<std::pair<std::string, double>> terms;
};

}  // namespace

std::vector<ControllerEntry> controllerEntries(const Plan& plan, const Eigen::VectorXd& parameters,
                                               const ParameterCovariance* covariance) {
  const Machine& machine = plan.machine;
  const auto& infos = machine.mechanism->parameters();
  std::vector<ControllerEntry> entries;
  for (std::size_t i = 0; i < infos.size(); ++i) {
    const int index = static_cast<int>(i);
    char error = 0, axis = 0;
    const bool located = splitName(infos[i].name, error, axis);
    ControllerEntry e;
    e.parameter = index;
    e.name = infos[i].name;
    e.axis = located ? std::string(1, axis) : std::string("tool");
    e.entry = entryName(e.name);
    e.value = toFileUnit(infos[i].quantity, parameters[index]);
    e.unit = std::string(unitName(infos[i].quantity));
    const int k = calibratedPosition(machine, index);
    if (k >= 0) {
      e.status = EntryStatus::Determined;
      e.u = covariance ? toFileUnit(infos[i].quantity, covariance->u[k]) : 0.0;
      e.note = carriedNote(plan, index);
    } else {
      describeUncalibrated(plan, index, e);
    }
    entries.push_back(e);
  }
  return entries;
}

namespace {

bool trunnion(const Plan& plan) {
  return plan.machine.mechanism->parameterIndex("E_Y0A") >= 0;
}

// The chained form's entries: for the trunnion, C's line relative to A's (the point of A's line
// in the plane x = 0, of C's at A = 0 in the plane z = 0: C minus A).
std::vector<ChainedEntry> chainedCombinations(const Plan& plan) {
  if (!trunnion(plan)) return {};
  return {{"C", "X offset from A", {{"E_X0C", 1.0}}},
          {"C", "Y offset from A", {{"E_Y0C", 1.0}, {"E_Y0A", -1.0}}},
          {"C", "Z offset from A", {{"E_Z0A", -1.0}}}};
}

std::string chainedFormText(const Plan& plan) {
  if (!trunnion(plan))
    return "not chained: B in the head (frame H, parallel to M, origin at the nominal pivot) and C "
           "on the bed (frame M) are each given in their own frame";
  return "C is carried by A: every entry is in M with the axes at zero; chained (C relative to A) "
         "below: C's line point (z = 0) minus A's line point (x = 0), mm";
}

const char* kKindText =
    "actual location of each axis in the machine frame M (ISO 230-7 sign, docs/five-axis.md "
    "section 5); a controller whose table holds corrections takes each determined value negated";

// The combination's value (file units, mm) and u; determined when every term is.
json combinationToJson(const Plan& plan, const ChainedEntry& c, const Eigen::VectorXd& parameters,
                       const ParameterCovariance* covariance) {
  const Machine& machine = plan.machine;
  double value = 0.0;
  Eigen::VectorXd weights = Eigen::VectorXd::Zero(machine.calibratedCount());
  std::vector<std::string> missing;
  for (const auto& [name, coefficient] : c.terms) {
    const int index = machine.mechanism->parameterIndex(name);
    value += coefficient * parameters[index];
    const int k = calibratedPosition(machine, index);
    if (k < 0)
      missing.push_back(name);
    else
      weights[k] = coefficient;
  }
  json out = {{"axis", c.axis}, {"entry", c.entry}, {"unit", "mm"}};
  if (!missing.empty()) {
    out["status"] = "not determined";
    out["value"] = nullptr;
    out["not_measured"] = missing;
    out["u"] = nullptr;
    out["U"] = nullptr;
    return out;
  }
  const double u =
      covariance ? std::sqrt(std::max(0.0, weights.dot(covariance->V * weights))) : 0.0;
  std::string note;
  for (const auto& term : c.terms) {
    const std::string carried = carriedNote(plan, machine.mechanism->parameterIndex(term.first));
    if (!carried.empty()) note += (note.empty() ? "" : "; ") + term.first + " " + carried;
  }
  out["note"] = note;
  out["status"] = "determined";
  out["value"] = value;
  out["u"] = u;
  out["U"] = kCoverageFactor * u;
  return out;
}

// One axis row of the earlier layout: values by column with each cell's status.
json axisRows(const std::vector<ControllerEntry>& entries) {
  json rows = json::array();
  for (const ControllerEntry& e : entries) {
    if (e.axis == "tool") continue;
    json* row = nullptr;
    for (json& r : rows)
      if (r["axis"] == e.axis) row = &r;
    if (!row) {
      json blank = {{"axis", e.axis},
                    {"offset_mm", json::object()},
                    {"orientation_deg", json::object()},
                    {"status", json::object()}};
      for (const char* c : {"X", "Y", "Z"}) {
        blank["offset_mm"][c] = 0.0;
        blank["status"][c] = "not a parameter";
      }
      for (const char* c : {"A", "B", "C"}) {
        blank["orientation_deg"][c] = 0.0;
        blank["status"][c] = "not a parameter";
      }
      rows.push_back(blank);
      row = &rows.back();
    }
    const std::string column(1, e.name[2]);
    (*row)[e.unit == "mm" ? "offset_mm" : "orientation_deg"][column] = e.value;
    (*row)["status"][column] = entryStatusName(e.status);
  }
  return rows;
}

}  // namespace

json controllerTableToJson(const Plan& plan, const Eigen::VectorXd& parameters,
                           const ParameterCovariance* covariance) {
  const std::vector<ControllerEntry> entries = controllerEntries(plan, parameters, covariance);
  json list = json::array();
  for (const ControllerEntry& e : entries) {
    const bool determined = e.status == EntryStatus::Determined;
    json row = {{"name", e.name},
                {"axis", e.axis},
                {"entry", e.entry},
                {"status", entryStatusName(e.status)},
                {"unit", e.unit}};
    // Only a determined entry has a measured value; the others carry the value the model kept.
    row["value"] = determined ? json(e.value) : json(nullptr);
    row["kept_value"] = e.value;
    row["u"] = determined ? json(e.u) : json(nullptr);
    row["U"] = determined ? json(kCoverageFactor * e.u) : json(nullptr);
    row["tied_to"] = e.tied_to;
    row["note"] = e.note;
    list.push_back(row);
  }
  json chained = json::array();
  for (const ChainedEntry& c : chainedCombinations(plan))
    chained.push_back(combinationToJson(plan, c, parameters, covariance));
  json out = {{"kind", "actual location"},
              {"sign", kKindText},
              {"coverage_factor", kCoverageFactor},
              {"chained_form", {{"description", chainedFormText(plan)}, {"entries", chained}}},
              {"entries", list},
              {"axes", axisRows(entries)}};
  const int l = plan.machine.mechanism->parameterIndex("L");
  if (l >= 0) out["tool_length_mm"] = parameters[l];
  return out;
}

namespace {

// "+0.0303 mm", "+0.001865 deg"; with the fine unit for u and U: "0.98 um", "4.24 urad".
std::string valueText(double value, const std::string& unit) {
  return unit == "deg" ? format("%+.6f deg", value) : format("%+.4f mm", value);
}
std::string fineText(double value, const std::string& unit) {
  return unit == "deg" ? format("%.2f urad", degToRad(value) * kMicroradiansPerRadian)
                       : format("%.2f um", value * 1e3);
}

}  // namespace

std::string controllerTable(const Plan& plan, const Eigen::VectorXd& parameters,
                            const ParameterCovariance* covariance) {
  const json table = controllerTableToJson(plan, parameters, covariance);
  std::ostringstream out;
  out << "\nController table: " << kKindText << "\n";
  out << "  chained form: " << chainedFormText(plan) << "\n";
  out << "  only determined entries have a value; a dropped or held entry was not measured: "
         "do not enter it as measured\n";
  out << "  axis  entry                status        value              u            U (k = 2)\n";
  for (const json& e : table["entries"]) {
    const std::string unit = e["unit"].get<std::string>();
    out << format("  %-4s  %-19s  %-11s", e["axis"].get<std::string>().c_str(),
                  e["entry"].get<std::string>().c_str(), e["status"].get<std::string>().c_str());
    if (e["status"] == "determined") {
      out << format("  %-16s  %-11s  %s", valueText(e["value"].get<double>(), unit).c_str(),
                    fineText(e["u"].get<double>(), unit).c_str(),
                    fineText(e["U"].get<double>(), unit).c_str());
    } else {
      // No number in the value column: the value the fit kept goes to the note.
      out << "  NOT MEASURED";
    }
    std::string note = e["note"].get<std::string>();
    if (e["status"] != "determined")
      note = e["name"].get<std::string>() + " held at " +
             (unit == "deg" ? format("%.6f deg", e["kept_value"].get<double>())
                            : format("%.4f mm", e["kept_value"].get<double>())) +
             " in the fit; " + note;
    out << (note.empty() ? "" : "\n        " + note) << "\n";
  }
  for (const json& c : table["chained_form"]["entries"]) {
    out << format("  %-4s  %-19s  ", c["axis"].get<std::string>().c_str(),
                  c["entry"].get<std::string>().c_str());
    if (c["status"] == "determined") {
      out << format("%-11s  %-16s  %-11s  %s", "determined",
                    valueText(c["value"].get<double>(), "mm").c_str(),
                    fineText(c["u"].get<double>(), "mm").c_str(),
                    fineText(c["U"].get<double>(), "mm").c_str());
    } else {
      out << "NOT DETERMINED (not measured:";
      for (const json& name : c["not_measured"]) out << " " << name.get<std::string>();
      out << ")";
    }
    if (c.contains("note") && !c["note"].get<std::string>().empty())
      out << "\n        " << c["note"].get<std::string>();
    out << "\n";
  }
  return out.str();
}

}  // namespace artcal
