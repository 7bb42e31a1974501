#include "artcal/report/report.hpp"
#include "artcal/model/joint_compliance.hpp"
#include "artcal/report/cartesian_report.hpp"
#include "artcal/report/location_errors.hpp"
#include "artcal/report/text_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace artcal {

using nlohmann::json;

json finiteOrNull(double value) {
  return std::isfinite(value) ? json(value) : json(nullptr);
}

json posteriorOrNull(double value) {
  return value > 0.0 ? finiteOrNull(value) : json(nullptr);
}

std::vector<double> jointsToFile(const Machine& machine, const Eigen::VectorXd& q) {
  std::vector<double> out;
  for (int i = 0; i < q.size(); ++i) {
    out.push_back(toFileUnit(jointQuantity(machine.mechanism->jointKind(i)), q[i]));
  }
  return out;
}

json countingToJson(const CountingCondition& counting) {
  json out = {{"N_p", counting.N_p},
              {"N_b", counting.N_b},
              {"N_r", counting.N_r},
              {"satisfied", counting.satisfied}};
  out["minimum_placements_alike"] =
      counting.minimum_alike > 0 ? json(counting.minimum_alike) : json(nullptr);
  out["N_r_table"] = counting.N_r_table;
  out["rigid_effective"] = counting.rigid_effective;
  return out;
}

json predictionNoiseToJson(double value, bool estimated, const std::string& source) {
  return {
      {"value", finiteOrNull(value)}, {"unit", "mm"}, {"estimated", estimated}, {"source", source}};
}

json tipWithUnmodelledToJson(const TipWithUnmodelled& tip, const UnmodelledError& from) {
  return {{"sigma", tip.sigma},
          {"trace_share", tip.trace_share},
          {"worst_total", tip.worst_total},
          {"mean_total", tip.mean_total},
          {"rms_total", tip.rms_total},
          {"unit", "mm"},
          {"scheme", from.scheme},
          {"folds", from.folds}};
}

json evaluateCommandToJson(const NoisedEvaluation& noised, const CartesianAnswers& cmm) {
  json out = evaluationToJson(noised.plan, noised.evaluation);
  out.update(cartesianAnswersToJson(noised.plan, cmm));
  const PredictionNoise& noise = noised.noise;
  out["probe_noise"] = predictionNoiseToJson(noise.probe, noise.estimated, noise.source);
  if (noised.tip_with_unmodelled)
    out["tip_with_unmodelled"] =
        tipWithUnmodelledToJson(*noised.tip_with_unmodelled, *noise.unmodelled);
  return out;
}

std::string tipWithUnmodelledTable(const TipWithUnmodelled& tip, const UnmodelledError& from) {
  return report_text::format(
      "Tip uncertainty with the unmodelled error s_u = %.2f um per coordinate (cross-validation, "
      "%d folds by %s; um)\n  worst  S_u = %.2f    mean S_u = %.2f    rms S_u = %.2f   "
      "(S_u^2 = S^2 + d s_u^2, d s_u^2 = (%.2f)^2)\n",
      tip.sigma * 1e3, from.folds, from.scheme.c_str(), tip.worst_total * 1e3, tip.mean_total * 1e3,
      tip.rms_total * 1e3, tip.trace_share * 1e3);
}

