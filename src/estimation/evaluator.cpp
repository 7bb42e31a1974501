#include "artcal/estimation/evaluator.hpp"

#include "artcal/core/dense_decompositions.hpp"
#include <cmath>
#include <string>

#include "artcal/core/error.hpp"
#include "artcal/estimation/consistent_readings.hpp"

namespace artcal {

std::optional<ParameterCovariance> covarianceFromInformation(const Eigen::MatrixXd& information) {
  const int n = static_cast<int>(information.rows());
  // Invert in scaled form (unit diagonal): parameters in mm and rad differ by orders of magnitude.
  const Eigen::VectorXd diagonal = information.diagonal();
  if (!(diagonal.array() > 0.0).all() || !diagonal.allFinite()) return std::nullopt;
  const Eigen::VectorXd scale = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = scale.asDiagonal() * information * scale.asDiagonal();
  const Eigen::LLT<Eigen::MatrixXd> llt(scaled);
  if (llt.info() != Eigen::Success) return std::nullopt;
  const Eigen::MatrixXd scaled_inverse = llt.solve(Eigen::MatrixXd::Identity(n, n));
  ParameterCovariance cov;
  cov.V = scale.asDiagonal() * scaled_inverse * scale.asDiagonal();
  if (!cov.V.allFinite() || !(cov.V.diagonal().array() > 0.0).all()) return std::nullopt;
  cov.u = cov.V.diagonal().cwiseSqrt();
  cov.correlation = cov.u.cwiseInverse().asDiagonal() * cov.V * cov.u.cwiseInverse().asDiagonal();
  cov.confounding = cov.u.cwiseProduct(diagonal.cwiseSqrt());
  return cov;
}

namespace {

// Every placement's observation block, its r_j eliminated as it arrives (docs/method.md section 3):
// the information of p. The one loop behind parameterInformation and PlanEvaluator.
Eigen::MatrixXd reduceInformation(const Plan& plan, const std::vector<Placement>& placements,
                                  const Eigen::VectorXd& p,
                                  const std::vector<RigidTransform>& poses,
                                  DesignMatrixBuilder& builder, NormalMatrixReducer& reducer,
                                  ObservationBlock& block, ParameterPrior prior,
                                  const std::vector<int>* rigid_caps = nullptr) {
  reducer.reset();
  const Eigen::VectorXd no_c;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placements[j].artifact)];
    builder.build(artifact, placements[j].measurements, p, poses[j], no_c, false, block);
    reducer.add(block, placements[j].artifact, nullptr, rigid_caps ? (*rigid_caps)[j] : -1);
  }
  return reducer.parameterInformation(prior);
}

}  // namespace

PlanInformation planInformation(const Plan& plan, const std::vector<Placement>& placements,
                                const Eigen::VectorXd& p, bool with_estimable) {
  DesignMatrixBuilder builder(plan.machine, plan.noise);
  NormalMatrixReducer reducer(GlobalLayout::of(plan));
  ObservationBlock block;
  PlanInformation out;
  // The readings' own information decides identifiability; the prior only narrows V_p.
  out.poses = fitPlacements(plan, placements, p);
  const std::vector<RigidTransform>& poses = out.poses;
  out.reduced = reduceInformation(plan, placements, p, poses, builder, reducer, block,
                                  ParameterPrior::Excluded);
  out.unreduced_diagonal = reducer.unreducedDiagonal();
  out.rigid_ranks = reducer.rigidRanks();
  if (!with_estimable) return out;
  // V_p eliminates only what the calibrated features see (PlanInformation::estimable): a second
  // pass where the readings made more look observed.
  std::vector<int> caps;
  bool capped = false;
  for (std::size_t j = 0; j < placements.size(); ++j) {
    const Artifact& artifact = plan.artifacts[static_cast<std::size_t>(placements[j].artifact)];
    caps.push_back(rigidRankOfFeatures(artifact, placements[j].measurements));
    capped = capped || out.rigid_ranks[j] > caps.back();
  }
  out.estimable = capped ? reduceInformation(plan, placements, p, poses, builder, reducer, block,
                                             ParameterPrior::Excluded, &caps)
                         : out.reduced;
  return out;
}

