#include "artcal/report/calibration_report.hpp"
#include "artcal/report/location_errors.hpp"
#include "artcal/report/text_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "artcal/plan/compliance_deflections.hpp"
#include "artcal/report/model_choice_report.hpp"
#include "artcal/report/report.hpp"

namespace artcal {

using nlohmann::json;

namespace {

/// printf-style text of one number; "-" when it is not finite.
std::string numberOrDash(const char* pattern, double value) {
  return std::isfinite(value) ? report_text::format(pattern, value) : "-";
}

/// The width of a parameter table's name column: the longest calibrated name, at least 10 (a
/// URDF's "wrist_3_link-tool0_fixed_joint.x" shifted every number of its row), and its heading.
std::size_t nameWidth(const Machine& machine) {
  std::size_t width = 10;
  for (int k = 0; k < machine.calibratedCount(); ++k)
    width = std::max(width, machine.calibratedInfo(k).name.size());
  return width;
}

std::string nameHeading(std::size_t width) {
  return std::string("parameter").append(width - 9, ' ');
}

std::string padded(const std::string& text, int width) {
  std::string out = text;
  if (static_cast<int>(out.size()) < width) out.insert(0, width - out.size(), ' ');
  return out;
}

json vectorToJson(const Eigen::VectorXd& v) {
  json out = json::array();
  for (int i = 0; i < v.size(); ++i) out.push_back(finiteOrNull(v[i]));
  return out;
}

/// Where each artifact's systematic errors start in c (GlobalLayout order, without p).
std::vector<int> systematicOffsets(const Plan& plan) {
  std::vector<int> offsets;
  int offset = 0;
  for (const Artifact& artifact : plan.artifacts) {
    offsets.push_back(offset);
    offset += artifact.systematicCount();
  }
  return offsets;
}

/// Below this many degrees of freedom chi2/dof is itself too uncertain for u_posterior to be read
/// as a figure: its square root has a relative standard error of about 1/sqrt(2 dof), 13 % at 30.
constexpr int kFewDegreesOfFreedom = 30;

}  // namespace

json posteriorCaveat(int dof) {
  if (dof <= 0) return "no redundancy (dof " + std::to_string(dof) + "): no u_posterior";
  if (dof >= kFewDegreesOfFreedom) return nullptr;
  char text[160];
  std::snprintf(text, sizeof text,
                "only %d degrees of freedom: sqrt(chi2/dof), and so u_posterior, is uncertain by "
                "about %.0f %% (1/sqrt(2 dof)); prefer u",
                dof, 100.0 / std::sqrt(2.0 * dof));
  return text;
}

namespace {

const Measurement& measurementOf(const std::vector<Placement>& placements,
                                 const ResidualEntry& entry) {
  return placements[static_cast<std::size_t>(entry.placement)]
      .measurements[static_cast<std::size_t>(entry.measurement)];
}

/// The gross errors for a person: where each reading is (a CSV file's data row when it came
/// from one) and how to leave it out once it has been checked.
std::string grossErrorText(const std::vector<Placement>& placements,
                           const Calibration& calibration) {
  std::ostringstream out;
  int count = 0;
  for (const ResidualEntry& e : calibration.residuals) {
    if (!e.gross) continue;
    const Measurement& m = measurementOf(placements, e);
    out << "  placement " << placementLabel(placements, static_cast<std::size_t>(e.placement))
        << " reading " << e.measurement << " feature " << e.feature
        << ": |z| = " << numberOrDash("%.1f", e.score);
    if (m.csv_row > 0) out << ", " << m.csv << " row " << m.csv_row;
    out << "\n";
    ++count;
  }
  if (count == 0) return "";
  std::ostringstream text;
  text << "\n"
       << count << (count == 1 ? " gross error" : " gross errors") << " (|z| > "
       << numberOrDash("%.2f", calibration.gross_limit)
       << ", the gross threshold times max(1, Birge ratio)): check each (a ball not seated, a "
          "socket that moved); a reading from a CSV file is left out with \"exclude_rows\": "
          "[row, ...] in its measurement entry, and calibrate again\n"
       << out.str();
  return text.str();
}

}  // namespace

namespace {

json noiseEstimateToJson(const Calibration& calibration) {
  const NoiseEstimate& e = *calibration.noise_estimate;
  return {{"probe", finiteOrNull(e.probe)},
          {"u", finiteOrNull(e.u)},
          {"stated", finiteOrNull(e.stated)},
          {"fits", e.fits},
          {"unit", "mm"}};
}

json weaklyDeterminedToJson(const Plan& plan) {
  json out = json::array();
  if (!plan.calibrate_resolution) return out;
  const CalibratedSetResolution& resolution = *plan.calibrate_resolution;
  const auto& parameters = plan.machine.mechanism->parameters();
  for (std::size_t i = 0; i < resolution.weak.size(); ++i) {
    out.push_back({{"name", parameters[static_cast<std::size_t>(resolution.weak[i])].name},
                   {"surviving_fraction", finiteOrNull(resolution.weak_fraction[i])}});
  }
  return out;
}

/// The parameters calibrate took in place of the weakly determined ones (the structural rule had
/// dropped them as tied): their names.
json inPlaceToJson(const Plan& plan) {
  json out = json::array();
  if (!plan.calibrate_resolution) return out;
  const auto& parameters = plan.machine.mechanism->parameters();
  for (const int index : plan.calibrate_resolution->in_place)
    out.push_back(parameters[static_cast<std::size_t>(index)].name);
  return out;
}

std::string parameterName(const Machine& machine, int index) {
  return machine.mechanism->parameters()[static_cast<std::size_t>(index)].name;
}

/// A fit of the plausible-minimum search (plausible_minimum.hpp): its cost, kept set, estimates
/// and flagged corrections, file units.
json minimumFitToJson(const Machine& machine, const MinimumFit& fit) {
  const auto& info = machine.mechanism->parameters();
  json kept = json::array();
  for (const int i : fit.calibrated) {
    const Quantity& q = info[static_cast<std::size_t>(i)].quantity;
    kept.push_back({{"name", parameterName(machine, i)},
                    {"estimate", finiteOrNull(toFileUnit(q, fit.parameters[i]))},
                    {"unit", std::string(unitName(q))}});
  }
  json flagged = json::array();
  for (const ImplausibleCorrection& c : fit.flagged) {
    const Quantity& q = info[static_cast<std::size_t>(c.parameter)].quantity;
    flagged.push_back({{"name", parameterName(machine, c.parameter)},
                       {"correction", finiteOrNull(toFileUnit(q, c.correction))},
                       {"limit", finiteOrNull(toFileUnit(q, c.limit))},
                       {"unit", std::string(unitName(q))}});
  }
  return {{"chi2", finiteOrNull(fit.chi2)},
          {"chi2_increase", finiteOrNull(fit.chi2_increase)},
          {"chi2_allowance", finiteOrNull(fit.chi2_allowance)},
          {"dof", fit.dof},
          {"chi2_per_dof", fit.dof > 0 ? finiteOrNull(fit.chi2_per_dof) : json(nullptr)},
          {"probe", {{"value", finiteOrNull(fit.probe)}, {"unit", "mm"}}},
          {"flagged", flagged},
          {"parameters", kept}};
}

json minimumToJson(const Machine& machine, const Calibration& calibration) {
  if (!calibration.minimum) return nullptr;
  const MinimumChoice& m = *calibration.minimum;
  json demoted = json::array();
  for (const int i : m.demoted) demoted.push_back(parameterName(machine, i));
  return {
      {"chosen", m.alternative_chosen ? "alternative" : "plain"},
      {"plausible", m.alternative_chosen && m.alternative->flagged.empty()},
      {"reason", m.reason},
      {"flagged", minimumFitToJson(machine, m.flagged)},
      {"alternative", m.alternative ? minimumFitToJson(machine, *m.alternative) : json(nullptr)},
      {"demoted", demoted},
      {"fits", m.fits}};
}

/// One line per fit of the search: chi2 and the flagged corrections.
std::string minimumFitText(const Machine& machine, const MinimumFit& fit) {
  const auto& info = machine.mechanism->parameters();
  std::string out = "chi2 = " + numberOrDash("%.4g", fit.chi2) + " on " + std::to_string(fit.dof) +
                    " dof, " + std::to_string(fit.calibrated.size()) + " kept";
  if (fit.flagged.empty()) return out + ", no implausible correction";
  out += ", corrects";
  for (std::size_t k = 0; k < fit.flagged.size(); ++k) {
    const ImplausibleCorrection& c = fit.flagged[k];
    const Quantity& q = info[static_cast<std::size_t>(c.parameter)].quantity;
    out += (k ? ", " : " ") + parameterName(machine, c.parameter) + " by " +
           numberOrDash("%.4g", toFileUnit(q, c.correction)) + " " + std::string(unitName(q)) +
           " (limit " + numberOrDash("%.3g", toFileUnit(q, c.limit)) + " " +
           std::string(unitName(q)) + ")";
  }
  return out;
}

std::string minimumText(const Machine& machine, const Calibration& calibration) {
  if (!calibration.minimum) return "";
  const MinimumChoice& m = *calibration.minimum;
  std::string out =
      std::string("minimum: ") + (m.alternative_chosen ? "a plausible one" : "the plain fit's") +
      " (" + m.reason + ")\n  plain fit:         " + minimumFitText(machine, m.flagged) + "\n";
  if (m.alternative) {
    out += std::string(m.alternative_chosen ? "  chosen minimum:    " : "  last alternative:  ") +
           minimumFitText(machine, *m.alternative) + "; chi2 increase " +
           numberOrDash("%+.3g", m.alternative->chi2_increase) + " x max(1, chi2/dof), allowed " +
           numberOrDash("%.3g", m.alternative->chi2_allowance) + "\n";
  }
  return out;
}

// The parameters the rank rule dropped (calibrate "identifiable"), each with what it is tied
// to: held at their nominal values, not measured (docs/models.md section 1).
std::string droppedText(const Plan& plan) {
  if (!plan.calibrate_resolution || plan.calibrate_resolution->dropped.empty()) return {};
  const CalibratedSetResolution& r = *plan.calibrate_resolution;
  const auto& parameters = plan.machine.mechanism->parameters();
  std::ostringstream out;
  out << "not calibrated, dropped by the rank rule (the readings cannot separate them; held at "
         "their nominal values, not measured):\n";
  for (std::size_t d = 0; d < r.dropped.size(); ++d) {
    out << "  " << parameters[static_cast<std::size_t>(r.dropped[d])].name << ": "
        << tieText(plan, r.ties[d]) << "\n";
  }
  return out.str();
}

// The noise estimate, the parameters held at nominal, the minimum taken and the warnings, for
// the table.
std::string calibrationNotes(const Plan& plan, const Calibration& calibration) {
  std::ostringstream out;
  if (calibration.noise_estimate) {
    const NoiseEstimate& e = *calibration.noise_estimate;
    out << "probe noise estimated from the fit: " << numberOrDash("%.4g", e.probe) << " mm (u "
        << numberOrDash("%.2g", e.u) << " mm; started from " << numberOrDash("%.4g", e.stated)
        << " mm, " << e.fits << (e.fits == 1 ? " fit" : " fits") << ")\n";
  }
  out << droppedText(plan);
  const json weak = weaklyDeterminedToJson(plan);
  if (!weak.empty()) {
    out << "held at nominal, weakly determined (surviving fraction of their information < 1e-6: "
           "set by the model mismatch, not by the readings):";
    for (const json& w : weak) out << " " << w["name"].get<std::string>();
    out << "\n";
  }
  const json in_place = inPlaceToJson(plan);
  if (!in_place.empty()) {
    out << "calibrated in their place (dropped by the structural rule as tied to them; the weak "
           "rule's choice over every listed parameter):";
    for (const json& name : in_place) out << " " << name.get<std::string>();
    out << "\n";
  }
  if (calibration.unmodelled) {
    const UnmodelledError& u = *calibration.unmodelled;
    out << "unmodelled error by cross-validation (" << u.folds << " folds of " << u.scheme
        << " left out, " << u.readings << " readings scored): " << numberOrDash("%.4g", u.sigma)
        << " mm per coordinate (left-out rms " << numberOrDash("%.4g", u.observed_rms)
        << " mm where V_p and the noise predict " << numberOrDash("%.4g", u.predicted_rms)
        << " mm); verify and the report add it to their predictions\n";
    if (u.scheme == "regions")
      out << "  (fewer than 3 placements: the folds left out regions of postures of the same "
             "placements; errors on other placements of the artifact can be larger)\n";
  }
  out << minimumText(plan.machine, calibration);
  if (calibration.model_choice) out << modelChoiceTable(plan, *calibration.model_choice) << "\n";
  for (const std::string& warning : calibration.warnings) out << "warning: " << warning << "\n";
  return out.str();
}

}  // namespace

std::string leftAligned(std::string text, std::size_t width) {
  if (text.size() < width) text.resize(width, ' ');
  return text;
}

// A compliance's u when it was calibrated (file units), NAN otherwise.
double complianceU(const Machine& machine, const Calibration& calibration, int parameter) {
  const auto at = std::find(machine.calibrated.begin(), machine.calibrated.end(), parameter);
  if (at == machine.calibrated.end() || !calibration.covariance) return NAN;
  const auto k = static_cast<int>(at - machine.calibrated.begin());
  return toFileUnit(machine.calibratedInfo(k).quantity, calibration.covariance->u[k]);
}

// docs/compliance.md section 5: each compliance with its u and the largest deflection it implies
// over the readings with their payloads, at the joint (deg or mm) and at the tip (mm).
json complianceToJson(const Plan& plan, const std::vector<Placement>& placements,
                      const Calibration& calibration) {
  const Machine& machine = plan.machine;
  json out = json::array();
  for (const ComplianceDeflection& d :
       complianceDeflections(machine, placements, calibration.parameters)) {
    const ParameterInfo& info =
        machine.mechanism->parameters()[static_cast<std::size_t>(d.parameter)];
    const double u = complianceU(machine, calibration, d.parameter);
    out.push_back(
        {{"name", info.name},
         {"estimate", finiteOrNull(toFileUnit(info.quantity, calibration.parameters[d.parameter]))},
         {"u", std::isfinite(u) ? json(u) : json(nullptr)},
         {"unit", std::string(unitName(info.quantity))},
         {"largest_torque", finiteOrNull(d.largest_torque)},
         {"torque_unit", std::string(torqueUnit(d.revolute))},
         {"largest_deflection",
          finiteOrNull(d.revolute ? radToDeg(d.largest_joint) : d.largest_joint)},
         {"deflection_unit", d.revolute ? "deg" : "mm"},
         {"largest_tip_deflection", finiteOrNull(d.largest_tip)}});
  }
  return out;
}

std::string complianceText(const Plan& plan, const std::vector<Placement>& placements,
                           const Calibration& calibration) {
  const json table = complianceToJson(plan, placements, calibration);
  if (table.empty()) return {};
  std::ostringstream out;
  out << "\njoint compliance (docs/compliance.md): largest over the readings with their payloads\n"
      << "parameter            estimate          u  unit         |tau|  unit  |C tau|  unit  "
         "tip mm\n";
  const auto number = [](const json& v, const char* pattern) {
    return v.is_number() ? numberOrDash(pattern, v.get<double>()) : std::string("-");
  };
  for (const json& c : table) {
    out << leftAligned(c["name"].get<std::string>(), 19)
        << padded(number(c["estimate"], "%.4g"), 10) << padded(number(c["u"], "%.2g"), 11) << "  "
        << leftAligned(c["unit"].get<std::string>(), 10)
        << padded(number(c["largest_torque"], "%.1f"), 8) << "  "
        << leftAligned(c["torque_unit"].get<std::string>(), 4)
        << padded(number(c["largest_deflection"], "%.4f"), 9) << "  "
        << leftAligned(c["deflection_unit"].get<std::string>(), 4)
        << padded(number(c["largest_tip_deflection"], "%.4f"), 8) << "\n";
  }
  return out.str();
}

json calibrationToJson(const Plan& plan, const std::vector<Placement>& placements,
                       const Calibration& calibration) {
  const Machine& machine = plan.machine;
  json out;
  out["plan"] = plan.name;
  out["converged"] = calibration.summary.converged();
  out["termination"] = terminationName(calibration.summary.termination);
  out["message"] = calibration.summary.message;
  out["iterations"] = calibration.summary.iterations;
  out["fits"] = calibration.summary.fits;
  out["chi2"] = finiteOrNull(calibration.chi2);
  out["dof"] = calibration.dof;
  // Without redundancy (dof <= 0) there is no chi2/dof at all: null, not 0.
  const bool redundant = calibration.dof > 0;
  out["chi2_per_dof"] = redundant ? finiteOrNull(calibration.chi2_per_dof) : json(nullptr);
  out["birge_ratio"] = redundant ? finiteOrNull(calibration.birgeRatio()) : json(nullptr);
  out["u_posterior_caveat"] = posteriorCaveat(calibration.dof);
  if (calibration.noise_estimate) out["noise_estimate"] = noiseEstimateToJson(calibration);
  if (calibration.unmodelled) {
    const UnmodelledError& u = *calibration.unmodelled;
    out["unmodelled_error"] = {{"sigma", finiteOrNull(u.sigma)},
                               {"scheme", u.scheme},
                               {"folds", u.folds},
                               {"readings", u.readings},
                               {"observed_rms", finiteOrNull(u.observed_rms)},
                               {"predicted_rms", finiteOrNull(u.predicted_rms)}};
  }
  out.update(calibrateSelectionToJson(plan));
  out["weakly_determined"] = weaklyDeterminedToJson(plan);
  out["calibrated_in_place"] = inPlaceToJson(plan);
  if (calibration.model_choice)
    out["model_choice"] = modelChoiceToJson(plan, *calibration.model_choice);
  out["warnings"] = calibration.warnings;
  if (calibration.minimum) out["minimum"] = minimumToJson(machine, calibration);
  const Eigen::VectorXd posterior = calibration.posteriorU();
  json parameters = json::array();
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    const ParameterInfo& info = machine.calibratedInfo(k);
    const int index = machine.calibrated[static_cast<std::size_t>(k)];
    json p{{"name", info.name},
           {"nominal", finiteOrNull(toFileUnit(info.quantity, machine.nominal[index]))},
           {"estimate", finiteOrNull(toFileUnit(info.quantity, calibration.parameters[index]))},
           {"unit", std::string(unitName(info.quantity))}};
    p["u"] = calibration.covariance
                 ? finiteOrNull(toFileUnit(info.quantity, calibration.covariance->u[k]))
                 : json(nullptr);
    p["u_posterior"] = posterior.size() > 0 ? finiteOrNull(toFileUnit(info.quantity, posterior[k]))
                                            : json(nullptr);
    parameters.push_back(p);
  }
  out["parameters"] = parameters;
  if (machine.mechanism->jointCompliance())
    out["compliance"] = complianceToJson(plan, placements, calibration);
  if (machine.mechanism->hasLocationErrors() && calibration.covariance) {
    out["location_errors"] =
        locationErrorsToJson(plan, *calibration.covariance, &calibration.parameters);
    out["controller_table"] =
        controllerTableToJson(plan, calibration.parameters, &*calibration.covariance);
  }
  json systematic = json::array();
  const std::vector<int> offsets = systematicOffsets(plan);
  for (std::size_t a = 0; a < plan.artifacts.size(); ++a) {
    const Artifact& artifact = plan.artifacts[a];
    for (int s = 0; s < artifact.systematicCount(); ++s) {
      const SystematicError& err = artifact.systematic[static_cast<std::size_t>(s)];
      systematic.push_back({{"artifact", artifact.id},
                            {"feature", err.feature},
                            {"coordinate", err.coordinate},
                            {"estimate", finiteOrNull(calibration.systematic[offsets[a] + s])},
                            {"prior_u", err.sigma},
                            {"unit", "mm"}});
    }
  }
  out["systematic"] = systematic;
  json residuals = json::array();
  int flagged = 0;
  for (const ResidualEntry& entry : calibration.residuals) {
    const Placement& placement = placements[static_cast<std::size_t>(entry.placement)];
    if (entry.measurement == 0) {
      residuals.push_back(
          {{"placement", entry.placement},
           {"artifact", plan.artifacts[static_cast<std::size_t>(placement.artifact)].id},
           {"measurements", json::array()}});
      if (!placement.name.empty()) residuals.back()["name"] = placement.name;
    }
    flagged += entry.flagged ? 1 : 0;
    residuals.back()["measurements"].push_back({{"measurement", entry.measurement},
                                                {"feature", entry.feature},
                                                {"residual", vectorToJson(entry.residual)},
                                                {"standardized", vectorToJson(entry.standardized)},
                                                {"score", finiteOrNull(entry.score)},
                                                {"flagged", entry.flagged},
                                                {"gross", entry.gross}});
  }
  out["residuals"] = residuals;
  out["flagged"] = flagged;
  json gross = json::array();
  for (const ResidualEntry& entry : calibration.residuals) {
    if (!entry.gross) continue;
    json g = {{"placement", entry.placement},
              {"measurement", entry.measurement},
              {"feature", entry.feature},
              {"score", finiteOrNull(entry.score)}};
    const Measurement& m = measurementOf(placements, entry);
    const std::string& name = placements[static_cast<std::size_t>(entry.placement)].name;
    if (!name.empty()) g["name"] = name;
    if (m.csv_row > 0) {
      g["csv"] = m.csv;
      g["csv_row"] = m.csv_row;
    }
    gross.push_back(g);
  }
  out["gross_errors"] = gross;
  if (calibration.largest_residual >= 0) {
    const ResidualEntry& largest =
        calibration.residuals[static_cast<std::size_t>(calibration.largest_residual)];
    out["largest_residual"] = {{"placement", largest.placement},
                               {"measurement", largest.measurement},
                               {"feature", largest.feature},
                               {"score", finiteOrNull(largest.score)},
                               {"flagged", largest.flagged}};
    const std::string& name = placements[static_cast<std::size_t>(largest.placement)].name;
    if (!name.empty()) out["largest_residual"]["name"] = name;
  } else {
    out["largest_residual"] = nullptr;
  }
  return out;
}

