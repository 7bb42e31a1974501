#include "artcal/acceptance/acceptance.hpp"

#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>
#include <regex>
#include <sstream>

#include "artcal/core/error.hpp"
#include "artcal/core/linear_algebra.hpp"
#include "artcal/core/units.hpp"
#include "artcal/estimation/evaluator.hpp"

namespace artcal {

AcceptanceInput acceptanceInputAtNominal(const Plan& plan, Eigen::MatrixXd V) {
  AcceptanceInput input;
  input.source = plan.source;
  input.machine = &plan.machine;
  input.parameters = plan.machine.nominal;
  input.uncertainty.indices = plan.machine.calibrated;
  input.uncertainty.V = std::move(V);
  input.noise = plan.noise;
  return input;
}

std::optional<AcceptanceInput> acceptanceInputFromPlan(const Plan& plan,
                                                       const Evaluation& evaluation) {
  if (!evaluation.identifiable()) return std::nullopt;
  AcceptanceInput input = acceptanceInputAtNominal(plan, evaluation.covariance->V);
  input.workspace = evaluation.workspace;
  return input;
}

AcceptanceInput evaluatedAcceptanceInput(const Plan& plan, const std::string& source) {
  auto input = acceptanceInputFromPlan(plan, evaluatePlan(plan));
  if (!input)
    throw InputError(source, "/placements",
                     "the plan does not identify its calibrated parameters (no V_p): run "
                     "`artcal evaluate` and follow its advice");
  return std::move(*input);
}

AcceptanceInput acceptanceInputFromMachine(const Plan& plan, const Eigen::VectorXd& parameters,
                                           ParameterUncertainty uncertainty, bool posterior) {
  AcceptanceInput input;
  input.source = plan.source;
  input.machine = &plan.machine;
  input.parameters = parameters;
  if (posterior && uncertainty.birge_ratio > 0.0)
    uncertainty.V *= uncertainty.birge_ratio * uncertainty.birge_ratio;
  input.uncertainty = std::move(uncertainty);
  input.noise = plan.noise;
  input.workspace = workspaceConfigurations(plan.machine, plan.workspace);
  return input;
}

std::string Mpe::text() const {
  std::ostringstream out;
  if (cap > 0.0) out << "min(";
  out << a / kMmPerMicrometre;
  if (k > 0.0) out << " + L/" << k;
  if (cap > 0.0) out << ", " << cap / kMmPerMicrometre << ")";
  return out.str();
}

std::optional<Mpe> parseMpe(const std::string& text, std::string* error) {
  // The datasheet forms (docs/method.md section 9), spaces free: "A", "A + L/K", "A + B*L" (B in
  // um per mm: K = 1/B), and either inside "min(..., C)" (C in um, the cap); numbers unsigned.
  static const std::string number = R"(([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?))";
  static const std::string inner = number + R"((?:\+L/)" + number + R"(|\+)" + number + R"(\*?L)?)";
  static const std::regex pattern("(?:" + inner + R"(|min\()" + inner + "," + number + R"(\)))");
  std::string compact;
  for (const char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) compact += c;
  std::smatch match;
  auto fail = [error](const std::string& message) -> std::optional<Mpe> {
    if (error) *error = message;
    return std::nullopt;
  };
  if (!std::regex_match(compact, match, pattern))
    return fail("MPE \"" + text +
                "\" is not of the form \"A + L/K\", \"A + B*L\" or \"min(A + L/K, C)\" (A, C in "
                "um, B in um/mm, L in mm)");
  const int at = match[1].matched ? 1 : 4;  // the form without min( or within it
  Mpe mpe;
  mpe.a = std::stod(match[at].str()) * kMmPerMicrometre;
  if (!(mpe.a > 0.0) || !std::isfinite(mpe.a)) return fail("MPE's A must be a number > 0 (um)");
  if (match[at + 1].matched) {
    mpe.k = std::stod(match[at + 1].str());
    if (!(mpe.k > 0.0) || !std::isfinite(mpe.k)) return fail("MPE's K must be a number > 0");
  } else if (match[at + 2].matched) {
    const double b = std::stod(match[at + 2].str());
    if (!(b > 0.0) || !std::isfinite(1.0 / b)) return fail("MPE's B must be a number > 0 (um/mm)");
    mpe.k = 1.0 / b;
  }
  if (match[7].matched) {
    mpe.cap = std::stod(match[7].str()) * kMmPerMicrometre;
    if (!(mpe.cap >= mpe.a) || !std::isfinite(mpe.cap))
      return fail("MPE's cap C must be a number at least A (um)");
  }
  return mpe;
}

Eigen::MatrixXd calibratedColumns(const Eigen::MatrixXd& J_full, const std::vector<int>& indices) {
  Eigen::MatrixXd J(J_full.rows(), static_cast<Eigen::Index>(indices.size()));
  for (std::size_t k = 0; k < indices.size(); ++k)
    J.col(static_cast<Eigen::Index>(k)) = J_full.col(indices[k]);
  return J;
}

Eigen::MatrixXd covarianceFactor(const Eigen::MatrixXd& V) {
  if (V.size() == 0) return Eigen::MatrixXd(V.rows(), 0);
  const SymmetricEigenSolver solver(0.5 * (V + V.transpose()));
  const Eigen::VectorXd roots = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return solver.eigenvectors() * roots.asDiagonal();
}

double expectedGaussianNorm(const Eigen::MatrixXd& covariance) {
  if (covariance.size() == 0) return 0.0;
  const SymmetricEigenSolver solver(0.5 * (covariance + covariance.transpose()),
                                    Eigen::EigenvaluesOnly);
  const Eigen::VectorXd lambda = solver.eigenvalues().cwiseMax(0.0);
  const double largest = lambda.maxCoeff();
  if (!std::isfinite(largest)) return std::numeric_limits<double>::quiet_NaN();
  if (largest <= 0.0) return 0.0;
  // t = e^u / largest, dt = t du: the integrand in u is (1 - prod) t^(-1/2); |u| <= 60 leaves
  // tails below e^-30 of the result.
  constexpr double kStep = 0.05, kEnd = 60.0;
  double sum = 0.0;
  for (double u = -kEnd; u <= kEnd + 0.5 * kStep; u += kStep) {
    const double t = std::exp(u) / largest;
    // 1 - prod without cancellation at small t: -expm1(-1/2 sum log1p(2 t lambda)).
    double log_sum = 0.0;
    for (const double l : lambda) log_sum += std::log1p(2.0 * t * l);
    sum += -std::expm1(-0.5 * log_sum) / std::sqrt(t);
  }
  return sum * kStep / (2.0 * std::sqrt(std::numbers::pi));
}

}  // namespace artcal
