#pragma once
// The ISO 10360-2 length test of a Cartesian CMM predicted from the calibration (docs/method.md
// section 9, "Acceptance tests predicted"):
//
// - the volume: the box of stylus-0 tip positions over the axis ranges (axes along the machine
//   frame's x, y, z, either sign); its centre c;
// - 7 lines through c (the 4 space diagonals, then x, y, z) or the caller's directions; on a line
//   of direction u whose segment inside the box is D long, 5 gauges of lengths L = f D,
//   f = 0.1, 0.3, 0.5, 0.7, 0.9, ends a = c - L/2 u, b = c + L/2 u, each measured 3 times;
// - a result E = u . (x_b - x_a) - L: its systematic part g^T dp, g = (J_p(q_b) - J_p(q_a))^T u
//   over the calibrated parameters (J_p the model's own, stylus 0, at the axis readings q that
//   put the tip on the end), dp ~ N(0, V_p) ONE draw shared by every result; its noise part
//   u . (e_b - e_a) + u . (J_q(q_b) eq_b - J_q(q_a) eq_a), fresh for every result:
//   sigma_noise^2 = 2 s_p^2 + u^T (J_q,b Sigma_q J_q,b^T + J_q,a Sigma_q J_q,a^T) u.
// - max_i |E_i| / MPE(L_i) over the 105 results by Monte-Carlo (acceptance/monte_carlo.hpp);
//   P(pass) = P(max <= 1).
// - E150 (`stylus_offset`, ISO 10360-2's test with a stylus tip offset perpendicular to the ram;
//   docs/calibration.md, "E150"): two positions instead of the lines. The ram is the last axis;
//   position k probes with stylus 0 moved `stylus_offset` mm along e_k, the k-th machine-frame
//   axis perpendicular to the ram (x, y, z order), on the diagonal of the box face spanned by the
//   other perpendicular axis and the ram (the line along which the ram's rotations move an offset
//   tip: Abbe errors), centred on the offset tip's box. 2 lines x 5 lengths x 3 repetitions.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "artcal/acceptance/acceptance.hpp"
#include "artcal/acceptance/monte_carlo.hpp"

namespace artcal {

/// Most lines a length test takes (`--lines`; docs/hardening.md, work caps): the prediction's
/// systematic covariance and its Monte-Carlo grow as the square of the results (5 lengths x 3
/// repetitions a line); 3000 lines took 46 s and 3.5 GB, 256 take well under a second.
inline constexpr std::size_t kMaxTestLines = 256;

struct LengthTestOptions {
  Mpe mpe;
  /// Unit directions replacing the 7 lines (`--lines`); empty: the standard ones.
  std::vector<Eigen::Vector3d> lines;
  /// E150: the stylus tip offset (mm, > 0) perpendicular to the ram (header); 0: the E0 test.
  double stylus_offset = 0.0;
  std::vector<double> fractions = {0.1, 0.3, 0.5, 0.7, 0.9};
  int repetitions = 3;
  MonteCarloOptions monte_carlo;
};

/// One gauge (a line and length); its `repetitions` results share everything below.
struct Gauge {
  int line = 0;
  std::string kind;  ///< "diagonal", "x", "y", "z", "custom" or (E150) "yz-face" and the like
  /// E150: the offset of the probing stylus from stylus 0 (mm, machine frame); a and b are its
  /// tip's positions. Zero for the E0 test.
  Eigen::Vector3d stylus_offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double fraction = 0.0;
  double length = 0.0;                                                       ///< mm
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();  ///< tip, mm
  Eigen::VectorXd joints_a, joints_b;                                        ///< axis readings, mm
  Eigen::RowVectorXd g;        ///< dE/dp over the covariance's parameters
  Eigen::RowVectorXd g_exact;  ///< dE/dp over the parameters outside it (exact ones)
  double sigma_sys = 0.0;      ///< mm
  double sigma_noise = 0.0;    ///< mm
  double mpe = 0.0;            ///< mm
  double sigmaTotal() const;
};

/// A parameter taken as exact that some results are sensitive to.
struct UnseenParameter {
  int parameter = 0;       ///< index into the model's parameters
  std::vector<int> lines;  ///< the lines whose results depend on it
};

struct LengthTestPrediction {
  Eigen::Vector3d box_lo, box_hi, center;  ///< the tip box (stylus 0), mm
  double stylus_offset = 0.0;              ///< E150's offset, mm; 0: the E0 test
  int lines = 0;
  int repetitions = 3;
  std::vector<Gauge> gauges;
  Eigen::MatrixXd systematic_covariance;  ///< of the gauges' systematic parts, mm^2
  std::vector<UnseenParameter> unseen;
  Mpe mpe;
  MonteCarloSummary monte_carlo;
};

/// The layout and the linear statistics (no Monte-Carlo). InputError when the machine is not a
/// Cartesian CMM with axes along x, y, z, or a line direction is not a unit vector; RunError
/// when an end cannot be reached.
LengthTestPrediction predictLengthTestLinear(const AcceptanceInput& input,
                                             const LengthTestOptions& options);

/// The Monte-Carlo model of a prediction's results (every gauge `repetitions` times).
LinearGaussianTest lengthTestModel(const LengthTestPrediction& prediction,
                                   const AcceptanceInput& input);

/// The gauges' g as rows (gauges x the covariance's parameters).
Eigen::MatrixXd gaugeDerivatives(const std::vector<Gauge>& gauges);

/// For each column s of S (one draw of the gauges' systematic parts, mm) the exact
/// P(max |E|/MPE <= t | s) = prod_k P(|s_k + n| <= t MPE_k)^repetitions, n ~ N(0, sigma_noise,k^2)
/// (t = `threshold`; t = 1: P(pass | s)).
Eigen::VectorXd conditionalPassProbabilities(const LengthTestPrediction& prediction,
                                             const Eigen::MatrixXd& S, double threshold = 1.0);

/// The mean over the columns of conditionalPassProbabilities(prediction, S): with
/// S = G chol(V_p) Z for fixed standard normal Z (common random numbers) an estimate of P(pass)
/// that is smooth in V_p (the optimizer's "pass" criterion).
double meanConditionalPassProbability(const LengthTestPrediction& prediction,
                                      const Eigen::MatrixXd& S);

/// The `probability` quantile of max |E|/MPE under the same estimate: the t at which the mean
/// over S's columns of P(max |E|/MPE <= t | s) reaches `probability` (in (0, 1)), to 1e-10
/// relative: bracketed by steps of 1.5 from the largest 1.96 sigma_k / MPE_k, then the Illinois
/// variant of regula falsi (the mean is continuous and non-decreasing in t). Smooth in V_p like
/// the mean; 0 when every result is exact and zero.
double conditionalStatisticQuantile(const LengthTestPrediction& prediction,
                                    const Eigen::MatrixXd& S, double probability);

/// predictLengthTestLinear, then the Monte-Carlo.
LengthTestPrediction predictLengthTest(const AcceptanceInput& input,
                                       const LengthTestOptions& options);

}  // namespace artcal