std::string calibrationTable(const Plan& plan, const std::vector<Placement>& placements,
                             const Calibration& calibration) {
  const Machine& machine = plan.machine;
  std::ostringstream out;
  const CalibrationSummary& s = calibration.summary;
  out << "calibration of " << (plan.name.empty() ? plan.source : plan.name) << ": "
      << (s.converged() ? "converged" : "NOT CONVERGED") << " (" << s.message << ") after "
      << s.iterations << " iterations"
      << (s.fits > 1 ? " in " + std::to_string(s.fits) + " fits" : std::string()) << "\n";
  out << "chi2 = " << numberOrDash("%.4g", calibration.chi2) << " on " << calibration.dof
      << " degrees of freedom, chi2/dof = ";
  if (calibration.dof > 0) {
    out << numberOrDash("%.4f", calibration.chi2_per_dof) << " (Birge ratio "
        << numberOrDash("%.3f", calibration.birgeRatio()) << ")\n";
  } else {
    out << "- (no redundancy)\n";
  }
  if (const json caveat = posteriorCaveat(calibration.dof); caveat.is_string()) {
    out << "note: " << caveat.get<std::string>() << "\n";
  }
  out << calibrationNotes(plan, calibration);
  out << "\n";
  const std::size_t name_width = nameWidth(machine);
  out << nameHeading(name_width)
      << "     nominal        estimate             u    u_posterior  unit\n";
  const Eigen::VectorXd posterior = calibration.posteriorU();
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    const ParameterInfo& info = machine.calibratedInfo(k);
    const int index = machine.calibrated[static_cast<std::size_t>(k)];
    const double u =
        calibration.covariance ? toFileUnit(info.quantity, calibration.covariance->u[k]) : NAN;
    const double up = posterior.size() > 0 ? toFileUnit(info.quantity, posterior[k]) : NAN;
    std::string name = info.name;
    name.resize(name_width, ' ');
    out << name
        << padded(numberOrDash("%.6f", toFileUnit(info.quantity, machine.nominal[index])), 13)
        << padded(numberOrDash("%.6f", toFileUnit(info.quantity, calibration.parameters[index])),
                  16)
        << padded(numberOrDash("%.3g", u), 14) << padded(numberOrDash("%.3g", up), 15) << "  "
        << unitName(info.quantity) << "\n";
  }
  out << complianceText(plan, placements, calibration);
  if (machine.mechanism->hasLocationErrors() && calibration.covariance) {
    out << locationErrorTable(plan, *calibration.covariance, &calibration.parameters);
    out << controllerTable(plan, calibration.parameters, &*calibration.covariance);
  }
  if (calibration.systematic.size() > 0) {
    out << "\nartifact systematic errors (estimate, prior u, mm):\n";
    const std::vector<int> offsets = systematicOffsets(plan);
    for (std::size_t a = 0; a < plan.artifacts.size(); ++a) {
      const Artifact& artifact = plan.artifacts[a];
      for (int i = 0; i < artifact.systematicCount(); ++i) {
        const SystematicError& err = artifact.systematic[static_cast<std::size_t>(i)];
        out << "  " << artifact.id << " feature " << err.feature << " coordinate " << err.coordinate
            << ": " << numberOrDash("%.6f", calibration.systematic[offsets[a] + i]) << "  ("
            << numberOrDash("%.3g", err.sigma) << ")\n";
      }
    }
  }
  if (!calibration.residuals.empty()) {
    out << "\nresiduals (mm) and standardised residuals z (whitened, divided by sqrt(1 - "
           "leverage)); |z| > threshold is flagged <<\n";
    out << "placement  reading  feature  residual                      z\n";
    for (std::size_t r = 0; r < calibration.residuals.size(); ++r) {
      const ResidualEntry& e = calibration.residuals[r];
      std::ostringstream residual, z;
      for (int k = 0; k < e.residual.size(); ++k)
        residual << numberOrDash("%+.5f", e.residual[k]) << " ";
      for (int k = 0; k < e.standardized.size(); ++k)
        z << numberOrDash("%+.2f", e.standardized[k]) << " ";
      std::string residual_text = residual.str();
      residual_text.resize(std::max<std::size_t>(residual_text.size(), 30), ' ');
      out << padded(placementLabel(placements, static_cast<std::size_t>(e.placement)), 9)
          << padded(std::to_string(e.measurement), 9) << padded(std::to_string(e.feature), 9)
          << "  " << residual_text << z.str();
      if (e.flagged) out << " <<";
      if (static_cast<int>(r) == calibration.largest_residual) out << " (largest)";
      out << "\n";
    }
  }
  out << grossErrorText(placements, calibration);
  return out.str();
}

