#pragma once
// The typed, validated content of a plan file (docs/plan-format.md). Everything here is in internal
// units (mm, rad); conversion happens only in plan_io. A Plan does not change during a run.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "artcal/artifact/artifact.hpp"
#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/core/enum_names.hpp"
#include "artcal/core/units.hpp"
#include "artcal/model/joint_compliance.hpp"
#include "artcal/model/machine.hpp"

namespace artcal {

/// Random errors (docs/method.md section 2): probing per coordinate (mm), encoders per joint (rad
/// or mm).
struct Noise {
  double probe = 0.0;  ///< mm, per coordinate; the starting value when estimate_probe
  Eigen::VectorXd encoder;
  /// `"probe": "estimate"`: calibrate estimates the probing noise from the fit (variance
  /// component, calibration/calibrate_readings.hpp) instead of trusting `probe`.
  bool estimate_probe = false;
};

/// The probe noise `"probe": "estimate"` starts from (mm): evaluate's planning figures use it.
inline constexpr double kDefaultProbeNoiseGuess = 0.1;

/// One reading: a feature probed with the given joint values (internal units).
struct Measurement {
  int feature = 0;
  Eigen::VectorXd joints;
  int stylus = 0;  ///< the probe's stylus (Cartesian CMMs, docs/models.md section 4)
  /// Where a reading from a CSV file came from, for a person: the file as the plan names it and
  /// its data row (from 1, header and blank lines not counted); empty and 0 when listed inline.
  std::string csv = {};
  int csv_row = 0;
  /// The index of the plan file's measurement entry it came from (a CSV entry gives many).
  int entry = 0;
  /// An instrument's reading (instruments.md): the point it reported, in its station's frame
  /// (mm); empty for a calibrated artifact. Simulation rewrites it with the readings it draws.
  Eigen::VectorXd point = {};
  /// A pose instrument's reading (`"measures": "pose"`): the orientation it reported, a rotation
  /// vector in its station's frame (rad; deg in files); empty otherwise.
  Eigen::VectorXd orientation = {};
  /// An instrument's reading only: `stationing` (verify fits the new station on these).
  bool stationing = false;
  /// An instrument's reading only: false when the plan left `point` out (planning only).
  bool point_given = true;
  /// The payload the machine carried (docs/compliance.md section 1: the reading's `"payload"`,
  /// else its placement's; no mass: none). Only a machine with compliance reads it.
  Payload payload = {};
  /// Its torques as attachTorques computed them (docs/compliance.md section 2), with what they
  /// were computed for: readingTorques takes them while the joints, the payload and the model
  /// are still those, and computes afresh otherwise.
  struct Torques {
    Eigen::VectorXd tau, joints;
    Payload payload;
    const Mechanism* model = nullptr;
  } torques = {};
};

/// Reading m's gravity torques, one per joint reading (N m or N; docs/compliance.md section 2):
/// at its joints as read and its payload, with the machine's nominal geometry; empty when the
/// machine has no compliance. Fixed numbers per reading: whatever p is being fitted.
Eigen::VectorXd readingTorques(const Machine& machine, const Measurement& m);

/// The forward kinematics of reading m through its stylus at parameters p: its joints deflected
/// by the compliance under its torques (forwardLoaded, model/joint_compliance.hpp); the plain
/// forward kinematics for a machine without compliance. Every evaluation of a reading goes
/// through these.
[[nodiscard]] ForwardStatus forwardReading(const Machine& machine, const Eigen::VectorXd& p,
                                           const Measurement& m, Eigen::VectorXd& x,
                                           Eigen::MatrixXd* J_x_p = nullptr,
                                           Eigen::MatrixXd* J_x_q = nullptr);
[[nodiscard]] ForwardStatus forwardReadingPose(const Machine& machine, const Eigen::VectorXd& p,
                                               const Measurement& m, Eigen::VectorXd& x,
                                               Eigen::Matrix3d& R, Eigen::MatrixXd* J_x_p = nullptr,
                                               Eigen::MatrixXd* J_x_q = nullptr,
                                               Eigen::MatrixXd* J_w_p = nullptr,
                                               Eigen::MatrixXd* J_w_q = nullptr);
/// forwardReading() for callers with no way to go on without x: a failure raises
/// KinematicsError.
void forwardReadingOrThrow(const Machine& machine, const Eigen::VectorXd& p, const Measurement& m,
                           Eigen::VectorXd& x, Eigen::MatrixXd* J_x_p = nullptr,
                           Eigen::MatrixXd* J_x_q = nullptr);
void forwardReadingPoseOrThrow(const Machine& machine, const Eigen::VectorXd& p,
                               const Measurement& m, Eigen::VectorXd& x, Eigen::Matrix3d& R,
                               Eigen::MatrixXd* J_x_p = nullptr, Eigen::MatrixXd* J_x_q = nullptr,
                               Eigen::MatrixXd* J_w_p = nullptr, Eigen::MatrixXd* J_w_q = nullptr);

/// The coordinates reading `m` targets in the artifact frame: an instrument's measured point,
/// otherwise the artifact's feature with the systematic errors c added.
Eigen::VectorXd readingTarget(const Artifact& artifact, const Measurement& m,
                              const Eigen::VectorXd& c);

/// An instrument's reading of the nominal machine with the station at the machine frame (planning
/// only, when the plan gives no point): `m.point` the nominal tip and, for a pose instrument,
/// `m.orientation` the nominal tip frame's orientation.
void setNominalReading(const Machine& machine, const Artifact& instrument, Measurement& m);

/// Where one reading stands in the input, for a message: its CSV file (the plan's folder joined
/// with the name the plan gives) and "row N", or the plan and the reading's JSON pointer.
struct ReadingLocation {
  std::string file;
  std::string where;
};
struct Plan;
/// The location of reading `reading` of placement `placement` (indices into Plan::placements and
/// Placement::measurements, which hold one entry per CSV row).
ReadingLocation readingLocation(const Plan& plan, std::size_t placement, std::size_t reading);

/// Where an artifact is put. 2-D: center and angle; 3-D: center, direction and roll.
struct Pose {
  Eigen::VectorXd center;
  double angle = 0.0;                                    ///< 2-D, rad
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< 3-D
  double roll = 0.0;                                     ///< 3-D, rad
};

/// `{"feature": k, "postures": N}` in a placement's measurements: N nominal readings of feature k
/// still to be planned from the placement's pose (`artcal plan --complete`).
struct PostureRequest {
  int feature = 0;
  int postures = 1;
  int stylus = -1;      ///< the tip the request names ("tip", docs/urdf.md); -1: the model's rule
  std::string pointer;  ///< where the request stands in the plan file, for messages
};

struct Placement {
  int artifact = 0;  ///< index into Plan::artifacts
  std::optional<Pose> pose;
  std::vector<Measurement> measurements;
  /// The placement's `"name"` (e.g. the folder its CSV files came from); empty when the plan
  /// gives none. Outputs name a placement by it (placementLabel).
  std::string name = {};
  std::vector<PostureRequest> posture_requests = {};
};

/// Computes each reading's torques once and keeps them with it (Measurement::torques): the
/// parsed plan's readings, a simulation's.
void attachTorques(const Machine& machine, std::vector<Placement>& placements);

/// The artifact-from-machine transform of a pose (placePlanar / placeSpatial, rigid_transform.hpp).
RigidTransform poseTransform(int dimension, const Pose& pose);

/// The placed artifact's features in the machine frame (dimension x features) for `pose`.
Eigen::MatrixXd placedFeatures(const Artifact& artifact, const Pose& pose);

/// How outputs name placement `index` of `plan`: its name, or its index (from 0) when unnamed.
std::string placementLabel(const std::vector<Placement>& placements, std::size_t index);

/// Where an artifact's features may lie when planning; where a task-space workspace samples.
struct Region {
  std::optional<std::array<double, 2>> reach;         ///< distance from the machine origin, mm
  std::optional<std::array<Eigen::VectorXd, 2>> box;  ///< opposite corners, mm
  bool contains(const Eigen::VectorXd& x) const;
};

/// The joint configurations tip uncertainty is evaluated over (docs/method.md section 4).
/// TaskSpace (docs/models.md section 5): `samples` probe positions uniform in `region`, each turned
/// into a configuration by the model's inverse kinematics in a random posture (an orientation
/// within `tilt` of home for the hexapod); unreachable ones are dropped and counted.
struct WorkspaceSpec {
  enum class Kind { Configurations, Samples, Grid, TaskSpace };
  Kind kind = Kind::Samples;
  std::vector<Eigen::VectorXd> configurations;  ///< Kind::Configurations, internal units
  int samples = 4096;                           ///< Kind::Samples, Kind::TaskSpace
  std::uint64_t seed = 1;                       ///< Kind::Samples, Kind::TaskSpace
  std::vector<int> grid;                        ///< Kind::Grid, points per joint
  Region region;                                ///< Kind::TaskSpace
  double tilt = 15.0 * kDegree;                 ///< Kind::TaskSpace, rad
};

/// Pass: 1 - P(pass) of the plan's ISO 10360-2 acceptance test (its "acceptance" block).
enum class Criterion { WorstTip, MeanTip, D, A, E, Pass };

/// An instrument design (instruments.md, "Planning an instrument calibration"): the design's
/// artifact is an instrument; `DesignSpec::placements` holds its `stations`, each of `readings`
/// configurations chosen from `candidates` ones (uniform within the limits narrowed by the joint
/// margin, or task-space samples of the design's `region` when it has one), drawn with
/// `candidate_seed`.
struct InstrumentDesignSpec {
  int readings = 0;  ///< per station
  int candidates = 5000;
  std::uint64_t candidate_seed = 1;
  bool task_space = false;  ///< candidates from DesignSpec::region
};

/// The `design` block of an optimization spec.
struct DesignSpec {
  int artifact = 0;
  int placements = 1;
  int postures = 1;
  Region region;
  Criterion criterion = Criterion::WorstTip;
  std::uint64_t seed = 1;
  int starts = 16;
  double time_limit = 60.0;  ///< s
  /// Candidate placements of the exchange (`design.pool`); 0: automatic (30 per placement,
  /// 120 .. 600).
  int pool = 0;
  /// `design.evaluations`: criterion evaluations of each start's continuous refinement; 0:
  /// automatic (300 per pose variable, at most 6000).
  int evaluations = 0;
  /// `design.polish` and `design.kicks`: the best designs polished at the end, and the kicks of
  /// the iterated local search on each (docs/optimize.md); 0: none.
  int polish = 0;
  int kicks = 0;
  /// `design.target_tip` (mm): with `optimize --placements`, the criterion value to reach.
  std::optional<double> target_tip;
  /// How far inside the joint limits every planned reading stays, per joint (rad or mm):
  /// `design.joint_margin` (deg for revolute, mm for prismatic joints), default 2 deg / 1 mm, so
  /// that a machine a little off nominal still reaches every planned point (docs/plan-format.md).
  Eigen::VectorXd joint_margin;
  /// Set when the design's artifact is an instrument.
  std::optional<InstrumentDesignSpec> instrument;
};

/// The default of `design.joint_margin`, file units: 2 deg for a revolute joint, 1 mm for a
/// prismatic one.
inline constexpr double kDefaultRevoluteMarginDeg = 2.0;
inline constexpr double kDefaultPrismaticMarginMm = 1.0;

/// `"calibrate": "identifiable"` once resolved (estimation/identifiability.hpp): the listed
/// parameters the plan's nominal readings cannot identify (indices into the model's parameters)
/// and, for each, the combination with the kept ones it is tied to (parameter index, coefficient
/// in the scaled parameters).
/// The weak rule's choice over every listed parameter at some parameter values
/// (estimation/identifiability.hpp, weakRuleChoice).
struct WeakRuleChoice {
  std::vector<int> kept;  ///< model parameter indices, in the listed order
  /// Of `structural`, those not kept, with their surviving fractions.
  std::vector<int> held;
  std::vector<double> held_fraction;
  /// Of the kept ones, those `structural` lacks (calibrated in place of held ones).
  std::vector<int> in_place;
  /// Whether the plan's current calibrated set passes the rule by itself (the smallest
  /// eigenvalue of S over it above the tolerance).
  bool current_passes = false;

