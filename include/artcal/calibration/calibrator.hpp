#pragma once
// The calibrator (docs/method.md section 6): from the readings of a plan, estimate the calibrated
// parameters p, every placement's rigid transform r_j and the artifacts' systematic errors c by
// minimising
//
//   sum_j e_j^T Sigma_j^-1 e_j + c^T Sigma_c^-1 c      (e = F(p, q, r_j) - W*(c), section 3)
//
// with Levenberg-Marquardt on the block structure: each placement's whitened observation block
// (DesignMatrixBuilder, weights re-evaluated at the current estimate) is reduced by the Schur
// complement of its r_j (NormalMatrixReducer), the damped step dg over g = (p, c) is solved
// (LevenbergMarquardtStrategy), and each r_j follows by back-substitution
// (PlacementElimination::rigidStep). Each r_j starts from a rigid (Umeyama) fit of the probed
// points at the starting parameters. The cost is linear in the number of placements.
//
// The reported u is sqrt(diag V_p), V_p the inverse of the reduced information at the estimate
// with the declared noise model (c eliminated with its prior); u_posterior = u sqrt(chi2/dof).
// dof = (valued coordinates observed) + (parameters with a prior) - N(p) - sum_j N(r_j): each c
// has one prior pseudo-observation and one unknown; a machine.prior adds one row per parameter
// (centred on the nominal value) to the cost.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "artcal/calibration/levenberg_marquardt.hpp"
#include "artcal/calibration/model_choice_result.hpp"
#include "artcal/calibration/plausible_minimum.hpp"
#include "artcal/calibration/unmodelled_error.hpp"
#include "artcal/calibration/verification.hpp"
#include "artcal/core/enum_names.hpp"
#include "artcal/estimation/design_matrix.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/estimation/normal_matrix.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

enum class TerminationType {
  Converged,      ///< the step or the cost change fell below its tolerance
  NoConvergence,  ///< max_iterations reached
  Failure,        ///< no descent step exists, or the problem became non-finite
};

/// The names calibrate's --json and its summary line use.
inline constexpr EnumNames<TerminationType, 3> kTerminationNames{
    {{TerminationType::Converged, "converged"},
     {TerminationType::NoConvergence, "no_convergence"},
     {TerminationType::Failure, "failure"}}};
/// "converged", "no_convergence", "failure".
std::string terminationName(TerminationType type);

struct CalibrationOptions {
  /// Iterations allowed. Well-conditioned plans converge in a few; a plan with weakly determined
  /// directions (the MUKCa Panda on 8 positions, u of 28 mm along panda_joint6.y) walks its
  /// valley in up to about 60 Gauss-Newton steps at chi2/dof 1, so 50 stopped it short.
  int max_iterations = 200;
  /// Converged when every |dg_i| / u_i < step_tolerance (the step is that small a fraction of
  /// the parameter's standard uncertainty, u_i = sqrt(diag N^-1) at the current linearisation)
  /// and the r_j steps are as small
  /// (Linearization::rigid_reduction < step_tolerance^2) ...
  double step_tolerance = 1e-3;
  /// ... or when the predicted or actual cost change of a step is below
  /// max(function_tolerance * cost, step_tolerance^2). Both tolerances are in the standard
  /// uncertainties the readings show: times max(1, sqrt(chi2/dof)), so that convergence does not
  /// depend on the stated noise's scale. The weights are re-evaluated at the
  /// estimate (they depend on p through J_q), so the iteration is a reweighted Gauss-Newton:
  /// near its fixed point the exact cost may not fall by the tiny amounts the model promises.
  double function_tolerance = 1e-6;
  DampingOptions damping;
  /// Normalised residuals larger than this (in absolute value) are flagged.
  double flag_threshold = 3.0;
  /// A reading is a gross error (a ball not seated, a socket that moved) when its score exceeds
  /// this many times max(1, Birge ratio): beyond 5 sigma of the scatter the fit itself shows,
  /// p = 5.7e-7 per coordinate for a normal error, so about one false call in 10^6 coordinates.
  double gross_threshold = 5.0;
  /// Residual table and V_p at the estimate (the Monte-Carlo confirmation skips them).
  bool details = true;
  /// How calibrateReadings settles `"calibrate": "identifiable"` (model_choice.hpp).
  ModelChoiceMode model_choice = ModelChoiceMode::HeldOut;
  /// calibrateReadings estimates the unmodelled error by cross-validation (unmodelled_error.hpp).
  bool cross_validation = true;
  bool isValid(std::string* error) const;
};

