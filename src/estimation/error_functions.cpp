#include "artcal/estimation/error_functions.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "artcal/core/linear_algebra.hpp"

namespace artcal {

namespace {

// Position of each full parameter index in the calibrated list, -1 when not calibrated.
std::vector<int> calibratedPositions(const Machine& machine) {
  std::vector<int> where(static_cast<std::size_t>(machine.mechanism->parameterCount()), -1);
  for (int k = 0; k < machine.calibratedCount(); ++k) {
    where[static_cast<std::size_t>(machine.calibrated[static_cast<std::size_t>(k)])] = k;
  }
  return where;
}

// The model's error-function layout; a model without one is the caller's mistake.
const AxisErrorFunctions& axisErrorsOf(const Mechanism& model) {
  const AxisErrorFunctions* layout = model.axisErrorFunctions();
  if (!layout)
    throw std::logic_error("error functions of model " + model.modelName() +
                           ", which has none (Mechanism::axisErrorFunctions)");
  return *layout;
}

}  // namespace

std::vector<ErrorFunctionProfile> errorFunctionProfiles(const Machine& machine,
                                                        const Eigen::MatrixXd& V,
                                                        const Eigen::VectorXd& p, int steps) {
  const AxisErrorFunctions& cmm = axisErrorsOf(*machine.mechanism);
  const std::vector<int> where = calibratedPositions(machine);
  const int degree = cmm.degree();
  std::vector<double> P(static_cast<std::size_t>(degree + 1)), dP(P.size());
  std::vector<ErrorFunctionProfile> out;
  steps = std::max(steps, 2);
  for (int k = 0; k < static_cast<int>(cmm.axes().size()); ++k) {
    const CartesianAxis& axis = cmm.axes()[static_cast<std::size_t>(k)];
    for (int e = 0; e < kAxisErrorCount; ++e) {
      ErrorFunctionProfile profile;
      profile.axis = k;
      profile.error = static_cast<AxisError>(e);
      profile.name = axis.name + "." + axisErrorName(profile.error);
      profile.meaning = axisErrorMeaning(axis.direction, profile.error);
      profile.rotation = e >= 3;
      std::vector<int> rows;  // positions in V of the calibrated degrees
      for (int n = 1; n <= degree; ++n) {
        const int at = where[static_cast<std::size_t>(cmm.parameterIndex(k, profile.error, n))];
        (at >= 0 ? profile.calibrated_degrees : profile.fixed_degrees).push_back(n);
        if (at >= 0) rows.push_back(at);
      }
      for (int i = 0; i < steps; ++i) {
        const double u =
            axis.range[0] + (axis.range[1] - axis.range[0]) * i / static_cast<double>(steps - 1);
        legendre(degree, cmm.normalised(k, u), P.data(), dP.data());
        double value = 0.0;
        for (int n = 1; n <= degree; ++n) {
          value += P[static_cast<std::size_t>(n)] * p[cmm.parameterIndex(k, profile.error, n)];
        }
        // g^T V_e g over the calibrated degrees.
        double variance = 0.0;
        for (std::size_t a = 0; a < rows.size(); ++a) {
          const double ga = P[static_cast<std::size_t>(profile.calibrated_degrees[a])];
          for (std::size_t b = 0; b < rows.size(); ++b) {
            const double gb = P[static_cast<std::size_t>(profile.calibrated_degrees[b])];
            variance += ga * V(rows[a], rows[b]) * gb;
          }
        }
        profile.position.push_back(u);
        profile.value.push_back(value);
        profile.u.push_back(std::sqrt(std::max(variance, 0.0)));
      }
      out.push_back(std::move(profile));
    }
  }
  return out;
}

Eigen::VectorXd frameRotationDirection(const Mechanism& model, const Eigen::Vector3d& w) {
  const AxisErrorFunctions& cmm = axisErrorsOf(model);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(model.parameterCount());
  for (std::size_t k = 0; k < cmm.axes().size(); ++k) {
    const CartesianAxis& axis = cmm.axes()[k];
    const double half_width = 0.5 * (axis.range[1] - axis.range[0]);
    v.segment<3>(cmm.parameterIndex(static_cast<int>(k), AxisError::Tx, 1)) =
        w.cross(axis.direction) * half_width;
  }
  return v;
}

std::vector<AbsorbedRotation> frameRotationsAbsorbed(const Mechanism& model,
                                                     const PlanInformation& information,
                                                     double tolerance) {
  // The rank test's matrix (identifiability.hpp): S = D^-1/2 N_red D^-1/2 with D the unreduced
  // diagonal, an unobserved parameter's row and column 0; the direction v_w in the same scaled
  // coordinates, y_w = D^1/2 v_w. The Rayleigh quotient y^T S y / y^T y is then the fraction of
  // the rotation's own information that survives, compared absolutely as every rank decision.
  const Eigen::MatrixXd S = scaledInformation(information);
  const Eigen::VectorXd root = information.unreduced_diagonal.cwiseMax(0.0).cwiseSqrt();
  Eigen::MatrixXd Y(S.rows(), 3);
  for (int a = 0; a < 3; ++a) {
    Y.col(a) = root.asDiagonal() * frameRotationDirection(model, Eigen::Vector3d::Unit(a));
  }
  // The rotations w minimising w^T (Y^T S Y) w / w^T (Y^T Y) w: the generalized eigenproblem.
  const Eigen::Matrix3d A = Y.transpose() * S * Y;
  const Eigen::Matrix3d B = Y.transpose() * Y;
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix3d> solver(A, B);
  std::vector<Eigen::Vector3d> axes;
  for (int a = 0; a < 3; ++a) {
    if (!(solver.eigenvalues()[a] > tolerance)) {
      axes.push_back(solver.eigenvectors().col(a).normalized());
    }
  }
  // Every rotation absorbed (one stylus): the machine axes are as good a basis as any.
  if (axes.size() == 3)
    axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
  std::vector<AbsorbedRotation> out;
  for (const Eigen::Vector3d& axis : axes) {
    AbsorbedRotation rotation;
    rotation.axis = axis;
    // Sign: the largest component positive, so that "about x" reads as +x; of components equal
    // up to rounding (a diagonal), the last, so that rounding does not flip the axis.
    const double largest = rotation.axis.cwiseAbs().maxCoeff();
    int at = 2;
    while (std::abs(rotation.axis[at]) < largest - 1e-9) --at;
    if (rotation.axis[at] < 0.0) rotation.axis = -rotation.axis;
    const Eigen::VectorXd v = frameRotationDirection(model, rotation.axis);
    for (int i = 0; i < v.size(); ++i) {
      if (std::abs(v[i]) > 1e-9 * v.cwiseAbs().maxCoeff()) {
        rotation.involves.push_back(model.parameters()[static_cast<std::size_t>(i)].name);
      }
    }
    out.push_back(std::move(rotation));
  }
  return out;
}

}  // namespace artcal
