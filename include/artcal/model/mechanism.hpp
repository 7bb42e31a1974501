#pragma once
// Mechanism models: forward kinematics x = f(p, q) with exact Jacobians (method.md section 1).
//
// A Mechanism is immutable. Parameters p are the model's full parameter vector in internal units
// (mm, rad); which of them are calibrated is the Machine's business, not the model's.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "artcal/core/error.hpp"
#include "artcal/core/units.hpp"

namespace artcal {

enum class JointKind { Revolute, Prismatic };

inline Quantity jointQuantity(JointKind kind) {
  return kind == JointKind::Revolute ? Quantity::Angle : Quantity::Length;
}

/// Outcome of a forward kinematics evaluation.
enum class ForwardStatus {
  Ok,
  NotConverged,  ///< the numerical solution did not reach its tolerance in its iterations
  Singular,      ///< the configuration is singular (no unique pose, no Jacobian)
};

/// "did not converge", "singular configuration".
std::string forwardStatusName(ForwardStatus status);

struct ParameterInfo {
  std::string name;
  Quantity quantity;
};

class Mechanism {
 public:
  virtual ~Mechanism() = default;

  /// The model's name in plan files ("planar2r", "serial-dh").
  virtual std::string modelName() const = 0;
  /// Dimension of the probe position x: 2 or 3.
  virtual int dimension() const = 0;
  virtual int jointCount() const = 0;
  virtual JointKind jointKind(int joint) const = 0;
  /// Every parameter of the model, in the order of p.
  virtual const std::vector<ParameterInfo>& parameters() const = 0;

  /// x = f(p, q). J_x_p (dimension x parameters) and J_x_q (dimension x joints) are filled when
  /// not null; they are resized as needed (no allocation when already the right size). A model
  /// whose forward kinematics is numerical (a closed chain solved by Newton) may fail: it says so
  /// in the status, and x and the Jacobians are then unspecified. Every caller handles it.
  [[nodiscard]] virtual ForwardStatus forward(const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                                              Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p = nullptr,
                                              Eigen::MatrixXd* J_x_q = nullptr) const = 0;

  int parameterCount() const { return static_cast<int>(parameters().size()); }
  /// Index of a parameter by name, or -1.
  int parameterIndex(const std::string& name) const;
};

using MechanismPtr = std::shared_ptr<const Mechanism>;

/// forward() for callers with no way to go on without x: a failure raises KinematicsError.
void forwardOrThrow(const Mechanism& mechanism, const Eigen::VectorXd& p, const Eigen::VectorXd& q,
                    Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p = nullptr,
                    Eigen::MatrixXd* J_x_q = nullptr);

}  // namespace artcal
