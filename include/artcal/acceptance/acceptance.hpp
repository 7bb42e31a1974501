#pragma once
// What an acceptance-test prediction starts from (docs/method.md section 9): the calibrated machine
// (its parameters), the covariance V_p of its calibrated parameters (a plan's predicted one, or
// a machine file's), and the noise of the readings (the plan's: probing per point, encoders per
// reading). Parameters outside the covariance are taken as exact.

#include <Eigen/Core>
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "artcal/calibration/verification.hpp"
#include "artcal/estimation/evaluation_result.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// One micrometre in mm (the unit of E and the MPE in outputs).
inline constexpr double kMmPerMicrometre = 1e-3;

struct AcceptanceInput {
  std::string source;  ///< the plan file, for messages
  const Machine* machine = nullptr;
  Eigen::VectorXd parameters;        ///< full vector, internal units
  ParameterUncertainty uncertainty;  ///< V_p over uncertainty.indices, internal units
  Noise noise;
  /// The configurations the inverse kinematics may start from (ISO 9283); the plan's workspace.
  std::vector<Eigen::VectorXd> workspace;
};

/// The plan's nominal machine with covariance V over its calibrated parameters and the plan's
/// noise (no workspace).
AcceptanceInput acceptanceInputAtNominal(const Plan& plan, Eigen::MatrixXd V);

/// The plan's own prediction: nominal parameters, the evaluator's V_p, the plan's noise and
/// workspace. std::nullopt when the plan does not identify its calibrated parameters.
std::optional<AcceptanceInput> acceptanceInputFromPlan(const Plan& plan,
                                                       const Evaluation& evaluation);

/// The plan evaluated (evaluatePlan), then acceptanceInputFromPlan: what `artcal acceptance PLAN`
/// and the Python module predict from. InputError naming `source` when the plan does not
/// identify its calibrated parameters.
AcceptanceInput evaluatedAcceptanceInput(const Plan& plan, const std::string& source);

/// A calibrated machine: its parameters and covariance (times birge_ratio^2 when `posterior`
/// and the ratio is known), the noise and workspace of the plan it was calibrated from.
AcceptanceInput acceptanceInputFromMachine(const Plan& plan, const Eigen::VectorXd& parameters,
                                           ParameterUncertainty uncertainty, bool posterior);

/// The maximum permissible error E0,MPE = A + L / K of ISO 10360-2: A in um, L in mm, L / K in
/// um. Kept in mm: `a` = A in mm; K = 0 means a constant MPE.
struct Mpe {
  double a = 0.0;    ///< mm
  double k = 0.0;    ///< dimensionless (L in mm gives L / K in um), 0: no length term
  double cap = 0.0;  ///< mm: min(A + L/K, C), 0: no cap
  /// MPE(L) in mm for L in mm.
  double at(double length) const {
    const double value = k > 0.0 ? a + length / k * kMmPerMicrometre : a;
    return cap > 0.0 ? std::min(value, cap) : value;
  }
  /// "1.5 + L/333", "min(1.5 + L/333, 4)" (A and C in um).
  std::string text() const;
};

/// Parses "A", "A + L/K", "A + B*L" (K = 1/B) or either inside "min(..., C)" (A, C in um, B in
/// um/mm, L in mm, K dimensionless; spaces free); std::nullopt and `error` set when malformed,
/// A, B or K <= 0, C < A, or not finite.
std::optional<Mpe> parseMpe(const std::string& text, std::string* error = nullptr);

/// The columns `indices` of a full-parameter Jacobian.
Eigen::MatrixXd calibratedColumns(const Eigen::MatrixXd& J_full, const std::vector<int>& indices);

/// A factor F with F F^T = V for V symmetric positive semi-definite (Q sqrt(Lambda) of its
/// eigen-decomposition, negative round-off eigenvalues taken as 0), so that a singular V, e.g.
/// V_p = 0, is allowed.
Eigen::MatrixXd covarianceFactor(const Eigen::MatrixXd& V);

/// E|b| for b ~ N(0, covariance), covariance symmetric positive semi-definite (negative round-off
/// eigenvalues taken as 0). With lambda_i its eigenvalues, |b|^2 = sum_i lambda_i z_i^2, and
/// sqrt(s) = 1/(2 sqrt(pi)) int_0^inf (1 - e^(-t s)) t^(-3/2) dt with E e^(-t |b|^2) =
/// prod_i (1 + 2 t lambda_i)^(-1/2) give the one-dimensional integral
///   E|b| = 1/(2 sqrt(pi)) int_0^inf (1 - prod_i (1 + 2 t lambda_i)^(-1/2)) t^(-3/2) dt,
/// computed by the trapezoidal rule in log t (exponentially convergent: the integrand decays
/// exponentially in log t at both ends). sigma sqrt(2/pi) in 1-D, 2 sigma sqrt(2/pi) for sigma^2
/// I_3.
double expectedGaussianNorm(const Eigen::MatrixXd& covariance);

}  // namespace artcal