json confirmationToJson(const Plan& plan, const ConfirmationOptions& options,
                        const Confirmation& confirmation) {
  json out;
  out["plan"] = plan.name;
  out["confirmed"] = confirmation.confirmed;
  out["trials"] = confirmation.trials;
  out["converged_trials"] = confirmation.converged_trials;
  out["seed"] = options.seed;
  out["noise_scale"] = options.noise_scale;
  out["perturbation"] = options.perturbation;
  out["mean_chi2_per_dof"] = finiteOrNull(confirmation.mean_chi2_per_dof);
  const Band& band = confirmation.band;
  out["band"] = {{"low", band.low},
                 {"high", band.high},
                 {"coverage_factor", band.coverage_factor},
                 {"sampling", band.sampling},
                 {"allowance", band.allowance},
                 {"level", options.level}};
  json parameters = json::array();
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    const ParameterInfo& info = plan.machine.calibratedInfo(k);
    const ConfirmedParameter& p = confirmation.parameters[static_cast<std::size_t>(k)];
    parameters.push_back({{"name", p.name},
                          {"predicted_u", finiteOrNull(toFileUnit(info.quantity, p.predicted_u))},
                          {"empirical_u", finiteOrNull(toFileUnit(info.quantity, p.empirical_u))},
                          {"bias", finiteOrNull(toFileUnit(info.quantity, p.bias))},
                          {"ratio", finiteOrNull(p.ratio)},
                          {"inside", p.inside},
                          {"unit", std::string(unitName(info.quantity))}});
  }
  out["parameters"] = parameters;
  return out;
}

