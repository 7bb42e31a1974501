#pragma once
// What a Cartesian CMM's calibration says about its error functions (docs/models.md section 4), in
// the terms a metrologist uses: each axis's six functions e(u) = sum_n c_n P_n(s) and the
// predicted standard uncertainty of each along its axis,
//   u_e(u)^2 = g(u)^T V_e g(u),   g(u) = (P_n(s(u)))_n over the function's calibrated degrees,
// V_e the block of V_p of those coefficients (docs/method.md section 4 applied to one function);
// and the rotations of the whole machine frame that the placements' rigid motions absorb.
//
// A frame rotation w turns every probed point x into x + w x (x - const). At p = 0 the degree-1
// translations of axis k, c_k = (w x direction_k) width_k / 2, do the same up to a constant and
// up to w x (stylus_i - stylus_0): those directions v_w of p are unobservable exactly when w is
// parallel to every stylus offset (all three with one stylus, the rotation about d with styli
// offset by d). frameRotationsAbsorbed tests v_w against the plan's information.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/model/cartesian.hpp"
#include "artcal/model/machine.hpp"

namespace artcal {

/// One error function of one axis along that axis.
struct ErrorFunctionProfile {
  int axis = 0;
  AxisError error = AxisError::Tx;
  std::string name;     ///< "x.ty"
  std::string meaning;  ///< "straightness in y"
  bool rotation = false;
  std::vector<int> calibrated_degrees;
  std::vector<int> fixed_degrees;  ///< not calibrated (kept at nominal)
  std::vector<double> position;    ///< axis reading u, mm
  std::vector<double> value;       ///< e(u) at the given parameters, internal units (mm, rad)
  std::vector<double> u;           ///< predicted standard uncertainty of e(u), internal units
};

/// Every axis's six functions at `steps` positions along its range. `V` is V_p over the
/// machine's calibrated parameters (internal units), `p` the full parameter vector the values are
/// taken at (nominal, or a calibrated estimate).
std::vector<ErrorFunctionProfile> errorFunctionProfiles(const Cartesian& cmm,
                                                        const Machine& machine,
                                                        const Eigen::MatrixXd& V,
                                                        const Eigen::VectorXd& p, int steps = 21);

/// v_w for the frame rotation about `w` (a unit vector): a full parameter vector.
Eigen::VectorXd frameRotationDirection(const Cartesian& cmm, const Eigen::Vector3d& w);

/// A frame rotation the placements absorb.
struct AbsorbedRotation {
  Eigen::Vector3d axis;               ///< unit
  std::vector<std::string> involves;  ///< the squareness coefficients it moves
};

/// The rotations (an orthonormal basis of them) whose v_w the information of *every* model
/// parameter does not see: |N v_w| <= tolerance |N| |v_w| with N over all parameters (full
/// information, `full_information` of the model's parameter order).
std::vector<AbsorbedRotation> frameRotationsAbsorbed(const Cartesian& cmm,
                                                     const Eigen::MatrixXd& full_information,
                                                     double tolerance = 1e-9);

}  // namespace artcal
