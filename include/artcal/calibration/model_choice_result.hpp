#pragma once
// What calibrate's held-out model choice found (model_choice.hpp): the candidate kept sets, the
// held-out error each predicts and shows, and which rule chose. Plain data, read by the report.

#include <string>
#include <vector>

#include "artcal/core/enum_names.hpp"

namespace artcal {

/// How `"calibrate": "identifiable"` settles the kept set of measured readings.
enum class ModelChoiceMode {
  HeldOut,  ///< the rank rule's set, or a smaller one of its order when held-out readings say so
  Rank,     ///< the rank rule alone (information only), as before the held-out choice
};

inline constexpr EnumNames<ModelChoiceMode, 2> kModelChoiceModeNames{
    {{ModelChoiceMode::HeldOut, "held-out"}, {ModelChoiceMode::Rank, "rank"}}};

/// The rule that judged the candidates.
enum class ModelChoiceRule {
  CrossValidation,       ///< leave one placement (station) out, 2 placements or more
  InformationCriterion,  ///< Mallows' Cp, fewer placements
};

inline constexpr EnumNames<ModelChoiceRule, 2> kModelChoiceRuleNames{
    {{ModelChoiceRule::CrossValidation, "leave-one-placement-out"},
     {ModelChoiceRule::InformationCriterion, "mallows-cp"}}};

/// One candidate kept set: the first `size` parameters of the rank rule's order by information
/// (the weakest removed first).
struct ModelChoiceCandidate {
  int size = 0;
  /// The parameter (model index) this candidate holds at nominal beyond the next larger one, and
  /// its surviving fraction of information in that larger set; -1 and 0 for the rank rule's set.
  int removed = -1;
  double removed_fraction = 0.0;
  /// The parameters the weak-direction rule held at nominal that this candidate calibrates again
  /// (model indices; empty but for the one candidate of the rank rule's set with them restored).
  std::vector<int> restored;
  /// The rank rule's set without its compliances (docs/compliance.md section 5): geometric only,
  /// beside the rank rule's geometric + compliance.
  bool geometric_only = false;
  /// Its fit corrects a parameter beyond the plausibility rule (corrections.hpp): never chosen.
  bool implausible = false;
  std::vector<int> kept;  ///< model parameter indices
  bool converged = false;
  double chi2_per_dof = 0.0;  ///< of its fit to every reading
  /// Held-out chi2 per held-out degree of freedom (whitened with the stated noise, 1): what the
  /// fit predicts for readings that scatter as its own (chi2/dof times 1 + the estimate's share)
  /// and what the left-out placements show (cross-validation) or Cp's estimate of it.
  double predicted = 0.0;
  double observed = 0.0;
  std::vector<double> fold_observed;  ///< per placement left out (cross-validation only)
  bool chosen = false;
};

struct ModelChoice {
  ModelChoiceRule rule = ModelChoiceRule::CrossValidation;
  int folds = 0;      ///< placements left out in turn (0: information criterion)
  int rank_size = 0;  ///< the rank rule's kept count
  std::vector<ModelChoiceCandidate> candidates;  ///< largest first; [0] is the rank rule's set
  int chosen = 0;                                ///< index into candidates
  /// "rank rule" or the rule's name: who decided the kept set.
  std::string decided_by;
  std::string reason;  ///< one sentence: why this candidate
  /// Whitened units to mm (the probe noise) when the readings' only noise is the probe's; 0
  /// otherwise (the errors are then given in the stated noise's units only).
  double mm_per_unit = 0.0;
};

}  // namespace artcal
