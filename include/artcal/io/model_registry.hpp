#pragma once
// The model registry: every mechanism family the plan format knows, by its name in files.
//
// A family is two halves. The model (src/model/, Eigen only) is a Mechanism: its parameter list
// with each parameter's Quantity (length, angle, or a coefficient unit such as "um/m"), forward
// kinematics with exact Jacobians and status, and its capabilities (Mechanism's virtual
// functions with defaults: closed-form inverse kinematics, postures per point, reach profile,
// skeleton for drawings; a family's extras as interfaces the model returns itself as:
// orientedPostures() when its postures are orientations, axisErrorFunctions() when its
// parameters are error functions of its axes, whose analyses live in estimation/ and
// acceptance/). The codec (src/io/, the only layer that sees JSON) reads the plan's machine
// block into that Mechanism, its nominal parameter vector and, when the family has them, its
// own default joint limits; and writes the block back with given parameters (`calibrate
// --write-machine`). Nothing outside the model layer and this registry names a family: no
// include of its header, no cast to its class, no comparison with its name
// (tests/model/family_names.cmake checks it).
//
// How to add a family "foo":
//   1. include/artcal/model/foo.hpp + src/model/foo.cpp: `class Foo final : public Mechanism`.
//      Override parameters(), forward() (return NotConverged/Singular instead of throwing),
//      and any capability whose default does not suit (a closed-form inverse makes the planner
//      faster and exact; posturesPerPoint() when the solutions are a finite set; reachRange()
//      and configurationsAtReach() only when the tip uncertainty depends on the reach alone;
//      skeleton() to be drawn in the report; orientedPostures() or axisErrorFunctions() to
//      reach the analyses written for them). Quantities: Quantity::Length, Quantity::Angle or
//      Quantity::coefficient(kind, "unit", scale) (core/units.hpp; kMicrometrePerMetre).
//      Test it in tests/model/test_foo.cpp with the finite-difference battery
//      (tests/support/finite_difference.hpp).
//   2. include/artcal/io/foo_codec.hpp + src/io/foo_codec.cpp: `ModelCodec fooCodec();` with
//      read() (use Node from io/json_node.hpp: every fault names its JSON pointer; call
//      machine.warnUnknown with your own fields only) and
//      write() (file units: toFileUnit(parameter quantity, value)).
//   3. One line in the table of src/io/model_registry.cpp: `fooCodec(),` (with its #include).
// The common part of the machine block (model, calibrate, joint_limits, covariance) is read by
// plan_io, which hands the codec the block without it.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "artcal/io/json_node.hpp"
#include "artcal/model/mechanism.hpp"

namespace artcal {

/// What a codec reads from a machine block.
struct MachineBlock {
  MechanismPtr mechanism;
  Eigen::VectorXd nominal;  ///< every parameter of the model, internal units
  /// The family's own joint limits, used when the block has no joint_limits (empty: none, the
  /// common default applies: +-180 deg for revolute joints, prismatic ones must be given).
  std::vector<std::array<double, 2>> default_limits;
};

/// A family's JSON codec: reads and writes its part of the plan's machine block.
struct ModelCodec {
  std::string name;  ///< "model" in plan files
  /// The machine block (its "model" already matched) to a mechanism and its nominal values;
  /// InputError through `machine` on any fault; unknown fields go to `warnings`.
  std::function<MachineBlock(const Node& machine, std::vector<std::string>& warnings)> read;
  /// Writes the family's fields of the machine block for `mechanism` (made by read) with the full
  /// parameter vector `parameters` (internal units) into `out` (model, calibrate and
  /// joint_limits are written by the caller).
  std::function<void(const Mechanism& mechanism, const Eigen::VectorXd& parameters,
                     nlohmann::json& out)>
      write;
};

/// Every registered family, in registration order.
const std::vector<ModelCodec>& modelCodecs();
/// The codec of family `name`, or nullptr.
const ModelCodec* findModelCodec(const std::string& name);
/// "planar2r, serial-dh or ..." for messages.
std::string modelNameList();
/// codec.read() of a machine block without the members every block shares (model, calibrate,
/// joint_limits, covariance: plan_io reads them), so that the codec checks only its own.
MachineBlock readOwnMembers(const ModelCodec& codec, const Node& machine,
                            std::vector<std::string>& warnings);

}  // namespace artcal
