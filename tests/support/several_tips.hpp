#pragma once
// Plans of chains imported from a URDF against its tree and with several tips (docs/urdf.md),
// built in the test: ball-bar placements near each tip's reach, each ball read by inverse
// kinematics from seeded starting postures, the readings naming their tip.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "artcal/io/plan_io.hpp"
#include "artcal/io/urdf.hpp"
#include "artcal/model/inverse_kinematics.hpp"
#include "artcal/plan/plan.hpp"
#include "test_paths.hpp"

namespace artcal::test_support {

inline std::string humanoidUrdf() {
  return testDataFile("urdf/humanoid-small.urdf");
}

struct TipPlanOptions {
  int placements_per_tip = 4;
  int postures = 3;                 ///< readings per ball
  double bar = 100.0;               ///< ball bar length, mm
  std::vector<int> tips_read = {};  ///< the tips that read (empty: all)
  bool shared_placements = false;   ///< every tip reads every placement (else one tip each)
  std::uint64_t seed = 7;
  Eigen::VectorXd truth =
      Eigen::VectorXd();  ///< the machine the readings are solved on (empty: nominal)
};

/// A plan for `machine` (a chain block from importUrdf, "calibrate" set by the caller): ball
/// bars near each reading tip's reach at a mid-range posture, each ball read in `postures`
/// postures (IK from seeded starts near that posture), the readings naming their tip.
inline Plan tipPlan(const nlohmann::json& machine, const TipPlanOptions& options = {}) {
  nlohmann::json document = {
      {"format", "artcal-plan/1"},
      {"name", "several-tips"},
      {"machine", machine},
      {"noise", {{"probe", 0.02}, {"encoder", 0.002}}},
      {"artifacts", {{"bar", {{"type", "ball_bar"}, {"length", options.bar}}}}},
      {"placements", nlohmann::json::array()},
      {"workspace", {{"samples", 64}, {"seed", 1}}}};
  const Plan bare = parsePlan(document, "several-tips", false);
  const Machine& m = bare.machine;
  const Mechanism& mech = *m.mechanism;
  const Eigen::VectorXd p = options.truth.size() ? options.truth : m.nominal;
  const std::vector<std::string> names = mech.stylusNames();
  Eigen::VectorXd middle(m.jointCount());
  for (int i = 0; i < middle.size(); ++i) {
    const auto [lo, hi] = m.joint_limits[static_cast<std::size_t>(i)];
    middle[i] = lo + 0.5 * (hi - lo);
  }
  std::vector<int> tips = options.tips_read;
  if (tips.empty())
    for (int t = 0; t < mech.stylusCount(); ++t) tips.push_back(t);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  nlohmann::json placements = nlohmann::json::array();
  const auto start = [&] {
    Eigen::VectorXd q = middle;
    for (int i = 0; i < q.size(); ++i) {
      const auto [lo, hi] = m.joint_limits[static_cast<std::size_t>(i)];
      q[i] += 0.15 * (hi - lo) * unit(rng);
    }
    applyJointLimits(m, q);
    return q;
  };
  const auto place = [&](const Eigen::Vector3d& center, const std::vector<int>& readers) {
    Eigen::Vector3d direction(normal(rng), normal(rng), normal(rng));
    direction.normalize();
    nlohmann::json measurements = nlohmann::json::array();
    for (int feature = 0; feature < 2; ++feature) {
      const Eigen::Vector3d ball = center + (feature == 0 ? -0.5 : 0.5) * options.bar * direction;
      for (const int t : readers) {
        int found = 0;
        for (int attempt = 0; attempt < 40 && found < options.postures; ++attempt) {
          IkOptions ik;
          ik.stylus = t;
          const auto q = solveInverseKinematics(m, p, ball, start(), ik);
          if (!q) continue;
          nlohmann::json joints = nlohmann::json::array();
          for (int i = 0; i < q->size(); ++i)
            joints.push_back(toFileUnit(jointQuantity(mech.jointKind(i)), (*q)[i]));
          nlohmann::json entry = {{"feature", feature}, {"joints", joints}};
          if (!names.empty()) entry["tip"] = names[static_cast<std::size_t>(t)];
          measurements.push_back(entry);
          ++found;
        }
      }
    }
    // A ball that no tip reached from the seeded starts leaves the bar without a pair: skipped.
    std::set<int> features_read;
    for (const nlohmann::json& entry : measurements) features_read.insert(entry["feature"].get<int>());
    if (features_read.size() == 2)
      placements.push_back({{"artifact", "bar"}, {"measurements", measurements}});
  };
  for (const int t : tips) {
    Eigen::VectorXd x;
    forwardOrThrow(mech, m.nominal, middle, x, nullptr, nullptr, t);
    for (int k = 0; k < options.placements_per_tip; ++k) {
      const Eigen::Vector3d center =
          x + 60.0 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
      place(center, options.shared_placements ? tips : std::vector<int>{t});
    }
  }
  document["placements"] = placements;
  return parsePlan(document, "several-tips");
}

}  // namespace artcal::test_support
