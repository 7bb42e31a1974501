#include "artcal/report/model_choice_report.hpp"

#include <cmath>
#include <sstream>

#include "artcal/report/report.hpp"
#include "artcal/report/text_format.hpp"

namespace artcal {

using nlohmann::json;

namespace {

const std::string& parameterName(const Plan& plan, int index) {
  return plan.machine.mechanism->parameters()[static_cast<std::size_t>(index)].name;
}

// Held-out chi2 per degree of freedom as an rms in mm (whitened rms times the probe noise), or
// null where the readings carry other noise than the probe's.
json rmsMm(const ModelChoice& choice, double chi2_per_dof) {
  if (!(choice.mm_per_unit > 0.0)) return nullptr;
  return finiteOrNull(choice.mm_per_unit * std::sqrt(std::max(0.0, chi2_per_dof)));
}

std::string cell(const json& value, const char* pattern) {
  return value.is_number() ? report_text::format(pattern, value.get<double>()) : "-";
}

}  // namespace

json modelChoiceToJson(const Plan& plan, const ModelChoice& choice) {
  json candidates = json::array();
  for (const ModelChoiceCandidate& c : choice.candidates) {
    json folds = json::array();
    for (const double f : c.fold_observed) folds.push_back(finiteOrNull(f));
    json restored = json::array();
    for (const int r : c.restored) restored.push_back(parameterName(plan, r));
    candidates.push_back(
        {{"size", c.size},
         {"held_at_nominal", c.removed >= 0 ? json(parameterName(plan, c.removed)) : json(nullptr)},
         {"surviving_fraction", c.removed >= 0 ? finiteOrNull(c.removed_fraction) : json(nullptr)},
         {"restored", restored},
         {"geometric_only", c.geometric_only},
         {"converged", c.converged},
         {"implausible", c.implausible},
         {"chi2_per_dof", finiteOrNull(c.chi2_per_dof)},
         {"predicted", finiteOrNull(c.predicted)},
         {"observed", finiteOrNull(c.observed)},
         {"observed_per_fold", folds},
         {"predicted_rms_mm", rmsMm(choice, c.predicted)},
         {"observed_rms_mm", rmsMm(choice, c.observed)},
         {"chosen", c.chosen}});
  }
  return {{"decided_by", choice.decided_by},
          {"rule", nameOf(kModelChoiceRuleNames, choice.rule)},
          {"folds", choice.folds},
          {"rank_rule_size", choice.rank_size},
          {"reason", choice.reason},
          {"unit", "held-out chi2 per degree of freedom (1); rms in mm"},
          {"candidates", candidates}};
}

std::string modelChoiceTable(const Plan& plan, const ModelChoice& choice) {
  std::ostringstream out;
  const json document = modelChoiceToJson(plan, choice);
  out << "\nkept set chosen by " << (choice.chosen == 0 ? "the " : "") << choice.decided_by << ": "
      << choice.reason << "\n";
  const bool cv = choice.rule == ModelChoiceRule::CrossValidation;
  out << (cv ? "held out: each of the " + std::to_string(choice.folds) +
                   " placements left out in turn (observed: its readings, not fitted)"
             : std::string("one placement, none to leave out: Mallows' Cp (observed: Cp's "
                           "estimate)"))
      << "; chi2 per degree of freedom (1), rms in mm\n";
  std::size_t width = 28;
  // The parameter a candidate holds at nominal, or "+ ..." the ones it calibrates again.
  auto label = [](const json& c) {
    if (c["geometric_only"].get<bool>()) return std::string("(geometric only: compliances)");
    if (c["held_at_nominal"].is_string()) return c["held_at_nominal"].get<std::string>();
    if (c["restored"].empty()) return std::string("(rank rule)");
    std::string out = "+";
    for (const json& name : c["restored"]) out.append(" ").append(name.get<std::string>());
    return out;
  };
  for (const json& c : document["candidates"]) width = std::max(width, label(c).size());
  out << "size  " << std::string("held at nominal (+ restored)").append(width - 28, ' ')
      << "  fraction  chi2/dof  predicted  observed  predicted_rms  observed_rms  chosen\n";
  for (const json& c : document["candidates"]) {
    const std::string held = label(c);
    out << report_text::format("%4d  ", c["size"].get<int>()) << held
        << std::string(width - held.size(), ' ') << "  "
        << report_text::format("%8s", cell(c["surviving_fraction"], "%.1e").c_str())
        << report_text::format("  %8s", cell(c["chi2_per_dof"], "%.4g").c_str())
        << report_text::format("  %9s", cell(c["predicted"], "%.4g").c_str())
        << report_text::format("  %8s", cell(c["observed"], "%.4g").c_str())
        << report_text::format("  %13s", cell(c["predicted_rms_mm"], "%.4f").c_str())
        << report_text::format("  %12s", cell(c["observed_rms_mm"], "%.4f").c_str())
        << (c["chosen"].get<bool>() ? "  *" : "")
        << (c["converged"].get<bool>() ? "" : "  (not converged)")
        << (c["implausible"].get<bool>() ? "  (implausible correction)" : "") << "\n";
  }
  const ModelChoiceCandidate& chosen = choice.candidates[static_cast<std::size_t>(choice.chosen)];
  if (chosen.geometric_only) {
    out << "held at nominal by the held-out choice: the compliances (geometric only)\n";
  } else if (!chosen.restored.empty()) {
    out << "calibrated again by the held-out choice (the weak-direction rule had held them):";
    for (const int r : chosen.restored) out << " " << parameterName(plan, r);
    out << "\n";
  } else if (choice.chosen > 0) {
    out << "held at nominal by the held-out choice:";
    for (int i = 1; i <= choice.chosen; ++i)
      out << " " << parameterName(plan, choice.candidates[static_cast<std::size_t>(i)].removed);
    out << "\n";
  }
  return out.str();
}

}  // namespace artcal