struct CalibrationSummary {
  TerminationType termination = TerminationType::Failure;
  std::string message;
  int iterations = 0;  ///< linearisations whose step was tried, summed over the fits
  int accepted_steps = 0;
  /// Levenberg-Marquardt runs behind the result: 1, more when calibrateReadings refits (each
  /// reweighting of `"probe": "estimate"`, a repeat after the rank rule at the estimate).
  int fits = 1;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  bool converged() const { return termination == TerminationType::Converged; }
  /// One line: termination, iterations, cost.
  std::string briefReport() const;
};

/// One measured point's residual in its valued artifact coordinates.
struct ResidualEntry {
  int placement = 0;
  int measurement = 0;
  int feature = 0;
  Eigen::VectorXd residual;  ///< F - W*, mm
  /// Standardised: z_i / sqrt(1 - h_ii), z = Sigma^-1/2 (F - W*) whitened, h_ii the row's
  /// leverage in the full fit (p, c and every r_j). Unit variance under the noise model, so a
  /// gross error is not hidden by what the fit absorbs; 0 where 1 - h_ii < 1e-3 (not testable).
  Eigen::VectorXd standardized;
  double score = 0.0;    ///< max |standardized|
  bool flagged = false;  ///< score > flag_threshold
  bool gross = false;    ///< score > gross_threshold * max(1, Birge ratio)
};

/// `"noise": {"probe": "estimate"}` resolved by calibrateReadings (calibrate_readings.hpp).
struct NoiseEstimate {
  double stated = 0.0;  ///< the starting s_p, mm
  double probe = 0.0;   ///< the estimate: chi2 = dof at the calibration's estimate, mm
  double u = 0.0;       ///< its standard uncertainty, sqrt(2 dof) / |d chi2/d probe|, mm
  int fits = 0;         ///< calibrations run until it settled
};

struct Calibration {
  CalibrationSummary summary;
  std::optional<NoiseEstimate> noise_estimate;  ///< when the plan asked for it
  /// The held-out model choice (calibrateReadings, model_choice.hpp), when it ran.
  std::optional<ModelChoice> model_choice;
  /// What a metrologist should look at before trusting the result (implausible corrections,
  /// readings that fit to rounding): one sentence each, naming the parameter.
  std::vector<std::string> warnings;
  /// When the plain fit's corrections were flagged: the minimum taken, the other, and why
  /// (calibrateReadings, plausible_minimum.hpp).
  std::optional<MinimumChoice> minimum;
  /// The error the model does not explain, by cross-validation (unmodelled_error.hpp), when
  /// calibrateReadings estimated it.
  std::optional<UnmodelledError> unmodelled;
  Eigen::VectorXd parameters;  ///< full parameter vector, internal units
  Eigen::VectorXd systematic;  ///< c over the GlobalLayout order, mm
  std::vector<RigidTransform> poses;
  double chi2 = 0.0;  ///< sum e^T Sigma^-1 e + c^T Sigma_c^-1 c at the estimate
  int dof = 0;
  double chi2_per_dof = 0.0;                      ///< 0 when dof <= 0
  std::optional<ParameterCovariance> covariance;  ///< V_p at the estimate (details only)
  std::vector<ResidualEntry> residuals;           ///< details only
  int largest_residual = -1;                      ///< index into residuals, -1 when none
  double gross_limit = 0.0;  ///< the score beyond which a reading is a gross error (details only)

  Eigen::VectorXd estimate(const Machine& machine) const {
    return machine.calibratedValues(parameters);
  }
  /// u * sqrt(chi2_per_dof), internal units; empty without covariance or when dof <= 0.
  Eigen::VectorXd posteriorU() const;
  /// sqrt(chi2_per_dof), the readings' scatter over the stated noise; 0 when dof <= 0.
  double birgeRatio() const;
  /// V_p over the machine's calibrated parameters with this fit's Birge ratio: what `verify`
  /// predicts from (the machine file carries the same); std::nullopt without covariance.
  std::optional<ParameterUncertainty> uncertainty(const Machine& machine) const;
};

/// The unknowns of the calibration: p (full vector), c (GlobalLayout order) and every r_j.
struct CalibrationState {
  Eigen::VectorXd p;
  Eigen::VectorXd c;
  std::vector<RigidTransform> poses;
};

