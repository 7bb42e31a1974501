#include "artcal/calibration/corrections.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace artcal {

namespace {

// The mean segment length of the machine's skeleton at zero joints (mm); 0 when not drawn.
double meanLinkLength(const Machine& machine, const Eigen::VectorXd& nominal) {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(machine.jointCount());
  const std::vector<Eigen::VectorXd> points = machine.mechanism->skeleton(nominal, zero);
  double length = 0.0;
  int segments = 0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const double segment = (points[i] - points[i - 1]).norm();
    if (!(segment > 0.0) || !std::isfinite(segment)) continue;
    length += segment;
    ++segments;
  }
  return segments > 0 ? length / segments : 0.0;
}

std::string fileValue(const Quantity& q, double internal) {
  char text[64];
  std::snprintf(text, sizeof text, "%.4g %s", toFileUnit(q, internal),
                std::string(unitName(q)).c_str());
  return text;
}

}  // namespace

std::vector<ImplausibleCorrection> implausibleCorrections(const Machine& machine,
                                                          const Eigen::VectorXd& nominal,
                                                          const Eigen::VectorXd& p,
                                                          const CorrectionTolerance& tolerance) {
  std::vector<ImplausibleCorrection> out;
  const auto& parameters = machine.mechanism->parameters();
  const double link = meanLinkLength(machine, nominal);
  for (const int i : machine.calibrated) {
    const Quantity& q = parameters[static_cast<std::size_t>(i)].quantity;
    ImplausibleCorrection c;
    c.parameter = i;
    c.correction = p[i] - nominal[i];
    // An angle a whole turn away describes the same machine.
    if (q == Quantity::Angle) c.correction = std::remainder(c.correction, 2.0 * std::numbers::pi);
    const bool has_prior = machine.prior_sigma.size() > i && machine.prior_sigma[i] > 0.0;
    if (has_prior) {
      c.limit = tolerance.prior_multiple * machine.prior_sigma[i];
      c.from_prior = true;
    } else if (q == Quantity::Length) {
      c.limit = tolerance.length_fraction * std::max(link, std::abs(nominal[i]));
    } else if (q == Quantity::Angle) {
      c.limit = tolerance.angle;
    } else {
      continue;  // an error-function coefficient: no default tolerance
    }
    if (c.limit > 0.0 && std::abs(c.correction) > c.limit) out.push_back(c);
  }
  return out;
}

std::string describeCorrection(const Machine& machine, const ImplausibleCorrection& correction) {
  const ParameterInfo& info =
      machine.mechanism->parameters()[static_cast<std::size_t>(correction.parameter)];
  const std::string why = correction.from_prior ? "5 times its prior (machine.prior)"
                          : info.quantity == Quantity::Angle
                              ? "2 deg"
                              : "5 % of the machine's mean link length or of its nominal value";
  return info.name + " is corrected by " + fileValue(info.quantity, correction.correction) +
         ", beyond " + fileValue(info.quantity, correction.limit) + " (" + why +
         "): a model mismatch or a bad reading is more likely than such a machine; check the "
         "residuals, or fix the parameter" +
         (correction.from_prior ? std::string()
                                : ", or, with readings too few for the parameters, state the "
                                  "machine's tolerances as built (machine.prior; import-readings "
                                  "--prior)");
}

}  // namespace artcal
