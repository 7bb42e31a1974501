#include "artcal/acceptance/length_acceptance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "artcal/core/error.hpp"
#include "artcal/model/axis_error_functions.hpp"

namespace artcal {

double Gauge::sigmaTotal() const {
  return std::sqrt(sigma_sys * sigma_sys + sigma_noise * sigma_noise);
}

namespace {

constexpr double kDirectionTolerance = 1e-9;

// The machine has axes (Mechanism::axisErrorFunctions(): a Cartesian CMM's), each along x, y or z.
void checkMachineAxes(const AcceptanceInput& input) {
  const AxisErrorFunctions* cartesian = input.machine->mechanism->axisErrorFunctions();
  if (!cartesian)
    throw InputError(input.source, "/machine/model",
                     "the ISO 10360-2 length test needs a Cartesian CMM (model \"cartesian\")");
  for (std::size_t k = 0; k < cartesian->axes().size(); ++k) {
    const Eigen::Vector3d& d = cartesian->axes()[k].direction;
    if (d.cwiseAbs().maxCoeff() < 1.0 - kDirectionTolerance)
      throw InputError(input.source, "/machine/axes/" + std::to_string(k) + "/direction",
                       "the length test needs every axis along the machine frame's x, y or z");
  }
}

/// The box of stylus-0 tip positions over the axis ranges (nominal geometry: the corners).
void tipBox(const AcceptanceInput& input, LengthTestPrediction& prediction) {
  const Machine& machine = *input.machine;
  const int n = machine.jointCount();
  prediction.box_lo.setConstant(std::numeric_limits<double>::infinity());
  prediction.box_hi.setConstant(-std::numeric_limits<double>::infinity());
  Eigen::VectorXd q(n), x;
  for (int corner = 0; corner < (1 << n); ++corner) {
    for (int k = 0; k < n; ++k) q[k] = machine.joint_limits[k][(corner >> k) & 1];
    forwardOrThrow(*machine.mechanism, machine.nominal, q, x, nullptr, nullptr, 0);
    prediction.box_lo = prediction.box_lo.cwiseMin(x.head<3>());
    prediction.box_hi = prediction.box_hi.cwiseMax(x.head<3>());
  }
  prediction.center = 0.5 * (prediction.box_lo + prediction.box_hi);
}

struct Line {
  std::string kind;
  Eigen::Vector3d direction;
};

std::vector<Line> standardLines(const Eigen::Vector3d& half) {
  std::vector<Line> lines;
  for (const auto& signs : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(-1, 1, 1),
                            Eigen::Vector3d(1, -1, 1), Eigen::Vector3d(-1, -1, 1)})
    lines.push_back({"diagonal", signs.cwiseProduct(half).normalized()});
  lines.push_back({"x", Eigen::Vector3d::UnitX()});
  lines.push_back({"y", Eigen::Vector3d::UnitY()});
  lines.push_back({"z", Eigen::Vector3d::UnitZ()});
  return lines;
}

std::vector<Line> testLines(const AcceptanceInput& input, const LengthTestOptions& options,
                            const Eigen::Vector3d& half) {
  if (options.lines.empty()) return standardLines(half);
  if (options.lines.size() > kMaxTestLines)
    throw InputError(input.source, "/lines",
                     std::to_string(options.lines.size()) + " lines, more than " +
                         std::to_string(kMaxTestLines) + ": give at most that many directions");
  std::vector<Line> lines;
  for (std::size_t i = 0; i < options.lines.size(); ++i) {
    const Eigen::Vector3d& u = options.lines[i];
    if (!u.allFinite() || std::abs(u.norm() - 1.0) > 1e-6)
      throw InputError(input.source, "/lines/" + std::to_string(i),
                       "a line direction must be a unit vector");
    lines.push_back({"custom", u.normalized()});
  }
  return lines;
}

/// Length of the segment through the centre along u inside the box of half-extents `half`.
double segmentLength(const Eigen::Vector3d& half, const Eigen::Vector3d& u) {
  double t = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i)
    if (std::abs(u[i]) > 1e-15) t = std::min(t, half[i] / std::abs(u[i]));
  return 2.0 * t;
}