PlanInformation verdictInformation(const Plan& plan, const std::vector<Placement>& placements,
                                   bool with_estimable) {
  const Eigen::VectorXd& p = plan.machine.nominal;
  const auto consistent = consistentPlacements(plan, placements, p);
  return planInformation(plan, consistent ? *consistent : placements, p, with_estimable);
}

Eigen::MatrixXd placementsInformation(const Plan& plan, const std::vector<Placement>& placements,
                                      const Eigen::VectorXd& p) {
  return addParameterPrior(planInformation(plan, placements, p).estimable, GlobalLayout::of(plan));
}

namespace {

// None of the plan's workspace configurations usable (every task-space sample out of reach, or
// every configuration's forward kinematics failing) is the plan's fault, answered at /workspace: a
// tip uncertainty over nothing has no worst case (fuzz_spec found the crash it used to be).
void requireUsable(const Plan& plan, std::size_t usable, const WorkspaceDrops& drops) {
  if (usable > 0) return;
  throw InputError(plan.source, "/workspace",
                   "no workspace configuration is usable (" + std::to_string(drops.unreachable) +
                       " samples out of reach, " + std::to_string(drops.failed) +
                       " whose forward kinematics fails at nominal): check workspace.region "
                       "and the machine's dimensions and joint_limits");
}

// The plan's usable workspace configurations (workspaceConfigurations, requireUsable).
std::vector<Eigen::VectorXd> usableWorkspace(const Plan& plan) {
  WorkspaceDrops drops;
  std::vector<Eigen::VectorXd> workspace =
      workspaceConfigurations(plan.machine, plan.workspace, &drops);
  requireUsable(plan, workspace.size(), drops);
  return workspace;
}

// Each placement's features in the machine frame, x = R^T (W - t), at its r_j.
std::vector<Eigen::MatrixXd> featuresInMachineFrame(const Plan& plan,
                                                    const std::vector<RigidTransform>& poses) {
  std::vector<Eigen::MatrixXd> out;
  for (std::size_t j = 0; j < plan.placements.size(); ++j) {
    const Artifact& artifact =
        plan.artifacts[static_cast<std::size_t>(plan.placements[j].artifact)];
    const RigidTransform machine_from_artifact = poses[j].inverse();
    Eigen::MatrixXd features(artifact.dimension, artifact.featureCount());
    for (int i = 0; i < artifact.featureCount(); ++i) {
      features.col(i) = machine_from_artifact.apply(artifact.features.col(i));
    }
    out.push_back(features);
  }
  return out;
}

// S, S_m and S_q per workspace configuration (mm) from S_m^2: the values
// TipEvaluator::summarizeVariance summarizes.
void perConfiguration(const TipEvaluator& tips, const Eigen::VectorXd& S_m2,
                      Evaluation& evaluation) {
  const auto count = static_cast<std::size_t>(tips.size());
  evaluation.workspace_total.resize(count);
  evaluation.workspace_kinematic.resize(count);
  evaluation.workspace_encoder.resize(count);
  for (int g = 0; g < tips.size(); ++g) {
    const auto at = static_cast<std::size_t>(g);
    evaluation.workspace_total[at] = std::sqrt(S_m2[g] + tips.encoderVariance()[g]);
    evaluation.workspace_kinematic[at] = std::sqrt(S_m2[g]);
    evaluation.workspace_encoder[at] = std::sqrt(tips.encoderVariance()[g]);
  }
}

}  // namespace

PlanEvaluator::PlanEvaluator(const Plan& plan) : PlanEvaluator(plan, usableWorkspace(plan)) {}

namespace {

// The workspace at every tip of a machine with named tips (docs/urdf.md): each configuration once
// per tip, so that the worst is the worst over every tip.
TipEvaluator everyTip(const Plan& plan, std::vector<Eigen::VectorXd> workspace) {
  const auto tips = static_cast<int>(plan.machine.mechanism->stylusNames().size());
  if (tips <= 1) return {plan.machine, plan.noise, std::move(workspace)};
  std::vector<Eigen::VectorXd> configurations;
  std::vector<int> styluses;
  for (int t = 0; t < tips; ++t) {
    configurations.insert(configurations.end(), workspace.begin(), workspace.end());
    styluses.insert(styluses.end(), workspace.size(), t);
  }
  return {plan.machine, plan.noise, std::move(configurations), std::move(styluses)};
}

}  // namespace