json calibrateSelectionToJson(const Plan& plan) {
  json out = json::object();
  if (!plan.calibrate_resolution) return out;
  const auto& params = plan.machine.mechanism->parameters();
  const auto name = [&params](int index) { return params[static_cast<std::size_t>(index)].name; };
  const CalibratedSetResolution& resolution = *plan.calibrate_resolution;
  json kept = json::array(), dropped = json::array(), ties = json::array();
  for (int k : resolution.kept) kept.push_back(name(k));
  for (std::size_t d = 0; d < resolution.dropped.size(); ++d) {
    dropped.push_back(name(resolution.dropped[d]));
    json names = json::array(), coefficients = json::array();
    for (const auto& [k, c] : resolution.ties[d]) {
      names.push_back(name(k));
      coefficients.push_back(c);
    }
    ties.push_back({{"parameters", names}, {"coefficients", coefficients}});
  }
  out["calibrate_resolved"] = kept;
  out["calibrate_dropped"] = dropped;
  out["calibrate_ties"] = ties;
  if (!resolution.unobserved.empty()) {  // docs/compliance.md section 4
    json unobserved = json::array();
    for (int k : resolution.unobserved) unobserved.push_back(name(k));
    out["calibrate_not_observed"] = unobserved;
  }
  const WeakRuleChoice& weak = resolution.at_nominal;
  json weak_kept = json::array(), held = json::array(), in_place = json::array();
  for (int k : weak.kept) weak_kept.push_back(name(k));
  for (std::size_t h = 0; h < weak.held.size(); ++h)
    held.push_back({{"name", name(weak.held[h])},
                    {"surviving_fraction", finiteOrNull(weak.held_fraction[h])}});
  for (int k : weak.in_place) in_place.push_back(name(k));
  out["calibrate_weak_rule"] = {{"kept", weak_kept}, {"held", held}, {"in_place", in_place}};
  return out;
}

json identifiabilityToJson(const Identifiability& id) {
  json names = json::array(), combinations = json::array();
  for (const Combination& c : id.unidentifiable) {
    names.push_back(c.names);
    combinations.push_back({{"parameters", c.names}, {"coefficients", c.coefficients}});
  }
  return {{"identifiable", id.identifiable()},
          {"counting", countingToJson(id.counting)},
          {"rank",
           {{"rank", id.rank},
            {"deficiency", id.deficiency},
            {"condition_number", finiteOrNull(id.condition_number)},
            {"tolerance", id.tolerance},
            {"unidentifiable", names},
            {"combinations", combinations},
            {"fix", id.to_fix},
            {"no_length_scale", id.no_length_scale}}}};
}

json tipToJson(const Machine& machine, const TipSummary& tip,
               const std::vector<Eigen::VectorXd>& workspace) {
  json worst = {{"total", tip.worst.total},
                {"kinematic", tip.worst.kinematic},
                {"encoder", tip.worst.encoder}};
  if (tip.worst_index >= 0) {
    worst["joints"] = jointsToFile(machine, workspace[static_cast<std::size_t>(tip.worst_index)]);
    worst["index"] = tip.worst_index;
  }
  return {
      {"worst", worst}, {"mean", tip.mean}, {"rms", tip.rms}, {"configurations", workspace.size()}};
}

json evaluationToJson(const Plan& plan, const Evaluation& ev) {
  json out = identifiabilityToJson(ev.identifiability);
  out.update(calibrateSelectionToJson(plan));
  out["plan"] = plan.name;
  out["identifiable"] = ev.identifiable();
  const Machine& machine = plan.machine;
  json parameters = json::array();
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    const ParameterInfo& info = machine.calibratedInfo(k);
    json p = {{"name", info.name},
              {"nominal", toFileUnit(info.quantity, machine.nominal[machine.calibrated[k]])},
              {"unit", unitName(info.quantity)}};
    p["u"] = ev.covariance ? json(toFileUnit(info.quantity, ev.covariance->u[k])) : json(nullptr);
    parameters.push_back(p);
  }
  out["parameters"] = parameters;
  if (ev.covariance && machine.mechanism->hasLocationErrors())
    out["location_errors"] = locationErrorsToJson(plan, *ev.covariance, nullptr);
  if (ev.covariance) {
    const Eigen::MatrixXd& corr = ev.covariance->correlation;
    json rows = json::array();
    for (int i = 0; i < corr.rows(); ++i) {
      json row = json::array();
      for (int j = 0; j < corr.cols(); ++j) row.push_back(corr(i, j));
      rows.push_back(row);
    }
    out["correlation"] = rows;
  }
  if (ev.tip) {
    out["tip"] = tipToJson(machine, *ev.tip, ev.workspace);
    out["tip"]["dropped"] = {{"unreachable", ev.workspace_drops.unreachable},
                             {"forward_failed", ev.workspace_drops.failed}};
  }
  if (!ev.tips.empty()) {
    json tips = json::array();
    for (const NamedTipSummary& named : ev.tips) {
      json names = json::array();
      for (const int k : named.calibrated) names.push_back(machine.calibratedInfo(k).name);
      tips.push_back({{"name", named.name},
                      {"tip", tipToJson(machine, named.tip, ev.workspace)},
                      {"parameters", names}});
    }
    out["tips"] = tips;
  }
  if (!ev.profile.empty()) {
    json profile = json::array();
    for (const ProfilePoint& p : ev.profile) {
      profile.push_back({{"reach", p.reach},
                         {"total", p.tip.total},
                         {"kinematic", p.tip.kinematic},
                         {"encoder", p.tip.encoder}});
    }
    out["profile"] = profile;
  }
  return out;
}