/// Axis readings putting stylus 0 on `tip` with the parameters `p`, with J_p and J_q there.
Eigen::VectorXd readingsAt(const AcceptanceInput& input, const Eigen::VectorXd& p,
                           const Eigen::Vector3d& tip, Eigen::MatrixXd& J_p, Eigen::MatrixXd& J_q) {
  // The axes' one solution (Newton from the nominal closed form).
  const Mechanism& cartesian = *input.machine->mechanism;
  const std::vector<Eigen::VectorXd> q = cartesian.closedFormInverse(p, tip, 0);
  if (q.empty())
    throw RunError(input.source, "/machine",
                   "the length test's end (" + std::to_string(tip.x()) + ", " +
                       std::to_string(tip.y()) + ", " + std::to_string(tip.z()) +
                       ") mm cannot be reached by stylus 0");
  Eigen::VectorXd x;
  forwardOrThrow(cartesian, p, q.front(), x, &J_p, &J_q, 0);
  return q.front();
}

/// u^T J_q Sigma_q J_q^T u.
double encoderVariance(const AcceptanceInput& input, const Eigen::MatrixXd& J_q,
                       const Eigen::Vector3d& u) {
  if (input.noise.encoder.size() == 0) return 0.0;
  const Eigen::RowVectorXd projected = u.transpose() * J_q;
  return projected.cwiseProduct(input.noise.encoder.transpose()).squaredNorm();
}

std::vector<int> exactParameters(const AcceptanceInput& input) {
  std::vector<int> exact;
  const auto& calibrated = input.uncertainty.indices;
  for (int j = 0; j < input.machine->mechanism->parameterCount(); ++j)
    if (std::find(calibrated.begin(), calibrated.end(), j) == calibrated.end()) exact.push_back(j);
  return exact;
}

Gauge makeGauge(const AcceptanceInput& input, const LengthTestPrediction& prediction,
                const Line& line, double fraction, const Mpe& mpe) {
  Gauge gauge;
  gauge.kind = line.kind;
  gauge.direction = line.direction;
  gauge.fraction = fraction;
  const Eigen::Vector3d half = 0.5 * (prediction.box_hi - prediction.box_lo);
  gauge.length = fraction * segmentLength(half, line.direction);
  gauge.a = prediction.center - 0.5 * gauge.length * line.direction;
  gauge.b = prediction.center + 0.5 * gauge.length * line.direction;
  Eigen::MatrixXd J_p_a, J_q_a, J_p_b, J_q_b;
  gauge.joints_a = readingsAt(input, input.parameters, gauge.a, J_p_a, J_q_a);
  gauge.joints_b = readingsAt(input, input.parameters, gauge.b, J_p_b, J_q_b);
  const Eigen::RowVectorXd g_full = line.direction.transpose() * (J_p_b - J_p_a).topRows(3);
  gauge.g = calibratedColumns(g_full, input.uncertainty.indices);
  // Which exact parameters a result depends on is read at the nominal machine, whatever the
  // parameters predicted at: at a calibrated estimate, products of small corrections make
  // parameters a result does not depend on show a derivative of 1e-6 (acceptance MACHINE --plan
  // PLAN warned of 21 parameters where acceptance PLAN warned of 10 for the same calibration).
  const Eigen::VectorXd& nominal = input.machine->nominal;
  if (input.parameters.size() == nominal.size() && input.parameters != nominal) {
    Eigen::MatrixXd N_p_a, N_q_a, N_p_b, N_q_b;
    readingsAt(input, nominal, gauge.a, N_p_a, N_q_a);
    readingsAt(input, nominal, gauge.b, N_p_b, N_q_b);
    const Eigen::RowVectorXd g_nominal = line.direction.transpose() * (N_p_b - N_p_a).topRows(3);
    gauge.g_exact = calibratedColumns(g_nominal, exactParameters(input));
  } else {
    gauge.g_exact = calibratedColumns(g_full, exactParameters(input));
  }
  gauge.sigma_sys =
      std::sqrt(std::max(0.0, (gauge.g * input.uncertainty.V * gauge.g.transpose())(0, 0)));
  const double probe = input.noise.probe;
  gauge.sigma_noise =
      std::sqrt(2.0 * probe * probe + encoderVariance(input, J_q_a, line.direction) +
                encoderVariance(input, J_q_b, line.direction));
  gauge.mpe = mpe.at(gauge.length);
  return gauge;
}

