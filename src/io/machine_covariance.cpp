#include "artcal/io/machine_covariance.hpp"

#include <cmath>
#include <set>

#include "artcal/core/linear_algebra.hpp"
#include "artcal/io/json_node.hpp"

namespace artcal {

namespace {

/// File-unit value per internal unit of a parameter (1 for mm, 180/pi for deg).
double fileScale(const ParameterInfo& info) {
  return toFileUnit(info.quantity, 1.0);
}

}  // namespace

nlohmann::json covarianceToJson(const Machine& machine, const Eigen::MatrixXd& V,
                                double birge_ratio) {
  nlohmann::json names = nlohmann::json::array();
  nlohmann::json matrix = nlohmann::json::array();
  const int n = machine.calibratedCount();
  for (int i = 0; i < n; ++i) {
    names.push_back(machine.calibratedInfo(i).name);
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j < n; ++j) {
      row.push_back(V(i, j) * fileScale(machine.calibratedInfo(i)) *
                    fileScale(machine.calibratedInfo(j)));
    }
    matrix.push_back(row);
  }
  nlohmann::json out = {{"parameters", names}, {"matrix", matrix}};
  if (birge_ratio > 0.0 && std::isfinite(birge_ratio)) out["birge_ratio"] = birge_ratio;
  return out;
}

nlohmann::json covarianceToJson(const Machine& machine, const ParameterUncertainty& uncertainty) {
  nlohmann::json out = covarianceToJson(machine, uncertainty.V, uncertainty.birge_ratio);
  if (uncertainty.probe_noise > 0.0 && std::isfinite(uncertainty.probe_noise))
    out["probe_noise"] = uncertainty.probe_noise;
  if (uncertainty.unmodelled > 0.0 && std::isfinite(uncertainty.unmodelled))
    out["unmodelled"] = uncertainty.unmodelled;
  return out;
}

std::optional<ParameterUncertainty> parseMachineCovariance(const nlohmann::json& document,
                                                           const std::string& source,
                                                           const Plan& plan) {
  const Node root(document, "", source);
  root.object();
  const auto covariance = root.find("covariance");
  if (!covariance) return std::nullopt;
  covariance->object();
  const Mechanism& mech = *plan.machine.mechanism;
  const Node names = covariance->at("parameters");
  const std::size_t n = names.arraySize(1, static_cast<std::size_t>(mech.parameterCount()));
  ParameterUncertainty out;
  std::set<int> seen;
  for (std::size_t i = 0; i < n; ++i) {
    const std::string name = names[i].string();
    const int index = mech.parameterIndex(name);
    if (index < 0) names[i].fail("unknown parameter \"" + name + "\" of " + mech.modelName());
    if (!seen.insert(index).second) names[i].fail("parameter \"" + name + "\" named twice");
    out.indices.push_back(index);
  }
  const Node matrix = covariance->at("matrix");
  matrix.arraySize(n, n);
  out.V.resize(static_cast<int>(n), static_cast<int>(n));
  for (std::size_t i = 0; i < n; ++i) {
    // Variances: the square of a number's bound bounds them.
    const Eigen::VectorXd row = matrix[i].finiteNumbers(n);
    if (row.cwiseAbs().maxCoeff() > kMaxInputMagnitude * kMaxInputMagnitude) {
      matrix[i].fail("an entry beyond " +
                     nlohmann::json(kMaxInputMagnitude * kMaxInputMagnitude).dump() +
                     ": check the covariance and its units (mm^2, deg^2)");
    }
    const double si = fileScale(mech.parameters()[static_cast<std::size_t>(out.indices[i])]);
    for (std::size_t j = 0; j < n; ++j) {
      const double sj = fileScale(mech.parameters()[static_cast<std::size_t>(out.indices[j])]);
      out.V(static_cast<int>(i), static_cast<int>(j)) = row[static_cast<int>(j)] / (si * sj);
    }
  }
  const double scale = out.V.cwiseAbs().maxCoeff();
  if (!(out.V - out.V.transpose()).isZero(1e-9 * scale)) matrix.fail("expected a symmetric matrix");
  const SymmetricEigenSolver eigen(out.V);
  if (eigen.eigenvalues().minCoeff() < -1e-9 * std::max(scale, 1e-300))
    matrix.fail("expected a positive semi-definite matrix");
  if (const auto birge = covariance->find("birge_ratio")) out.birge_ratio = birge->positive();
  if (const auto noise = covariance->find("probe_noise")) out.probe_noise = noise->positive();
  if (const auto unmodelled = covariance->find("unmodelled")) {
    out.unmodelled = unmodelled->number();
    if (out.unmodelled < 0.0) unmodelled->fail("expected the unmodelled error in mm, >= 0");
  }
  return out;
}

}  // namespace artcal