/// The problem linearised at a state, reduced over g = (p, c).
struct Linearization {
  double cost = 0.0;  ///< sum e^T Sigma^-1 e + c^T Sigma_c^-1 c
  Eigen::MatrixXd N;  ///< reduced normal matrix with the prior
  /// Reduced right-hand side with the prior: along (dg, dr_j = rigidStep(dg) - rigidStep(0)),
  /// the cost changes at the rate -2 b^T dg.
  Eigen::VectorXd b;
  std::vector<PlacementElimination> eliminations;  ///< per placement, for back-substitution
  /// sum_j g_r^T (A_r^T A_r)^+ g_r: what re-fitting every r_j alone (dg = 0) would gain. The
  /// full model prediction is this plus 2 b^T dg - dg^T N dg.
  double rigid_reduction = 0.0;
  /// Per placement, the weights used (held for the trials of the next step).
  std::vector<ReadingWeights> weights;
  /// Per placement, the weights at its own state when it was whitened with held ones: what
  /// makes it fresh without building it again (the convergence tests' re-weighting).
  std::vector<ReadingWeights> own_weights;
  /// Whitened with the weights at its own state (false: with another state's, held).
  bool fresh = true;
  /// Per placement, the whitened observation block (residuals included) it was reduced from:
  /// what the rank rule at the estimate and the probe-noise estimate read back
  /// (Calibrator::information, Calibrator::misfits) instead of building them again.
  std::vector<ObservationBlock> blocks;
  /// Per placement, its block's products (NormalMatrixReducer::add): what the rank rule reduces
  /// again with each placement's full rigid motion (Calibrator::information).
  std::vector<BlockProducts> products;
  double predictedReduction(const Eigen::VectorXd& dg) const;
};

/// Prepared calibrations of one plan (model/data split): holds the builders and scratch space.
/// Not thread-safe: one per thread.
class Calibrator {
 public:
  explicit Calibrator(const Plan& plan, const CalibrationOptions& options = {});

  /// Calibrates from `placements` (their readings), starting from the plan's nominal parameters.
  Calibration run(const std::vector<Placement>& placements);
  /// Same, starting from the full parameter vector `start`.
  Calibration run(const std::vector<Placement>& placements, const Eigen::VectorXd& start);
  /// Same, starting from a whole state (p, c and every r_j): a calibration repeated from where
  /// another converged (calibrate_readings.hpp: the noise re-estimated).
  Calibration run(const std::vector<Placement>& placements, const CalibrationState& start);

  /// The probe noise s_p (mm) the readings are whitened with: the plan's when constructed.
  double probeNoise() const { return builder_.noise().probe; }
  /// Whiten with s_p = `probe` (mm) from the next linearisation on (the variance component
  /// calibrate_readings.hpp estimates). The plan is not touched: the calibrator owns its noise.
  void setProbeNoise(double probe) { builder_.setProbeNoise(probe); }

  /// The starting state: p = start, c = 0, each r_j fitted (Umeyama) at `start`.
  CalibrationState initialState(const std::vector<Placement>& placements,
                                const Eigen::VectorXd& start) const;
  /// Linearises at `state`, with the weights evaluated there or, given `weights`, the ones that
  /// linearisation used (iteratively reweighted least squares: the weights depend on p through
  /// J_q, and a trial step is judged under the current weights); false when anything is
  /// non-finite.
  bool linearize(const std::vector<Placement>& placements, const CalibrationState& state,
                 Linearization& out, const Linearization* weights = nullptr);
  /// Linearises at `state` with its own weights and keeps it (linearization()): a run() from
  /// the same state over the same placements, noise unchanged, starts from it instead of
  /// linearising again. What the rank rule at the starting values reads (information()).
  bool prepare(const std::vector<Placement>& placements, const CalibrationState& state);
  /// prepare() at `other`'s prepared state, for this calibrator's plan calibrating the parameters
  /// at positions `columns` of the set `other` was prepared with (the weak rule held the rest):
  /// `other`'s blocks without the other columns of A_p, reduced again. The same blocks a build
  /// would give (the columns of A_p are independent; r, c, the residuals and the weights do not
  /// depend on the calibrated set) without evaluating the readings again. Falls back to
  /// prepare() when `other` holds no prepared linearisation of `placements`.
  bool prepareFrom(const Calibrator& other, const std::vector<int>& columns,
                   const std::vector<Placement>& placements);
  /// The last linearisation with its own weights: prepare()'s, or the estimate's after run().
  const Linearization& linearization() const { return current_lin_; }
  /// The information of p at linearization()'s state, each placement's *full* rigid motion
  /// eliminated and c with its prior, without the parameter prior (as planInformation with
  /// with_estimable = false, evaluator.hpp): from the kept blocks, nothing built again. Its
  /// poses are linearization()'s. With every coordinate of the points valued (k = dimension) the
  /// reduced information of p does not depend on the poses (the span of a placement's rigid
  /// motions is the same whatever its pose, and the whitened Gram is rotation-invariant).
  PlanInformation information(const std::vector<Placement>& placements);
  /// Each reading's misfit at linearization()'s state (DesignMatrixBuilder::misfits), from the
  /// kept blocks: residual L e_w and encoder covariance L L^T - s_p^2 I, L the whitening factor.
  std::vector<ReadingMisfit> misfits(const std::vector<Placement>& placements) const;
  /// The state after the global step dg, each r_j back-substituted (docs/method.md section 3).
  void step(const CalibrationState& from, const Linearization& at, const Eigen::VectorXd& dg,
            const std::vector<Placement>& placements, CalibrationState& to) const;

