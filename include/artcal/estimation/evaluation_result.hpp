#pragma once
// What evaluating a plan answers (evaluator.hpp computes it, tip.hpp the tip figures;
// docs/method.md sections 3-5): plain result types, so that a reader of results (report/)
// includes no computation. Internal units (mm, rad) throughout.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "artcal/estimation/identifiability_result.hpp"

namespace artcal {

/// What workspaceConfigurations left out of a workspace.
struct WorkspaceDrops {
  int unreachable = 0;  ///< task-space samples with no posture within the joint limits
  int failed = 0;       ///< configurations whose forward kinematics fails (closed chains)
  int total() const { return unreachable + failed; }
};

struct TipPoint {
  double total = 0.0;      ///< S
  double kinematic = 0.0;  ///< S_m
  double encoder = 0.0;    ///< S_q
};

struct TipSummary {
  TipPoint worst;
  int worst_index = -1;  ///< into the workspace configurations
  double mean = 0.0;     ///< mean of S over the workspace
  double rms = 0.0;      ///< sqrt(mean of S^2): the I criterion's root
};

/// One tip of a machine with several named tips (a chain's "tips", docs/urdf.md): its tip
/// uncertainty over the workspace configurations every tip is evaluated at, and the calibrated
/// parameters that move it, whose rows and columns of V_p are its covariance.
struct NamedTipSummary {
  std::string name;
  TipSummary tip;
  std::vector<int> calibrated;  ///< indices into the machine's calibrated parameters
};

/// One row of the reach profile: the worst branch at distance `reach` from the base.
struct ProfilePoint {
  double reach = 0.0;
  TipPoint tip;
};

/// V_p and what follows from it directly.
struct ParameterCovariance {
  Eigen::MatrixXd V;  ///< internal units
  Eigen::VectorXd u;  ///< sqrt(diag V), internal units
  Eigen::MatrixXd correlation;
  /// The confounding index F_k = u_k / u_k(alone), u_k(alone) = 1 / sqrt(N_red[k, k]) (the
  /// parameter's u with every other calibrated one held): >= 1, 1 = as well determined as if it
  /// were the only unknown (docs/five-axis.md).
  Eigen::VectorXd confounding;
};

struct Evaluation {
  Identifiability identifiability;
  Eigen::MatrixXd information;                    ///< of p, internal units
  Eigen::VectorXd unreduced_diagonal;             ///< the rank test's scale (identifiability.hpp)
  std::optional<ParameterCovariance> covariance;  ///< absent when not identifiable
  std::optional<TipSummary> tip;                  ///< the first tip's when the machine has several
  /// Per tip, in the machine's order, when it names two or more (tips[0].tip equals `tip`);
  /// empty otherwise.
  std::vector<NamedTipSummary> tips;
  std::vector<ProfilePoint> profile;  ///< planar2r only
  /// Per placement, its artifact's features in the machine frame (columns, mm): x = R^T (W - t)
  /// with r_j the placement's pose or the rigid fit to its nominal readings, the r_j the
  /// information was taken at. Present whether or not the plan is identifiable.
  std::vector<Eigen::MatrixXd> placed_features;
  std::vector<Eigen::VectorXd> workspace;  ///< the configurations evaluated
  /// S at each configuration of `workspace`, mm (S^2 = S_m^2 + S_q^2, the values `tip`
  /// summarizes): what the report's map draws.
  std::vector<double> workspace_total;
  /// S_m and S_q at each configuration of `workspace`, mm (the parts of workspace_total).
  std::vector<double> workspace_kinematic, workspace_encoder;
  WorkspaceDrops workspace_drops;  ///< samples left out of `workspace`
  bool identifiable() const { return identifiability.identifiable() && covariance.has_value(); }
};

}  // namespace artcal
