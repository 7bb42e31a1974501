#pragma once
// What a machine's joint compliance implies over a plan's readings (docs/compliance.md section 5):
// for each compliance C_r, the largest torque, the largest deflection |C_r tau_r| (rad or mm
// inside) and the largest tip displacement it causes |(d t / d q_r) C_r tau_r| (mm), over the
// readings with their payloads. calibrate reports them beside each estimate and its u (a
// computation over the plan's readings beside readingTorques, in the plan layer).

#include <Eigen/Core>
#include <vector>

#include "artcal/plan/plan.hpp"

namespace artcal {

struct ComplianceDeflection {
  int parameter = 0;            ///< index into the model's parameters
  int joint = 0;                ///< the reading it deflects (from 0)
  bool revolute = true;         ///< deg/(N m) and N m, else mm/N and N
  double largest_torque = 0.0;  ///< N m or N
  double largest_joint = 0.0;   ///< rad or mm
  double largest_tip = 0.0;     ///< mm
};

/// One entry per compliance parameter of the machine (none without compliance), at parameters
/// `p`, over every reading of `placements`.
std::vector<ComplianceDeflection> complianceDeflections(const Machine& machine,
                                                        const std::vector<Placement>& placements,
                                                        const Eigen::VectorXd& p);

}  // namespace artcal
