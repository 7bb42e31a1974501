#include "artcal/plan/compliance_deflections.hpp"

#include <algorithm>
#include <cmath>

namespace artcal {

std::vector<ComplianceDeflection> complianceDeflections(const Machine& machine,
                                                        const std::vector<Placement>& placements,
                                                        const Eigen::VectorXd& p) {
  const Mechanism& mech = *machine.mechanism;
  const JointCompliance* compliance = mech.jointCompliance();
  std::vector<ComplianceDeflection> out;
  if (!compliance) return out;
  const std::vector<int>& index = compliance->complianceParameters();
  for (int r = 0; r < mech.jointCount(); ++r)
    out.push_back({index[static_cast<std::size_t>(r)], r, mech.jointKind(r) == JointKind::Revolute,
                   0.0, 0.0, 0.0});
  Eigen::VectorXd x;
  Eigen::MatrixXd J_x_q;
  for (const Placement& placement : placements) {
    for (const Measurement& m : placement.measurements) {
      const Eigen::VectorXd tau = readingTorques(machine, m);
      if (forwardReading(machine, p, m, x, nullptr, &J_x_q) != ForwardStatus::Ok) continue;
      for (ComplianceDeflection& d : out) {
        const double deflection = std::abs(p[d.parameter] * tau[d.joint]);
        d.largest_torque = std::max(d.largest_torque, std::abs(tau[d.joint]));
        d.largest_joint = std::max(d.largest_joint, deflection);
        d.largest_tip = std::max(d.largest_tip, J_x_q.col(d.joint).norm() * deflection);
      }
    }
  }
  return out;
}

}  // namespace artcal