/// The exact parameters some results depend on, with the lines affected.
std::vector<UnseenParameter> unseenParameters(const AcceptanceInput& input,
                                              const std::vector<Gauge>& gauges) {
  const std::vector<int> exact = exactParameters(input);
  std::vector<UnseenParameter> unseen;
  for (std::size_t j = 0; j < exact.size(); ++j) {
    UnseenParameter entry{exact[j], {}};
    for (const Gauge& gauge : gauges) {
      const double tolerance = 1e-9 * (1.0 + gauge.length);
      const bool sensitive = std::abs(gauge.g_exact[static_cast<Eigen::Index>(j)]) > tolerance;
      if (sensitive && (entry.lines.empty() || entry.lines.back() != gauge.line))
        entry.lines.push_back(gauge.line);
    }
    if (!entry.lines.empty()) unseen.push_back(std::move(entry));
  }
  return unseen;
}

}  // namespace

Eigen::MatrixXd gaugeDerivatives(const std::vector<Gauge>& gauges) {
  if (gauges.empty()) return {};
  Eigen::MatrixXd G(static_cast<Eigen::Index>(gauges.size()), gauges.front().g.size());
  for (std::size_t i = 0; i < gauges.size(); ++i) G.row(static_cast<Eigen::Index>(i)) = gauges[i].g;
  return G;
}

Eigen::VectorXd conditionalPassProbabilities(const LengthTestPrediction& prediction,
                                             const Eigen::MatrixXd& S, double threshold) {
  Eigen::VectorXd probabilities = Eigen::VectorXd::Ones(S.cols());
  for (std::size_t k = 0; k < prediction.gauges.size(); ++k) {
    const Gauge& gauge = prediction.gauges[k];
    const double limit = threshold * gauge.mpe;
    const double scale = gauge.sigma_noise > 0.0 ? 1.0 / (gauge.sigma_noise * std::sqrt(2.0)) : 0.0;
    for (Eigen::Index m = 0; m < S.cols(); ++m) {
      const double s = S(static_cast<Eigen::Index>(k), m);
      const double p = gauge.sigma_noise > 0.0
                           ? 0.5 * (std::erf((limit - s) * scale) + std::erf((limit + s) * scale))
                           : (std::abs(s) <= limit ? 1.0 : 0.0);
      for (int r = 0; r < prediction.repetitions; ++r) probabilities[m] *= p;
    }
  }
  return probabilities;
}

double meanConditionalPassProbability(const LengthTestPrediction& prediction,
                                      const Eigen::MatrixXd& S) {
  return S.cols() > 0 ? conditionalPassProbabilities(prediction, S).mean() : 0.0;
}

namespace {

/// A first guess of the quantile of max |E|/MPE: the largest z sigma_k / MPE_k over the gauges,
/// sigma_k from the draws' root mean square and the noise, z the normal quantile at 95 %.
double quantileGuess(const LengthTestPrediction& prediction, const Eigen::MatrixXd& S) {
  constexpr double kZ95 = 1.959963984540054;
  double guess = 0.0;
  for (std::size_t k = 0; k < prediction.gauges.size(); ++k) {
    const Gauge& gauge = prediction.gauges[k];
    const double mean_square = S.row(static_cast<Eigen::Index>(k)).squaredNorm() /
                               static_cast<double>(std::max<Eigen::Index>(S.cols(), 1));
    const double sigma = std::sqrt(mean_square + gauge.sigma_noise * gauge.sigma_noise);
    if (gauge.mpe > 0.0) guess = std::max(guess, kZ95 * sigma / gauge.mpe);
  }
  return guess > 0.0 && std::isfinite(guess) ? guess : 1.0;
}

}  // namespace

