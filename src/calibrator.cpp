#include "artcal/calibrator.hpp"

#include <cmath>
#include <sstream>
#include <utility>

namespace artcal {

std::string terminationName(TerminationType type) {
  switch (type) {
    case TerminationType::Converged:
      return "converged";
    case TerminationType::NoConvergence:
      return "no_convergence";
    case TerminationType::Failure:
      return "failure";
  }
  return "failure";
}

bool CalibrationOptions::isValid(std::string* error) const {
  auto fail = [error](const char* message) {
    if (error) *error = message;
    return false;
  };
  if (max_iterations < 1) return fail("max_iterations must be at least 1");
  if (!(step_tolerance > 0.0) || !std::isfinite(step_tolerance))
    return fail("step_tolerance must be > 0");
  if (!(function_tolerance >= 0.0) || !std::isfinite(function_tolerance))
    return fail("function_tolerance must be >= 0");
  if (!(flag_threshold > 0.0) || !std::isfinite(flag_threshold))
    return fail("flag_threshold must be > 0");
  return damping.isValid(error);
}

std::string CalibrationSummary::briefReport() const {
  std::ostringstream out;
  out << terminationName(termination) << " after " << iterations << " iterations ("
      << accepted_steps << " steps accepted), cost " << initial_cost << " -> " << final_cost;
  if (!message.empty()) out << ": " << message;
  return out.str();
}

Eigen::VectorXd Calibration::posteriorU() const {
  if (!covariance) return {};
  return covariance->u * std::sqrt(chi2_per_dof);
}

Calibrator::Calibrator(const Plan& plan, const CalibrationOptions& options)
    : plan_(&plan),
      options_(options),
      layout_(GlobalLayout::of(plan)),
      builder_(plan.machine, plan.noise),
      reducer_(layout_),
      strategy_(options.damping) {
  std::string error;
  if (!options_.isValid(&error)) throw std::invalid_argument("calibration options: " + error);
}

namespace {

const Artifact& artifactOf(const Plan& plan, const Placement& placement) {
  return plan.artifacts[static_cast<std::size_t>(placement.artifact)];
}

/// The systematic errors of one artifact, taken from c (GlobalLayout order).
Eigen::VectorXd artifactErrors(const GlobalLayout& layout, const Artifact& artifact,
                               int artifact_index, const Eigen::VectorXd& c) {
  const int offset =
      layout.artifact_offset[static_cast<std::size_t>(artifact_index)] - layout.parameters;
  return c.segment(offset, artifact.systematicCount());
}

}  // namespace

bool Calibrator::linearize(const std::vector<Placement>& placements, State& state) {
  const Plan& plan = *plan_;
  reducer_.reset();
  state.eliminations.resize(placements.size());
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = artifactOf(plan, placements[j]);
    const Eigen::VectorXd c_j = artifactErrors(layout_, artifact, placements[j].artifact, state.c);
    builder_.build(artifact, placements[j].measurements, state.p, state.poses[j], c_j, true,
                   block_);
    reducer_.add(block_, placements[j].artifact, &state.eliminations[j]);
  }
  // The prior on c (method.md section 2): cost c^T Sigma_c^-1 c, gradient and curvature added.
  const Eigen::VectorXd prior = layout_.c_sigma.array().square().inverse();
  state.cost = reducer_.chi2() + state.c.dot(prior.asDiagonal() * state.c);
  state.N = reducer_.normalWithPrior();
  state.b = reducer_.rhs();
  state.b.tail(layout_.systematicCount()) -= prior.asDiagonal() * state.c;
  return std::isfinite(state.cost) && state.N.allFinite() && state.b.allFinite();
}

void Calibrator::candidate(const State& from, const Eigen::VectorXd& dg,
                           const std::vector<Placement>& placements, State& to) const {
  const Machine& machine = plan_->machine;
  const int n_p = layout_.parameters;
  to.p = machine.withCalibrated(from.p, machine.calibratedValues(from.p) + dg.head(n_p));
  to.c = from.c + dg.tail(layout_.systematicCount());
  to.poses.resize(from.poses.size());
  for (std::size_t j = 0; j < placements.size(); ++j) {
    // Back-substitution of r_j for the global step (method.md section 3).
    const Artifact& artifact = artifactOf(*plan_, placements[j]);
    const Eigen::VectorXd dr = from.eliminations[j].rigidStep(dg);
    to.poses[j] = from.poses[j].perturbed(artifact.expandRigidStep(dr));
  }
}

Calibration Calibrator::run(const std::vector<Placement>& placements) {
  return run(placements, plan_->machine.nominal);
}

