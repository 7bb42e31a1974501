#pragma once
// A capability a model may offer (Mechanism::axisErrorFunctions()): its parameters are error
// functions of its prismatic axes' positions (ISO 230-1 rigid-body model; docs/models.md section
// 4, the Cartesian CMM). Each axis carries six error functions of its own position, three
// translations and three rotations, each a Legendre series without constant term:
//   e(u) = sum_{n=1..degree} c_n P_n(s),   s = 2 (u - mid_k) / width_k.
// The analyses of such a model (estimation/error_functions.hpp: the functions' predicted bands,
// the frame rotations the placements absorb; the ISO 10360-2 length test) ask the model for this
// capability, never for its family.

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "artcal/core/enum_names.hpp"

namespace artcal {

class Mechanism;

struct CartesianAxis {
  std::string name;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< unit vector
  std::array<double, 2> range = {0.0, 1.0};              ///< mm, lower < upper
};

/// The six error functions of an axis, in parameter order within one degree.
enum class AxisError { Tx, Ty, Tz, Rx, Ry, Rz };
inline constexpr int kAxisErrorCount = 6;

/// The functions' names in parameter names ("x.ty.2") and tables.
inline constexpr EnumNames<AxisError, kAxisErrorCount> kAxisErrorNames{{{AxisError::Tx, "tx"},
                                                                        {AxisError::Ty, "ty"},
                                                                        {AxisError::Tz, "tz"},
                                                                        {AxisError::Rx, "rx"},
                                                                        {AxisError::Ry, "ry"},
                                                                        {AxisError::Rz, "rz"}}};
/// "tx", ..., "rz".
std::string axisErrorName(AxisError error);
/// The metrologist's name of axis `axis`'s error function `error` along an axis whose direction
/// is `direction`: positioning, straightness (in y), pitch, yaw, roll, ...
std::string axisErrorMeaning(const Eigen::Vector3d& direction, AxisError error);

/// Legendre polynomials P_0..P_degree at s and their derivatives (Bonnet's recursion).
void legendre(int degree, double s, double* P, double* dP);

/// The error-function layout of a model whose parameters are the coefficients c_n of its axes'
/// error functions.
class AxisErrorFunctions {
 public:
  virtual ~AxisErrorFunctions() = default;
  /// The axes from the base to the probe; axis k is joint k.
  virtual const std::vector<CartesianAxis>& axes() const = 0;
  /// The highest degree n of every function's series.
  virtual int degree() const = 0;
  /// The probe's styli (offsets from the quill), stylus 0 first.
  virtual const std::vector<Eigen::Vector3d>& styli() const = 0;
  /// Index in p of the coefficient of degree n (1..degree) of `error` of axis `axis`.
  virtual int parameterIndex(int axis, AxisError error, int n) const = 0;
  /// The normalised position s in [-1, 1] of reading u of axis `axis`.
  virtual double normalised(int axis, double u) const = 0;
  /// The same machine (axes, error functions, parameters) probing with other styli (ISO
  /// 10360-2's E150: stylus 0 moved across the ram).
  virtual std::shared_ptr<const Mechanism> withStyli(std::vector<Eigen::Vector3d> styli) const = 0;
};

}  // namespace artcal