PlanEvaluator::PlanEvaluator(const Plan& plan, std::vector<Eigen::VectorXd> workspace)
    : plan_(&plan),
      workspace_size_(static_cast<int>(workspace.size())),
      tip_(everyTip(plan, std::move(workspace))),
      builder_(plan.machine, plan.noise),
      reducer_(GlobalLayout::of(plan)) {}

const Eigen::MatrixXd& PlanEvaluator::information(const std::vector<Placement>& placements,
                                                  const std::vector<RigidTransform>* poses) {
  const Plan& plan = *plan_;
  std::vector<RigidTransform> fitted;
  if (!poses) {
    fitted = fitPlacements(plan, placements, plan.machine.nominal);
    poses = &fitted;
  }
  information_ = reduceInformation(plan, placements, plan.machine.nominal, *poses, builder_,
                                   reducer_, block_, ParameterPrior::Included);
  return information_;
}

std::optional<TipSummary> PlanEvaluator::tip(const std::vector<Placement>& placements,
                                             const std::vector<RigidTransform>* poses) {
  const auto covariance = covarianceFromInformation(information(placements, poses));
  if (!covariance) return std::nullopt;
  TipSummary summary = tip_.summarize(covariance->V);
  if (summary.worst_index >= 0 && workspace_size_ > 0) summary.worst_index %= workspace_size_;
  return summary;
}

Evaluation evaluatePlan(const Plan& plan, const EvaluateOptions& options) {
  Evaluation evaluation;
  // The verdict from the planned-equivalent readings (verdictInformation), V_p from the readings
  // as they are: the same matrix where they are consistent (planned readings), computed once.
  const Eigen::VectorXd& nominal = plan.machine.nominal;
  const auto consistent = consistentPlacements(plan, plan.placements, nominal);
  PlanInformation information = planInformation(plan, plan.placements, nominal);
  evaluation.identifiability = analyseIdentifiability(
      plan, plan.placements,
      consistent ? planInformation(plan, *consistent, nominal, false) : information,
      options.rank_tolerance);
  evaluation.information = addParameterPrior(information.estimable, GlobalLayout::of(plan));
  evaluation.unreduced_diagonal = std::move(information.unreduced_diagonal);
  evaluation.placed_features = featuresInMachineFrame(plan, information.poses);
  if (evaluation.identifiability.deficiency > 0) return evaluation;
  evaluation.covariance = covarianceFromInformation(evaluation.information);
  if (!evaluation.covariance) return evaluation;
  // One covariance, one evaluation: the direct product, nothing prepared (TipUse); the samples'
  // forward kinematics checked as their Jacobians are made.
  WorkspaceDrops& drops = evaluation.workspace_drops;
  const TipEvaluator tip = TipEvaluator::ofSamples(
      plan.machine, plan.noise, workspaceSamples(plan.machine, plan.workspace, &drops), drops,
      TipUse::Once);
  requireUsable(plan, static_cast<std::size_t>(tip.size()), drops);
  evaluation.workspace = tip.configurations();
  Eigen::VectorXd S_m2;
  tip.kinematicVariance(evaluation.covariance->V, S_m2);
  evaluation.tip = tip.summarizeVariance(S_m2);
  perConfiguration(tip, S_m2, evaluation);
  // Several named tips (docs/urdf.md): each tip at the same configurations, one V_p.
  const std::vector<std::string> tip_names = plan.machine.mechanism->stylusNames();
  if (tip_names.size() > 1) {
    // Tip 0's is the evaluation's own (`tip` above).
    evaluation.tips.push_back({tip_names.front(), *evaluation.tip, tip.movingParameters()});
    for (std::size_t t = 1; t < tip_names.size(); ++t) {
      const TipEvaluator of_tip(plan.machine, plan.noise, evaluation.workspace, static_cast<int>(t),
                                TipUse::Once);
      evaluation.tips.push_back(
          {tip_names[t], of_tip.summarize(evaluation.covariance->V), of_tip.movingParameters()});
    }
  }
  evaluation.profile =
      reachProfile(plan.machine, plan.noise, evaluation.covariance->V, options.profile_steps);
  return evaluation;
}

}  // namespace artcal
