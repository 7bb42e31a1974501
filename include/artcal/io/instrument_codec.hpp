#pragma once
// The instrument artifact in a plan file (instruments.md): `"type": "instrument"` with `measures`
// and `noise`, and an instrument placement's readings (one station): `joints` and the `point` the
// instrument reported (or a CSV of joints then measured coordinates), `stationing` for verify.
// Every fault raises InputError with the JSON pointer (or the CSV file and row).

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "artcal/io/artifact_registry.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// `{"type": "instrument", "measures": "point" | "pose", "noise": mm, "noise_angle": deg}`.
/// `"pose"` needs a model whose forward kinematics gives an orientation.
ArtifactCodec instrumentArtifactCodec();

/// Joint values of a reading from its JSON array (file units), checked against the limits and the
/// nominal forward kinematics by the plan reader.
using JointsFromNode = std::function<Eigen::VectorXd(const Node& joints)>;
/// A CSV row's joint values checked likewise: InputError(file, where, ...) on a fault.
using CheckCsvJoints = std::function<void(const Eigen::VectorXd& q, const std::string& file,
                                          const std::string& where)>;

/// The readings of one station (`measurements` of an instrument placement) appended to
/// `placement`: each one's point becomes a feature of `instrument`. `plan_source` locates CSVs.
void parseStationReadings(const Node& measurements, const std::string& plan_source,
                          const Machine& machine, Artifact& instrument, Placement& placement,
                          const JointsFromNode& joints_from_node,
                          const CheckCsvJoints& check_csv_joints,
                          std::vector<std::string>& warnings);

/// A station needs at least 3 readings whose nominal tip points are not collinear (its rotation
/// about their line would be free): InputError at `placement_node` otherwise, naming the station.
void checkStation(const Node& placement_node, const Machine& machine, const Placement& placement,
                  const std::string& label);

}  // namespace artcal