double conditionalStatisticQuantile(const LengthTestPrediction& prediction,
                                    const Eigen::MatrixXd& S, double probability) {
  if (S.cols() == 0 || prediction.gauges.empty()) return 0.0;
  auto excess = [&](double t) {
    return conditionalPassProbabilities(prediction, S, t).mean() - probability;
  };
  // A bracket [lo, hi], excess(lo) < 0 <= excess(hi), by steps of kStep from the guess.
  constexpr double kStep = 1.5;
  constexpr int kBracketSteps = 2000;
  double hi = quantileGuess(prediction, S), f_hi = excess(hi);
  double lo = hi, f_lo = f_hi;
  if (f_hi < 0.0) {
    for (int step = 0; step < kBracketSteps && f_hi < 0.0; ++step) {
      lo = hi;
      f_lo = f_hi;
      hi *= kStep;
      f_hi = excess(hi);
    }
  } else {
    for (int step = 0; step < kBracketSteps && f_lo >= 0.0 && lo > 0.0; ++step) {
      hi = lo;
      f_hi = f_lo;
      lo /= kStep;
      f_lo = excess(lo);
    }
  }
  if (!(f_lo < 0.0)) return 0.0;  // every result exact and zero: the quantile is 0
  if (!(f_hi >= 0.0)) return std::numeric_limits<double>::infinity();
  // Illinois: regula falsi, halving the value kept at an end that stays twice in a row.
  int kept = 0;
  constexpr int kIterations = 200;
  for (int iteration = 0; iteration < kIterations && hi - lo > 1e-10 * hi; ++iteration) {
    const double t = std::clamp(hi - f_hi * (hi - lo) / (f_hi - f_lo), lo, hi);
    const double f = excess(t);
    if (f == 0.0) return t;
    if (f < 0.0) {
      lo = t;
      f_lo = f;
      if (kept == -1) f_hi *= 0.5;
      kept = -1;
    } else {
      hi = t;
      f_hi = f;
      if (kept == 1) f_lo *= 0.5;
      kept = 1;
    }
  }
  return hi;
}

namespace {

// The machine probing with its stylus 0 moved by `offset` (E150): the same axes, error functions
// and parameters (the styli are not parameters: models.md section 4), that one stylus.
Machine withOffsetStylus(const Machine& machine, const Eigen::Vector3d& offset) {
  const AxisErrorFunctions& cmm = *machine.mechanism->axisErrorFunctions();
  Machine shifted = machine;
  shifted.mechanism = cmm.withStyli({cmm.styli().front() + offset});
  return shifted;
}

// E150's two positions (length_acceptance.hpp): position k offsets stylus 0 along the k-th
// machine-frame axis across the ram and measures along the diagonal of the face spanned by the
// other one and the ram, centred on the offset tip's box.
void addOffsetPositions(const AcceptanceInput& input, const LengthTestOptions& options,
                        LengthTestPrediction& prediction) {
  if (!options.lines.empty())
    throw InputError("--lines", "",
                     "E150's two positions are fixed (the faces across the stylus offset): give "
                     "either --lines or --stylus-offset");
  const Eigen::Vector3d& ram_direction =
      input.machine->mechanism->axisErrorFunctions()->axes().back().direction;
  int ram = 0;
  ram_direction.cwiseAbs().maxCoeff(&ram);
  std::vector<int> across;
  for (int i = 0; i < 3; ++i)
    if (i != ram) across.push_back(i);
  for (int k = 0; k < 2; ++k) {
    const int along = across[static_cast<std::size_t>(k)];
    const int other = across[static_cast<std::size_t>(1 - k)];
    const Eigen::Vector3d offset = options.stylus_offset * Eigen::Vector3d::Unit(along);
    const Machine shifted = withOffsetStylus(*input.machine, offset);
    AcceptanceInput shifted_input = input;
    shifted_input.machine = &shifted;
    LengthTestPrediction offset_box;
    tipBox(shifted_input, offset_box);
    const Eigen::Vector3d half = 0.5 * (offset_box.box_hi - offset_box.box_lo);
    Eigen::Vector3d direction = Eigen::Vector3d::Zero();
    direction[other] = half[other];
    direction[ram] = half[ram];
    const std::string face = {"xyz"[std::min(other, ram)], "xyz"[std::max(other, ram)]};
    const Line line{face + "-face", direction.normalized()};
    for (double fraction : options.fractions) {
      Gauge gauge = makeGauge(shifted_input, offset_box, line, fraction, options.mpe);
      gauge.line = k;
      gauge.stylus_offset = offset;
      prediction.gauges.push_back(std::move(gauge));
    }
  }
  prediction.lines = 2;
}

}  // namespace