namespace {

using report_text::format;

// Standard uncertainties read best in um for lengths, mdeg-scale decimals for angles and four
// significant digits in a coefficient's own unit (e.g. um/m).
std::string uncertaintyText(const Quantity& q, double internal) {
  if (q == Quantity::Angle) return format("%.6f deg", radToDeg(internal));
  if (q == Quantity::Length) return format("%.2f um", internal * 1000.0);
  return format("%.4g %s", toFileUnit(q, internal), std::string(unitName(q)).c_str());
}

}  // namespace

namespace {

// Where a placement's measurements see fewer rigid directions than its artifact kind has
// (docs/method.md section 5, effective N(r_j)): the table value, the effective one, and why.
std::string effectiveRigidText(const Plan& plan, const CountingCondition& c) {
  if (c.N_r == c.N_r_table) return {};
  std::ostringstream out;
  out << format("  effective N(r) = %d (table %d): the measurements of", c.N_r, c.N_r_table);
  for (std::size_t j = 0; j < c.rigid_table.size(); ++j) {
    if (c.rigid_table[j] == c.rigid_effective[j]) continue;
    const Artifact& artifact =
        plan.artifacts[static_cast<std::size_t>(plan.placements[j].artifact)];
    const std::string name = plan.placements[j].name.empty()
                                 ? format("/placements/%zu", j)
                                 : "placement " + plan.placements[j].name;
    out << format(" %s (%s) see %d of %d", name.c_str(), artifactTypeName(artifact).c_str(),
                  c.rigid_effective[j], c.rigid_table[j]);
  }
  out << " rigid directions\n";
  return out.str();
}

// One term "+c name" of a combination; "-" for a coefficient that could not be computed (a plan
// whose information overflowed): tables never print nan or inf (docs/plan-format.md).
std::string termText(bool first, double coefficient, const std::string& name) {
  const std::string number = std::isfinite(coefficient) ? format("%+.4g", coefficient) : "-";
  return (first ? "" : "  ") + number + " " + name;
}

}  // namespace

std::string tieText(const Plan& plan, const std::vector<std::pair<int, double>>& tie) {
  const auto& params = plan.machine.mechanism->parameters();
  const int first = tie.front().first;
  const bool compliance = isComplianceParameter(*plan.machine.mechanism, first);
  // Not observed at all (docs/compliance.md section 4), where the plan's set was resolved; a
  // design's set (calibrateFixText) names its ties alone.
  const CalibratedSetResolution* resolution =
      plan.calibrate_resolution ? &*plan.calibrate_resolution : nullptr;
  if (resolution &&
      std::count(resolution->unobserved.begin(), resolution->unobserved.end(), first)) {
    return compliance ? "not observed: its torque is zero at every reading (gravity along the "
                        "joint's axis, or the masses' centres on it; docs/compliance.md section 4)"
                      : "not observed: no information (sqrt(N_kk) below 1e-9 of the largest)";
  }
  if (tie.size() == 1) return "not observed, or absorbed by the placements' rigid motions";
  std::string out;
  bool ties_compliance = false;
  for (std::size_t i = 0; i < tie.size(); ++i) {
    out += termText(i == 0, tie[i].second, params[static_cast<std::size_t>(tie[i].first)].name);
    ties_compliance =
        ties_compliance || isComplianceParameter(*plan.machine.mechanism, tie[i].first);
  }
  out += "   (scaled parameters)";
  if (ties_compliance)
    out +=
        "; a compliance whose torque does not vary over the readings is the joint's offset "
        "again: vary the payloads and postures (docs/compliance.md section 4)";
  return out;
}

