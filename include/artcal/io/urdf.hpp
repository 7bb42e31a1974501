#pragma once
// URDF import and export of the `chain` model (docs/models.md section 1).
//
// Import: the chain of joints from a base link to a tip link (up the tree to their common
// ancestor, each joint there "reversed", then down), parsed with urdfdom (the model:
// links, joints, types, axes, limits); the <origin> values are read from the file's own text with
// tinyxml2 (urdfdom keeps origins as quaternions, and back to roll-pitch-yaw loses digits near
// pitch = +-90 deg). Metres and radians become mm and degrees; joint_limits come from <limit>
// (continuous joints: -180..180 deg). A <mimic> becomes the joint's "mimic" (offset in mm or
// deg); the readings and joint_limits are the driving joints' (a master off the chain, with its
// <limit>, where its first mimic stands); a mimic of a missing joint, of a mimic (a cycle) or of
// another type is refused naming the <mimic>'s line.
//
// Export: the input URDF with the chain's <origin> xyz and rpy attributes replaced by the
// machine's, and nothing else changed (meshes, limits, gazebo and transmission tags, comments
// stay). A movable joint's offset d is folded exactly into the origins of the joints that hang
// from its child link (the chain's next joint among them): M(q + d) = M(q) M(d), and M(d)
// premultiplies each such origin (Rot(axis, d) for a revolute joint, Trans(d axis) for a
// prismatic one; a mimic joint's alike). Every <mimic> is written back unchanged; a machine
// coupled otherwise than the URDF is refused. The exported file's forward kinematics equals the
// machine's.
//
// Errors are InputError naming the URDF file (or the machine file), "line N" where the XML
// gives one, and what to check.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "artcal/io/urdf_origin_edit.hpp"
#include "artcal/model/chain.hpp"

namespace artcal {

/// The machine block ("model": "chain", "joints", "joint_limits", "calibrate": "identifiable")
/// of the chain from link `base` to link `tip` of the URDF file at `urdf_path`.
nlohmann::json importUrdf(const std::string& urdf_path, const std::string& base,
                          const std::string& tip);
/// The machine block of several tips sharing joints: each tip's path from `base` (docs/urdf.md,
/// "one machine, several tips"), the joints once each, "tips" naming each path (one tip: the
/// block above, without "tips").
nlohmann::json importUrdf(const std::string& urdf_path, const std::string& base,
                          const std::vector<std::string>& tips);

/// importUrdf() of one tip with a compliance block (`import-urdf --compliance`,
/// docs/compliance.md): its "masses" from the links' <inertial> (mass in kg, origin xyz in m to
/// mm; rpy does not move the centre), each link with the links rigidly attached to it off the
/// chain folded in (behind fixed joints; behind movable ones at their zero), by chain joint;
/// gravity (0, 0, -9.81).
nlohmann::json importUrdfWithCompliance(const std::string& urdf_path, const std::string& base,
                                        const std::vector<std::string>& tips);

/// `p` with the origins of `chain`'s joints as the URDF file at `urdf_path` states them (offsets
/// 0): the nominal machine a calibrated one is compared with (export-urdf's warnings,
/// calibration/corrections.hpp). Joints missing from the file keep their values from `p`.
Eigen::VectorXd urdfNominal(const Chain& chain, const Eigen::VectorXd& p,
                            const std::string& urdf_path);

/// The text of the URDF file at `urdf_path` with the origins of `chain`'s joints set from the
/// parameters `p` (internal units, offsets folded as above). `machine_source` names the machine
/// file in errors (a joint of the chain missing from the URDF, of another type, or an offset
/// with no joint below it to fold into).
/// `calibrated` (parameter indices; empty: every joint) limits the rewritten origins to the
/// joints with a calibrated parameter and those an offset is folded into: every other joint keeps
/// its text.
std::string exportUrdf(const Chain& chain, const Eigen::VectorXd& p, const std::string& urdf_path,
                       const std::string& machine_source, const std::vector<int>& calibrated = {});
/// The origins exportUrdf writes (xyz m, rpy rad): every chain joint's and those of off-chain
/// joints an offset is folded into, in that order.
std::vector<OriginEdit> calibratedOrigins(const Chain& chain, const Eigen::VectorXd& p,
                                          const std::string& urdf_path,
                                          const std::string& machine_source,
                                          const std::vector<int>& calibrated = {});

}  // namespace artcal
