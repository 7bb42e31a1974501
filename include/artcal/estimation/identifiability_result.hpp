#pragma once
// What the identifiability analysis answers (identifiability.hpp computes it, docs/method.md
// section 5): plain result types, so that a reader of results (report/) includes no computation.

#include <string>
#include <vector>

namespace artcal {

struct CountingCondition {
  int N_p = 0;                       ///< calibrated parameters
  int N_b = 0;                       ///< valued coordinates observed, sum of n o k
  int N_r = 0;                       ///< rigid-motion unknowns, sum of the effective N(r_j)
  int N_r_table = 0;                 ///< sum of the table values N(r_j) of the artifact kinds
  std::vector<int> rigid_table;      ///< per placement, the table value
  std::vector<int> rigid_effective;  ///< per placement, the rank of its rigid block
  bool satisfied = false;
  /// Placements needed when all are alike the first one: ceil(N_p / (n o k - N(r))), or -1
  /// when a placement gives no more equations than unknowns.
  int minimum_alike = -1;
};

struct Combination {
  std::vector<std::string> names;
  std::vector<double> coefficients;  ///< scaled parameters, largest magnitude 1
};

struct Identifiability {
  CountingCondition counting;
  int rank = 0;
  int deficiency = 0;
  double condition_number = 0.0;  ///< of the scaled N_red (largest / smallest eigenvalue)
  double tolerance = 0.0;
  std::vector<Combination> unidentifiable;
  /// When deficient: the calibrated parameters to fix (keep at nominal) so that the rest is
  /// identifiable with these placements (chooseIdentifiableSet in the plan's order).
  std::vector<std::string> to_fix;
  /// The machine's change of scale (every calibrated length in proportion to its nominal value,
  /// angles unchanged) keeps less than `tolerance` of its information: nothing in the plan fixes
  /// a length (a single plane's touches: docs/planes.md). Never set when no length is calibrated.
  bool no_length_scale = false;
  bool identifiable() const { return counting.satisfied && deficiency == 0; }
};

}  // namespace artcal
