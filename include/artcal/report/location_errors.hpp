#pragma once
// The machine-tool engineer's answers (docs/five-axis.md), for models whose parameters are ISO
// 230-7 location errors (Mechanism::hasLocationErrors): each location error with u in deg and
// urad or mm and um and the confounding index F_k; after a calibration, the controller table (one
// row per axis: its offsets in mm and orientation errors in deg, the values of the estimate).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

#include "artcal/estimation/evaluation_result.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// The location errors with u (and the estimate when `estimate` is not null, a full parameter
/// vector) and F_k, and the hint "F <= 2: well separated".
std::string locationErrorTable(const Plan& plan, const ParameterCovariance& covariance,
                               const Eigen::VectorXd* estimate);
nlohmann::json locationErrorsToJson(const Plan& plan, const ParameterCovariance& covariance,
                                    const Eigen::VectorXd* estimate);
/// The controller table of the full parameter vector `parameters` (internal units).
std::string controllerTable(const Plan& plan, const Eigen::VectorXd& parameters);
nlohmann::json controllerTableToJson(const Plan& plan, const Eigen::VectorXd& parameters);

}  // namespace artcal
