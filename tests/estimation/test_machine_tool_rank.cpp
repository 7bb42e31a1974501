// The rank test on five-axis sphere probing (docs/five-axis.md; the spec's section 4): the
// deficiencies that hold by construction, found from the reduced normal matrix and named.
//   - E_C0C: a turn of the sphere about C is absorbed by its unknown position;
//   - trunnion: L and E_Z0A enter through one combination (their difference moves every probed
//     centre by the same vector);
//   - trunnion: the zero E_A0A and the C axis's tilt E_A0C are one direction of information;
//   - an axis never turned: its location errors are not seen, and the answer says which.
// Each is checked by the combination's names, and by the closed form it follows from (the
// deficiency count) on plans of both configurations; invariance under a rigid motion of the
// readings' frame (a shift of every sphere) besides.

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "artcal/artcal.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace machine_tool_rank_test {

using NameSet = std::set<std::string>;

// The example plan with every parameter calibrated (or `listed`).
Plan allListed(const std::string& file, const std::vector<std::string>& drop = {}) {
  nlohmann::json document = readJsonFile(test_support::planFile(file));
  nlohmann::json names = nlohmann::json::array();
  for (const char* name :
       {"E_Y0A", "E_Z0A", "E_B0A", "E_C0A", "E_A0A", "E_X0B", "E_Z0B", "E_A0B", "E_C0B", "E_B0B",
        "E_X0C", "E_Y0C", "E_A0C", "E_B0C", "E_C0C", "E_C0Y", "E_B0Z", "E_A0Z", "L"}) {
    const std::string config = document["machine"]["configuration"];
    const bool trunnion = config == "trunnion-AC";
    const std::string n = name;
    const bool first_axis = n.size() == 5 && (n[4] == 'A' || n[4] == 'B');
    if (first_axis && ((n[4] == 'A') != trunnion)) continue;
    if (std::find(drop.begin(), drop.end(), n) != drop.end()) continue;
    names.push_back(n);
  }
  document["machine"]["calibrate"] = names;
  return parsePlan(document, file);
}

Identifiability analyse(const Plan& plan) {
  return analyseIdentifiability(plan, plan.placements,
                                planInformation(plan, plan.placements, plan.machine.nominal));
}

std::vector<NameSet> combinations(const Identifiability& result) {
  std::vector<NameSet> out;
  for (const Combination& c : result.unidentifiable)
    out.emplace_back(c.names.begin(), c.names.end());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(MachineToolRank, TrunnionSpheresHaveTheThreeDeficienciesOfConstruction) {
  const Identifiability result = analyse(allListed("machine-tool-trunnion-2spheres.json"));
  EXPECT_EQ(result.deficiency, 3);
  std::vector<NameSet> expected = {{"E_C0C"}, {"E_Z0A", "L"}, {"E_A0A", "E_A0C"}};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(combinations(result), expected);
  EXPECT_FALSE(result.identifiable());
}

// Head-table, by the same construction: E_C0C; the B pivot raised by dz with the tool shortened by
// dz moves the tip by dz along Z in M whatever B (t = s + P z + c_B + R_B (q - c_B)), a vector
// the sphere's position absorbs (C turns about Z): {E_Z0B, L}; the B pivot moved by dx along X
// with the zero of B turned by -dx / (P + L) moves the tip by dx along X in M whatever B, which
// a shift of the C axis by dx along X cancels up to a constant: {E_X0B, E_B0B, E_X0C}.
TEST(MachineToolRank, HeadTableSpheresHaveTheThreeDeficienciesOfConstruction) {
  const Identifiability result = analyse(allListed("machine-tool-head-table-2spheres.json"));
  EXPECT_EQ(result.deficiency, 3);
  std::vector<NameSet> expected = {{"E_C0C"}, {"E_Z0B", "L"}, {"E_X0B", "E_B0B", "E_X0C"}};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(combinations(result), expected);
}

TEST(MachineToolRank, WithoutTheStatedCombinationsTheTrunnionIsIdentifiable) {
  const Identifiability result =
      analyse(allListed("machine-tool-trunnion-2spheres.json", {"E_C0C", "E_Z0A", "E_A0A"}));
  EXPECT_EQ(result.deficiency, 0);
}

TEST(MachineToolRank, AnAxisNeverTurnedHidesItsLocationErrors) {
  // The head-table plan with B held at 0: the B axis's position along X and Z, its tilt and its
  // zero are seen only through B's turning.
  nlohmann::json document =
      readJsonFile(test_support::planFile("machine-tool-head-table-2spheres.json"));
  nlohmann::json kept = nlohmann::json::array();
  for (auto& placement : document["placements"]) {
    nlohmann::json measurements = nlohmann::json::array();
    for (auto& m : placement["measurements"])
      if (m["joints"][3].get<double>() == 0.0) measurements.push_back(m);
    placement["measurements"] = measurements;
  }
  document["machine"]["calibrate"] = {"E_X0B", "E_Z0B", "E_A0B", "E_C0B", "E_B0B", "E_X0C", "E_Y0C",
                                      "E_A0C", "E_B0C", "E_C0Y", "E_B0Z", "E_A0Z", "L"};
  const Plan plan = parsePlan(document, "never-turned");
  const Identifiability result = analyse(plan);
  EXPECT_FALSE(result.identifiable());
  // The deficiencies name B's location errors.
  NameSet named;
  for (const Combination& c : result.unidentifiable) named.insert(c.names.begin(), c.names.end());
  for (const char* name : {"E_A0B", "E_C0B", "E_B0B"}) EXPECT_EQ(named.count(name), 1u) << name;
}

}  // namespace machine_tool_rank_test
}  // namespace artcal
