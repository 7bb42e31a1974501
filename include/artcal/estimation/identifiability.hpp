#pragma once
// Identifiability (method.md section 5).
//
// The counting condition sum_j (N(b_j) - N(r_j)) >= N(p) is necessary, not sufficient. The real
// test is the numerical rank of the information of p, N_red, after scaling its columns (and rows)
// to a unit diagonal: eigenvalues below `tolerance` times the largest mark a deficiency, and
// their eigenvectors are the parameter combinations the plan cannot separate. The null space is
// reported in reduced row-echelon form, so that a parameter that is unidentifiable on its own
// (j1.theta of a serial arm) appears alone, and the coefficients are in the scaled parameters
// (each divided by the standard deviation its diagonal alone would give).
//
// A parameter that no observation touches has a zero diagonal: it is reported alone, deficient.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/plan/plan.hpp"

namespace artcal {

struct CountingCondition {
  int N_p = 0;  ///< calibrated parameters
  int N_b = 0;  ///< valued coordinates observed, sum of n o k
  int N_r = 0;  ///< rigid-motion unknowns, sum of N(r_j)
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
  bool identifiable() const { return counting.satisfied && deficiency == 0; }
};

inline constexpr double kDefaultRankTolerance = 1e-10;

CountingCondition countingCondition(const Plan& plan, const std::vector<Placement>& placements);

Identifiability analyseIdentifiability(const Plan& plan, const std::vector<Placement>& placements,
                                       const Eigen::MatrixXd& information,
                                       double tolerance = kDefaultRankTolerance);

}  // namespace artcal