namespace {

// "calibrate": "identifiable" resolved: the kept set, the dropped parameters, and the
// combination tying each dropped one to the kept ones (docs/models.md section 1).
std::string calibrateSelectionText(const Plan& plan) {
  if (!plan.calibrate_resolution) return {};
  const auto& params = plan.machine.mechanism->parameters();
  const auto name = [&params](int index) { return params[static_cast<std::size_t>(index)].name; };
  const CalibratedSetResolution& resolution = *plan.calibrate_resolution;
  std::ostringstream out;
  out << format("  calibrate \"identifiable\": %zu kept, %zu dropped\n    kept:",
                resolution.kept.size(), resolution.dropped.size());
  for (int k : resolution.kept) out << " " << name(k);
  out << "\n";
  for (std::size_t d = 0; d < resolution.dropped.size(); ++d) {
    out << "    dropped " << name(resolution.dropped[d]) << ": "
        << tieText(plan, resolution.ties[d]) << "\n";
  }
  const WeakRuleChoice& weak = resolution.at_nominal;
  if (!weak.held.empty() || !weak.in_place.empty()) {
    out << "  calibrate of measured readings (the weak rule: surviving fraction < 1e-6 over every "
           "listed parameter, docs/method.md section 5) holds at nominal:";
    for (std::size_t h = 0; h < weak.held.size(); ++h)
      out << " " << name(weak.held[h]) << format(" (%.2g)", weak.held_fraction[h]);
    if (!weak.in_place.empty()) {
      out << "\n    and calibrates in their place:";
      for (int k : weak.in_place) out << " " << name(k);
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace

std::string identifiabilityTable(const Plan& plan, const Identifiability& id) {
  std::ostringstream out;
  const CountingCondition& c = id.counting;
  out << "Plan " << (plan.name.empty() ? plan.source : plan.name) << ": " << plan.placements.size()
      << " placements, " << c.N_p << " calibrated parameters\n";
  out << format("  counting condition  N(b) - N(r) = %d - %d = %d %s N(p) = %d   %s\n", c.N_b,
                c.N_r, c.N_b - c.N_r, c.satisfied ? ">=" : "<", c.N_p,
                c.satisfied ? "satisfied" : "NOT satisfied");
  out << effectiveRigidText(plan, c);
  // More placements like the first help a plan whose rank is full, and one with too few
  // equations: there they are the answer, not fixing parameters (docs/method.md section 5).
  const bool too_few_equations = !c.satisfied && c.minimum_alike > 0;
  if (too_few_equations) {
    out << format(
        "  too few equations: placements like the first needed: m >= %d (the plan has %zu)\n",
        c.minimum_alike, plan.placements.size());
  } else if (c.minimum_alike > 0 && id.deficiency == 0) {
    out << format("  placements like the first needed: m >= %d\n", c.minimum_alike);
  }
  out << format("  rank of scaled N_red  %d of %d (deficiency %d, tolerance %.0e)\n", id.rank,
                c.N_p, id.deficiency, id.tolerance);
  if (std::isfinite(id.condition_number)) {
    out << format("  condition number      %.3g\n", id.condition_number);
  }
  for (std::size_t k = 0; k < id.unidentifiable.size(); ++k) {
    const Combination& comb = id.unidentifiable[k];
    out << "  unidentifiable #" << k + 1 << ":  ";
    for (std::size_t i = 0; i < comb.names.size(); ++i) {
      out << termText(i == 0, comb.coefficients[i], comb.names[i]);
    }
    out << "   (scaled parameters)\n";
  }
  if (id.no_length_scale) {
    out << "  no length scale: the machine's change of scale (every calibrated length in "
           "proportion) is unobserved;\n  the readings hold no known length: add a ball bar, a "
           "gauge block or a second face at a known distance\n";
  }
  if (!id.to_fix.empty() && !too_few_equations) {
    out << "  more placements like these will not help; to calibrate the rest, fix:";
    for (const std::string& name : id.to_fix) out << " " << name;
    out << "\n";
  }
  out << calibrateSelectionText(plan);
  out << (id.identifiable() ? "IDENTIFIABLE\n" : "NOT IDENTIFIABLE\n");
  return out.str();
}

std::string calibrateFixText(const Plan& plan, const CalibratedSetResolution& resolution) {
  const auto& params = plan.machine.mechanism->parameters();
  const auto name = [&params](int index) { return params[static_cast<std::size_t>(index)].name; };
  std::ostringstream out;
  out << "fix (keep at nominal):";
  for (std::size_t d = 0; d < resolution.dropped.size(); ++d) {
    out << (d == 0 ? " " : "; ") << name(resolution.dropped[d]) << " ("
        << tieText(plan, resolution.ties[d]) << ")";
  }
  out << "; calibrate the " << resolution.kept.size() << " others:";
  for (int k : resolution.kept) out << " " << name(k);
  return out.str();
}

std::string evaluationTable(const Plan& plan, const Evaluation& ev) {
  std::ostringstream out;
  out << identifiabilityTable(plan, ev.identifiability);
  if (!ev.covariance) {
    out << "No uncertainties: the plan does not identify every calibrated parameter.\n";
    return out.str();
  }
  const Machine& machine = plan.machine;
  out << "\nParameter          nominal          u (standard uncertainty)\n";
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    const ParameterInfo& info = machine.calibratedInfo(k);
    const double nominal = toFileUnit(info.quantity, machine.nominal[machine.calibrated[k]]);
    out << format("  %-12s %12.4f %-4s   %s\n", info.name.c_str(), nominal,
                  std::string(unitName(info.quantity)).c_str(),
                  uncertaintyText(info.quantity, ev.covariance->u[k]).c_str());
  }
  if (machine.mechanism->hasLocationErrors())
    out << locationErrorTable(plan, *ev.covariance, nullptr);
  if (ev.tip) {
    const TipSummary& tip = *ev.tip;
    out << format("\nTip uncertainty over %zu workspace configurations (um)\n",
                  ev.workspace.size());
    out << format("  worst  S = %.2f  (S_m %.2f, S_q %.2f) at joints [", tip.worst.total * 1e3,
                  tip.worst.kinematic * 1e3, tip.worst.encoder * 1e3);
    const auto joints =
        jointsToFile(machine, ev.workspace[static_cast<std::size_t>(tip.worst_index)]);
    for (std::size_t i = 0; i < joints.size(); ++i) out << format(i ? ", %.2f" : "%.2f", joints[i]);
    out << "]\n" << format("  mean   S = %.2f    rms S = %.2f\n", tip.mean * 1e3, tip.rms * 1e3);
    if (ev.workspace_drops.total() > 0) {
      out << format(
          "  dropped %d samples: %d unreachable within the joint limits, %d forward "
          "kinematics failed\n",
          ev.workspace_drops.total(), ev.workspace_drops.unreachable, ev.workspace_drops.failed);
    }
  }
  if (!ev.tips.empty()) {
    out << "\nTip uncertainty per tip, at the same configurations (um)\n";
    for (const NamedTipSummary& named : ev.tips) {
      out << format(
          "  %s: worst S = %.2f (S_m %.2f, S_q %.2f), mean %.2f, rms %.2f; moved by %zu "
          "of the calibrated parameters\n",
          named.name.c_str(), named.tip.worst.total * 1e3, named.tip.worst.kinematic * 1e3,
          named.tip.worst.encoder * 1e3, named.tip.mean * 1e3, named.tip.rms * 1e3,
          named.calibrated.size());
    }
  }
  if (!ev.profile.empty()) {
    out << "\nTip uncertainty against reach (seed Fig. 6; worse elbow branch)\n";
    out << "  reach mm     S_m um    S_q um      S um\n";
    for (const ProfilePoint& p : ev.profile) {
      out << format("  %8.1f  %9.2f %9.2f %9.2f\n", p.reach, p.tip.kinematic * 1e3,
                    p.tip.encoder * 1e3, p.tip.total * 1e3);
    }
  }
  return out.str();
}

}  // namespace artcal