Calibration Calibrator::run(const std::vector<Placement>& placements,
                            const Eigen::VectorXd& start) {
  Calibration out;
  CalibrationSummary& summary = out.summary;
  current_.p = start;
  current_.c = Eigen::VectorXd::Zero(layout_.systematicCount());
  current_.poses = fitPlacements(*plan_, placements, start);
  strategy_.reset();
  bool finite = linearize(placements, current_);
  summary.initial_cost = current_.cost;
  if (!finite) {
    summary.termination = TerminationType::Failure;
    summary.message = "the problem is not finite at the starting values";
  } else {
    summary.termination = TerminationType::NoConvergence;
    summary.message = "max_iterations reached";
  }
  Eigen::VectorXd dg;
  for (int it = 1; finite && it <= options_.max_iterations; ++it) {
    summary.iterations = it;
    const bool solved = strategy_.computeStep(current_.N, current_.b, dg);
    const double scaled_step =
        solved ? (dg.array() * current_.N.diagonal().array().max(0.0).sqrt()).abs().maxCoeff()
               : 0.0;
    // A tiny step only means convergence when the damping is not what made it tiny.
    if (solved && scaled_step < options_.step_tolerance && strategy_.mu() <= 1.0) {
      summary.termination = TerminationType::Converged;
      summary.message = "step below step_tolerance";
      break;
    }
    const double predicted =
        solved ? LevenbergMarquardtStrategy::predictedReduction(current_.N, current_.b, dg) : 0.0;
    // The weights depend on p (method.md section 2), so the reweighted Gauss-Newton fixed point
    // is where the linear model promises nothing more, not where the cost stops falling exactly.
    if (solved && strategy_.mu() <= 1.0 &&
        predicted <= options_.function_tolerance * current_.cost) {
      summary.termination = TerminationType::Converged;
      summary.message = "predicted cost change below function_tolerance";
      break;
    }
    bool accepted = false;
    double actual = 0.0;
    if (solved && predicted > 0.0) {
      candidate(current_, dg, placements, trial_);
      if (linearize(placements, trial_)) {
        actual = current_.cost - trial_.cost;
        accepted = actual > 0.0;
      }
    }
    if (!accepted) {
      strategy_.stepRejected();
      if (strategy_.exhausted()) {
        summary.termination = TerminationType::Failure;
        summary.message = "no step reduces the cost (damping exhausted)";
        break;
      }
      continue;
    }
    strategy_.stepAccepted(actual / predicted);
    ++summary.accepted_steps;
    const double previous_cost = current_.cost;
    std::swap(current_, trial_);
    if (actual <= options_.function_tolerance * previous_cost) {
      summary.termination = TerminationType::Converged;
      summary.message = "cost change below function_tolerance";
      break;
    }
  }
  summary.final_cost = current_.cost;
  out.parameters = current_.p;
  out.systematic = current_.c;
  out.poses = current_.poses;
  out.chi2 = current_.cost;
  int rows = 0;
  for (const Placement& placement : placements) {
    const Artifact& artifact = artifactOf(*plan_, placement);
    rows += artifact.valuedPerFeature() * static_cast<int>(placement.measurements.size());
    out.dof -= artifact.rigidDof();
  }
  out.dof += rows - layout_.parameters;
  out.chi2_per_dof = out.dof > 0 && std::isfinite(out.chi2) ? out.chi2 / out.dof : 0.0;
  if (options_.details && finite) fillDetails(placements, out);
  return out;
}

void Calibrator::fillDetails(const std::vector<Placement>& placements, Calibration& out) {
  const Plan& plan = *plan_;
  reducer_.reset();
  out.residuals.clear();
  Eigen::VectorXd x;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Placement& placement = placements[j];
    const Artifact& artifact = artifactOf(plan, placement);
    const Eigen::VectorXd c_j =
        artifactErrors(layout_, artifact, placement.artifact, out.systematic);
    builder_.build(artifact, placement.measurements, out.parameters, out.poses[j], c_j, true,
                   block_);
    reducer_.add(block_, placement.artifact);
    const int k = artifact.valuedPerFeature();
    for (std::size_t i = 0; i < placement.measurements.size(); ++i) {
      const Measurement& m = placement.measurements[i];
      plan.machine.mechanism->forward(out.parameters, m.joints, x);
      ResidualEntry entry;
      entry.placement = static_cast<int>(j);
      entry.measurement = static_cast<int>(i);
      entry.feature = m.feature;
      entry.residual = (out.poses[j].apply(x) - artifact.feature(m.feature, c_j)).head(k);
      entry.normalized = block_.e.segment(k * static_cast<int>(i), k);
      entry.score = entry.normalized.cwiseAbs().maxCoeff();
      entry.flagged = entry.score > options_.flag_threshold;
      if (out.largest_residual < 0 || entry.score > out.residuals[out.largest_residual].score) {
        out.largest_residual = static_cast<int>(out.residuals.size());
      }
      out.residuals.push_back(std::move(entry));
    }
  }
  out.covariance = covarianceFromInformation(reducer_.parameterInformation());
}

Calibration calibratePlan(const Plan& plan, const CalibrationOptions& options) {
  Calibrator calibrator(plan, options);
  return calibrator.run(plan.placements);
}

}  // namespace artcal
