// Cartesian CMM plans (models.md section 4): the independent reference case
// tests/data/ref-cartesian-plate matched, and what the example plans in plans/cmm-*.json can
// identify.

#include <gtest/gtest.h>

#include <fstream>

#include "artcal/artcal.hpp"
#include "artcal/model/cartesian.hpp"

namespace artcal {
namespace {

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

std::vector<std::string> names(const nlohmann::json& list) {
  std::vector<std::string> out;
  for (const auto& name : list) out.push_back(name.get<std::string>());
  return out;
}

// The reference gives rotations' u in um/m and translations' in mm; artcal keeps rad and mm.
double referenceInternal(const std::string& name, double value) {
  const bool rotation = name.find(".r") != std::string::npos;
  return rotation ? value * 1e-6 : value;
}

TEST(CartesianReference, PlateInThreePlanesWithTwoStyliAndDiagonals) {
  const std::string base = std::string(ARTCAL_TEST_DATA) + "/ref-cartesian-plate";
  const Plan plan = loadPlan(base + ".json");
  const nlohmann::json expected = readJson(base + ".expected.json");
  const Evaluation ev = evaluatePlan(plan);
  const nlohmann::json got = evaluationToJson(plan, ev);
  EXPECT_EQ(got["identifiable"], expected["identifiable"]);
  EXPECT_EQ(got["rank"]["deficiency"], expected["rank"]["deficiency"]);
  for (const char* key : {"N_p", "N_b", "N_r", "satisfied"}) {
    EXPECT_EQ(got["counting"][key], expected["counting"][key]) << key;
  }
  EXPECT_EQ(names(got["calibrate_resolved"]), names(expected["calibrate_resolved"]));
  EXPECT_EQ(names(got["calibrate_dropped"]), names(expected["calibrate_dropped"]));
  ASSERT_TRUE(ev.covariance);
  const auto& reference = expected["parameters"];
  ASSERT_EQ(plan.machine.calibratedCount(), static_cast<int>(reference.size()));
  for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
    const std::string name = reference[static_cast<std::size_t>(k)]["name"];
    EXPECT_EQ(plan.machine.calibratedInfo(k).name, name);
    const double u = referenceInternal(name, reference[static_cast<std::size_t>(k)]["u"]);
    EXPECT_NEAR(ev.covariance->u[k], u, 1e-6 * u) << name;
  }
  ASSERT_TRUE(ev.tip);
  const auto& worst = expected["tip"]["worst"];
  EXPECT_NEAR(got["tip"]["worst"]["total"].get<double>(), worst["total"].get<double>(),
              1e-6 * worst["total"].get<double>());
  EXPECT_NEAR(got["tip"]["worst"]["kinematic"].get<double>(), worst["kinematic"].get<double>(),
              1e-6 * worst["kinematic"].get<double>());
  EXPECT_NEAR(got["tip"]["worst"]["encoder"].get<double>(), worst["encoder"].get<double>(),
              1e-6 * worst["encoder"].get<double>());
  EXPECT_NEAR(got["tip"]["mean"].get<double>(), expected["tip"]["mean"].get<double>(),
              1e-6 * expected["tip"]["mean"].get<double>());
}

}  // namespace
}  // namespace artcal