  /// The set to calibrate, given the `current` one the rule was judged against: `current` where
  /// it passes and the rule's choice is no larger (the same directions under other names of an
  /// exact tie, or rounding, never move a fit), else the rule's choice (empty: `current`).
  const std::vector<int>& setFor(const std::vector<int>& current) const {
    if (kept.empty() || (current_passes && kept.size() <= current.size())) return current;
    return kept;
  }
};

/// A listed parameter whose sqrt(N_kk) is below this fraction of the largest is not observed.
inline constexpr double kUnobservedInformation = 1e-9;

struct CalibratedSetResolution {
  std::vector<int> listed;  ///< the candidates in preferred order, before the resolution
  std::vector<int> kept;
  std::vector<int> dropped;
  std::vector<std::vector<std::pair<int, double>>> ties;
  /// Of `dropped`, those with no information at all: sqrt(N_kk) of the unreduced normal matrix
  /// below kUnobservedInformation of the largest (a compliance whose torque is zero at every
  /// reading, docs/compliance.md section 4): named "not observed".
  std::vector<int> unobserved;
  /// Held at nominal by calibrate on measured readings (calibration/calibrate_readings.hpp):
  /// surviving fraction below 1e-6 at the nominal parameters or at the estimate.
  std::vector<int> weak;
  std::vector<double> weak_fraction;  ///< each one's surviving fraction when it was held
  /// Calibrated by calibrate though the structural rule dropped them: the weak rule's choice
  /// over every listed parameter takes them in place of tied ones it holds (a tool length in
  /// place of a wrist's twist, calibration/calibrate_readings.hpp).
  std::vector<int> in_place;
  /// Ranked last by the weak rule's pivoting (the plausible-minimum search's demoted parameters,
  /// calibration/plausible_minimum.hpp): taken only where the others cannot carry a direction.
  std::vector<int> last;
  /// The weak rule at the nominal parameters, from the information the structural rule read
  /// (resolveListedSet): what calibrate of measured readings calibrates first, and what check
  /// says it will hold.
  WeakRuleChoice at_nominal;
};

/// The plan's optional `acceptance` block (docs/plan-format.md; docs/method.md section 9): the test
/// the calibrated machine must pass, as the file states it.
struct AcceptanceSpec {
  std::string test;                             ///< "iso10360-2" or "iso9283"
  std::string mpe;                              ///< "A + L/K" (um, mm) or, for iso9283, mm as text
  std::optional<double> cube;                   ///< iso9283, mm
  std::optional<Eigen::Vector3d> center;        ///< iso9283, mm
  std::optional<Eigen::Vector3d> orientation;   ///< iso9283, the cube's roll, pitch, yaw, rad
  std::optional<Eigen::VectorXd> seed_posture;  ///< iso9283, internal units (parsePlan)
  std::optional<double> unmodelled;             ///< iso9283, mm per coordinate
};

struct Plan {
  std::string source;  ///< the file it came from, for messages
  std::string name;
  std::string description;
  Machine machine;
  Noise noise;
  std::vector<Artifact> artifacts;
  std::vector<Placement> placements;
  WorkspaceSpec workspace;
  std::optional<DesignSpec> design;
  std::vector<std::string> warnings;  ///< e.g. unknown fields ignored
  std::optional<CalibratedSetResolution> calibrate_resolution;
  std::optional<AcceptanceSpec> acceptance;

  int artifactIndex(const std::string& id) const;
};

/// The criteria by their names in plan files ("design": {"criterion": ...}).
inline constexpr EnumNames<Criterion, 6> kCriterionNames{{{Criterion::WorstTip, "worst-tip"},
                                                          {Criterion::MeanTip, "mean-tip"},
                                                          {Criterion::D, "D"},
                                                          {Criterion::A, "A"},
                                                          {Criterion::E, "E"},
                                                          {Criterion::Pass, "pass"}}};
std::string criterionName(Criterion criterion);
std::optional<Criterion> criterionFromName(const std::string& name);

}  // namespace artcal
