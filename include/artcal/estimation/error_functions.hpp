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
// offset by d). frameRotationsAbsorbed tests v_w against the plan's information as the rank
// policy tests any direction (identifiability.hpp): in S = D^-1/2 N_red D^-1/2, D the unreduced
// diagonal, a rotation is absorbed when the fraction of its own information that survives the
// elimination is at or below the rank tolerance (absolute).
//
// These analyses ask the model for its error-function layout (Mechanism::axisErrorFunctions(),
// model/axis_error_functions.hpp), never for its family.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/estimation/cartesian_answers.hpp"
#include "artcal/estimation/evaluation_result.hpp"
#include "artcal/estimation/identifiability.hpp"
#include "artcal/model/axis_error_functions.hpp"
#include "artcal/model/machine.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// Every axis's six functions at `steps` positions along its range. `V` is V_p over the
/// machine's calibrated parameters (internal units), `p` the full parameter vector the values are
/// taken at (nominal, or a calibrated estimate). The machine's model has axisErrorFunctions().
std::vector<ErrorFunctionProfile> errorFunctionProfiles(const Machine& machine,
                                                        const Eigen::MatrixXd& V,
                                                        const Eigen::VectorXd& p, int steps = 21);

/// v_w for the frame rotation about `w` (a unit vector): a full parameter vector of `model`
/// (which has axisErrorFunctions()).
Eigen::VectorXd frameRotationDirection(const Mechanism& model, const Eigen::Vector3d& w);

/// The rotations (an orthonormal basis of them) whose v_w the information of *every* model
/// parameter does not see: the smallest fractions w^T Y^T S Y w / w^T Y^T Y w (S the rank test's
/// scaled matrix, scaledInformation; y_w = D^1/2 v_w) at or below `tolerance` (absolute, as the
/// rank test). `information` is planInformation over every parameter of `model`.
std::vector<AbsorbedRotation> frameRotationsAbsorbed(const Mechanism& model,
                                                     const PlanInformation& information,
                                                     double tolerance = kDefaultRankTolerance);

/// What check and evaluate answer for a Cartesian CMM (cartesian_answers.hpp); empty for other
/// models. `evaluation` may be null (check): then no profiles (else at nominal, `profile_steps`
/// positions per axis, from the evaluation's V_p).
CartesianAnswers cartesianAnswers(const Plan& plan, const Evaluation* evaluation,
                                  int profile_steps = 11);

/// The error functions `artcal report` draws along the axes (cartesian_report.hpp): at `p` with
/// V_p = `V` (nominal for a plan evaluated, the estimate after a calibration: `calibrated`), and
/// with `truth` (a simulated machine's full parameter vector) the same functions at the truth.
/// Empty for other models.
ErrorFunctionBands errorFunctionBands(const Plan& plan, const Eigen::MatrixXd& V,
                                      const Eigen::VectorXd& p, bool calibrated,
                                      const Eigen::VectorXd* truth = nullptr, int steps = 21);

}  // namespace artcal
