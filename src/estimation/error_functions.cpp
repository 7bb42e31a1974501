#include "artcal/estimation/error_functions.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

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

}  // namespace

std::vector<ErrorFunctionProfile> errorFunctionProfiles(const Cartesian& cmm,
                                                        const Machine& machine,
                                                        const Eigen::MatrixXd& V,
                                                        const Eigen::VectorXd& p, int steps) {
  const std::vector<int> where = calibratedPositions(machine);
  const int degree = cmm.degree();
  std::vector<double> P(static_cast<std::size_t>(degree + 1)), dP(P.size());
  std::vector<ErrorFunctionProfile> out;
  steps = std::max(steps, 2);
  for (int k = 0; k < cmm.jointCount(); ++k) {
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

Eigen::VectorXd frameRotationDirection(const Cartesian& cmm, const Eigen::Vector3d& w) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(cmm.parameterCount());
  for (int k = 0; k < cmm.jointCount(); ++k) {
    const CartesianAxis& axis = cmm.axes()[static_cast<std::size_t>(k)];
    const double half_width = 0.5 * (axis.range[1] - axis.range[0]);
    v.segment<3>(cmm.parameterIndex(k, AxisError::Tx, 1)) = w.cross(axis.direction) * half_width;
  }
  return v;
}

std::vector<AbsorbedRotation> frameRotationsAbsorbed(const Cartesian& cmm,
                                                     const Eigen::MatrixXd& full_information,
                                                     double tolerance) {
  // Scaled as the rank policy scales (identifiability.hpp): S = D^-1/2 N D^-1/2, y_w = D^1/2 v_w.
  // A parameter whose information is rounding (D_i <= 1e-9 max D) is unobserved: its row is 0,
  // not rounding blown up to 1.
  const Eigen::VectorXd d = full_information.diagonal().cwiseMax(0.0).cwiseSqrt();
  const double observed = 1e-9 * d.maxCoeff();
  Eigen::VectorXd scale(d.size());
  for (int i = 0; i < d.size(); ++i) scale[i] = d[i] > observed ? d[i] : 1.0;
  Eigen::MatrixXd S =
      scale.cwiseInverse().asDiagonal() * full_information * scale.cwiseInverse().asDiagonal();
  for (int i = 0; i < d.size(); ++i) {
    if (d[i] <= observed) {
      S.row(i).setZero();
      S.col(i).setZero();
    }
  }
  Eigen::MatrixXd Y(S.rows(), 3);
  for (int a = 0; a < 3; ++a) {
    Y.col(a) = scale.asDiagonal() * frameRotationDirection(cmm, Eigen::Vector3d::Unit(a));
  }
  // The rotations w minimising w^T (Y^T S Y) w / w^T (Y^T Y) w: the generalized eigenproblem.
  const Eigen::Matrix3d A = Y.transpose() * S * Y;
  const Eigen::Matrix3d B = Y.transpose() * Y;
  const double largest = SymmetricEigenSolver(S, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix3d> solver(A, B);
  std::vector<Eigen::Vector3d> axes;
  for (int a = 0; a < 3; ++a) {
    if (solver.eigenvalues()[a] <= tolerance * largest) {
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
    // Sign: the largest component positive, so that "about x" reads as +x.
    int at = 0;
    rotation.axis.cwiseAbs().maxCoeff(&at);
    if (rotation.axis[at] < 0.0) rotation.axis = -rotation.axis;
    const Eigen::VectorXd v = frameRotationDirection(cmm, rotation.axis);
    for (int i = 0; i < v.size(); ++i) {
      if (std::abs(v[i]) > 1e-9 * v.cwiseAbs().maxCoeff()) {
        rotation.involves.push_back(cmm.parameters()[static_cast<std::size_t>(i)].name);
      }
    }
    out.push_back(std::move(rotation));
  }
  return out;
}

}  // namespace artcal