 private:
  void fillDetails(const std::vector<Placement>& placements, Calibration& out);
  /// At a convergence test: true when the current linearisation has its own weights; otherwise
  /// re-linearises with them (`finite` says whether that worked) and returns false: the loop
  /// goes on under the new weights.
  bool settled(const std::vector<Placement>& placements, bool& finite);
  /// A cost change too small to matter (see CalibrationOptions).
  double negligible(double cost) const;
  /// max(1, sqrt(cost / dof)): the readings' scatter over the stated noise, which scales the
  /// convergence tests so that they do not depend on the stated noise's scale.
  double scatter(double cost) const;
  /// After an accepted step that gained more than kExtendRatio times the prediction: tries
  /// 2, 4, ... kMaxExtension times the step (weights held), keeping the best in trial_.
  void extendStep(const Eigen::VectorXd& dg, const std::vector<Placement>& placements,
                  double& actual);
  /// The step's largest component in standard uncertainties (see the .cpp).
  static double stepInUncertainties(const Eigen::MatrixXd& N, const Eigen::VectorXd& dg);
  /// Valued coordinates observed + prior rows - N(p) - sum of the effective N(r_j).
  int degreesOfFreedom(const std::vector<Placement>& placements) const;
  /// rigid_caps_ <- each placement's rigidRankOfFeatures: the caps of the reduction, once per
  /// run (they depend on the readings' features, not on the state).
  void computeRigidCaps(const std::vector<Placement>& placements);
  /// linearize() with the caps of rigid_caps_.
  bool linearizeCapped(const std::vector<Placement>& placements, const CalibrationState& state,
                       Linearization& out, const Linearization* weights = nullptr);
  /// True when current_lin_ is its own (fresh) linearisation at `state` over `placements`.
  bool isPrepared(const std::vector<Placement>& placements, const CalibrationState& state) const;
  /// current_lin_'s blocks re-whitened for the plan's probe noise, changed since it was built.
  bool reweightToProbe(const std::vector<Placement>& placements);
  /// current_lin_'s blocks re-whitened with `targets` (per placement and reading, the factors L'
  /// of the new Sigma = L' L'^T): each reading's rows times L'^-1 L, then reduced again. Fresh
  /// afterwards (the targets are the weights at its own state).
  bool rewhiten(const std::vector<Placement>& placements,
                const std::vector<ReadingWeights>& targets);
  /// The priors, N, b and the rigid reduction of `out`, its blocks added to reducer_.
  bool finishLinearization(const CalibrationState& state, Linearization& out);

  const Plan* plan_;
  CalibrationOptions options_;
  GlobalLayout layout_;
  DesignMatrixBuilder builder_;
  NormalMatrixReducer reducer_;
  ObservationBlock block_;
  LevenbergMarquardtStrategy strategy_;
  CalibrationState current_, trial_, extended_;
  Linearization current_lin_, trial_lin_, extended_lin_;
  int dof_ = 0;
  int reweightings_ = 0;         ///< weights re-evaluated at a converged estimate so far
  std::vector<int> rigid_caps_;  ///< per placement of the current run (computeRigidCaps)
  /// The placements and probe noise of current_lin_ when it is fresh at current_ (prepare(), or
  /// a run's end); null once a run has started from it.
  const std::vector<Placement>* prepared_of_ = nullptr;
  double prepared_probe_ = 0.0;
  /// Rounds of reweighting at a converged estimate (settled()).
  static constexpr int kMaxReweightings = 1;
  static constexpr double kExtendRatio = 1.5;
  /// Accepted steps after which the poses' own convergence no longer holds back p's.
  static constexpr int kPoseCrawlSteps = 5;
  static constexpr double kMaxExtension = 64.0;
};

/// Convenience: Calibrator(plan, options).run(plan.placements).
Calibration calibratePlan(const Plan& plan, const CalibrationOptions& options = {});

}  // namespace artcal
