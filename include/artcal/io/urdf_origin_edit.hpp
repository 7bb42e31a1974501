#pragma once
// export-urdf's edit of a URDF file in place (docs/exports.md): the calibrated joints' <origin
// xyz rpy> attribute values are replaced in the file's own text, byte for byte everything else
// as it was (indentation, comments, attribute order, number spellings of untouched values), so
// that a diff of input and output shows the calibrated joints' origins only.
//
// The scanner reads what tinyxml2 reads for these elements: the root's direct <joint> children
// by their name attribute (entities &lt; &gt; &amp; &quot; &apos; decoded), and each one's first
// direct <origin> child; comments, CDATA, processing instructions and the DOCTYPE are skipped.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace artcal {

/// A joint's new origin: xyz in metres, rpy in rad, as the URDF states them.
struct OriginEdit {
  std::string joint;
  Eigen::Vector3d xyz_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
};

/// The shortest text of a double that reads back to it ("0.333", "-1.5707963267948966").
std::string shortestNumber(double value);

/// `text` (the URDF file `source`) with each edit's joint origin set. An attribute whose three
/// numbers already equal the new ones to 1e-14 (m or rad) keeps its text; a missing attribute is
/// added after the origin's last one, a missing <origin> as the joint's first child on a line of
/// its own (absent means zeros, as URDF says: nothing is added for zeros). InputError naming
/// `source` when a joint is not found or an origin attribute is not three numbers.
std::string editJointOrigins(const std::string& text, const std::vector<OriginEdit>& edits,
                             const std::string& source);

}  // namespace artcal