std::string confirmationTable(const Plan& plan, const ConfirmationOptions& options,
                              const Confirmation& confirmation) {
  std::ostringstream out;
  const Band& band = confirmation.band;
  out << "confirmation of " << (plan.name.empty() ? plan.source : plan.name) << ": "
      << (confirmation.confirmed ? "CONFIRMED" : "NOT CONFIRMED") << "\n";
  out << confirmation.trials << " simulated calibrations (seed " << options.seed << ", noise x "
      << options.noise_scale << ", true parameters nominal + " << options.perturbation
      << " u N(0,1)" << (plan.machine.prior_sigma.size() > 0 ? ", or from machine.prior" : "")
      << "), " << confirmation.converged_trials << " converged; mean chi2/dof "
      << numberOrDash("%.3f", confirmation.mean_chi2_per_dof) << "\n";
  out << "band for empirical/predicted: [" << numberOrDash("%.3f", band.low) << ", "
      << numberOrDash("%.3f", band.high) << "] = 1 +- ("
      << numberOrDash("%.2f", band.coverage_factor) << " x " << numberOrDash("%.4f", band.sampling)
      << " sampling + " << numberOrDash("%.3f", band.allowance) << " non-linearity allowance)\n\n";
  const std::size_t name_width = nameWidth(plan.machine);
  out << nameHeading(name_width) << "    predicted_u    empirical_u          bias   ratio  unit\n";
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    const ParameterInfo& info = plan.machine.calibratedInfo(k);
    const ConfirmedParameter& p = confirmation.parameters[static_cast<std::size_t>(k)];
    std::string name = p.name;
    name.resize(name_width, ' ');
    out << name << padded(numberOrDash("%.4g", toFileUnit(info.quantity, p.predicted_u)), 14)
        << padded(numberOrDash("%.4g", toFileUnit(info.quantity, p.empirical_u)), 15)
        << padded(numberOrDash("%+.3g", toFileUnit(info.quantity, p.bias)), 14)
        << padded(numberOrDash("%.3f", p.ratio), 8) << "  " << unitName(info.quantity)
        << (p.inside ? "" : "  << outside the band") << "\n";
  }
  return out.str();
}

}  // namespace artcal