LengthTestPrediction predictLengthTestLinear(const AcceptanceInput& input,
                                             const LengthTestOptions& options) {
  // Within the bound of every length read (1e9 mm, io/json_node.hpp's kMaxInputMagnitude): 1e300
  // wrote null and quantiles of 1e296 (issue 44).
  constexpr double kLargestStylusOffset = 1e9;
  if (!(std::isfinite(options.stylus_offset) && options.stylus_offset >= 0.0 &&
        options.stylus_offset <= kLargestStylusOffset))
    throw InputError("--stylus-offset", "",
                     "expected a finite number of mm, >= 0 and within 1e9 (ISO 10360-2's E150: "
                     "150)");
  checkMachineAxes(input);
  LengthTestPrediction prediction;
  prediction.mpe = options.mpe;
  prediction.repetitions = options.repetitions;
  prediction.stylus_offset = options.stylus_offset;
  tipBox(input, prediction);
  if (options.stylus_offset > 0.0) {
    addOffsetPositions(input, options, prediction);
  } else {
    const std::vector<Line> lines =
        testLines(input, options, 0.5 * (prediction.box_hi - prediction.box_lo));
    prediction.lines = static_cast<int>(lines.size());
    for (std::size_t l = 0; l < lines.size(); ++l) {
      for (double fraction : options.fractions) {
        Gauge gauge = makeGauge(input, prediction, lines[l], fraction, options.mpe);
        gauge.line = static_cast<int>(l);
        prediction.gauges.push_back(std::move(gauge));
      }
    }
  }
  const Eigen::MatrixXd G = gaugeDerivatives(prediction.gauges);
  prediction.systematic_covariance = G * input.uncertainty.V * G.transpose();
  prediction.unseen = unseenParameters(input, prediction.gauges);
  return prediction;
}

LinearGaussianTest lengthTestModel(const LengthTestPrediction& prediction,
                                   const AcceptanceInput& input) {
  LinearGaussianTest test;
  test.A = gaugeDerivatives(prediction.gauges) * covarianceFactor(input.uncertainty.V);
  for (std::size_t i = 0; i < prediction.gauges.size(); ++i) {
    const Gauge& gauge = prediction.gauges[i];
    for (int r = 0; r < prediction.repetitions; ++r) {
      TestResult result;
      result.first_row = static_cast<int>(i);
      result.noise_factor(0, 0) = gauge.sigma_noise;
      result.scale = 1.0 / gauge.mpe;
      test.results.push_back(std::move(result));
    }
  }
  return test;
}

LengthTestPrediction predictLengthTest(const AcceptanceInput& input,
                                       const LengthTestOptions& options) {
  LengthTestPrediction prediction = predictLengthTestLinear(input, options);
  prediction.monte_carlo = runMonteCarlo(lengthTestModel(prediction, input), options.monte_carlo);
  return prediction;
}

}  // namespace artcal
