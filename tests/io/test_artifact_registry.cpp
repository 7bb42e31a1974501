// The artifact registry (io/artifact_registry.hpp): every kind is reached through its codec, and
// each kind answers what it does (artifact/artifact_kind.hpp) as the method says it should.
#include <gtest/gtest.h>

#include <algorithm>

#include <nlohmann/json.hpp>

#include "artcal/core/error.hpp"
#include "artcal/io/artifact_registry.hpp"
#include "artcal/io/plan_io.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace artifact_registry_test {

/// An entry of each registered type, with what docs/method.md section 1 and the kinds' docs give
/// for it on a 3-D machine: valued coordinates per feature k and the rigid motions N(r) a
/// placement estimates.
struct Expected {
  nlohmann::json entry;
  std::string type_name;
  int valued;
  int rigid_dof;
};

std::vector<Expected> oneOfEach() {
  return {
      {{{"type", "ball_bar"}, {"length", 300.0}}, "ball_bar", 3, 5},
      {{{"type", "ball_bar"}, {"length", 300.0}, {"ends", "table-spindle"}},
       "ball_bar (table-spindle)",
       1,
       3},
      {{{"type", "ball_plate"}, {"centers", {{0, 0, 0}, {100, 0, 0}, {0, 100, 0}}}},
       "ball_plate",
       3,
       6},
      {{{"type", "step_gauge"}, {"positions", {0, 20, 40}}}, "step_gauge", 1, 3},
      {{{"type", "instrument"}, {"noise", 0.01}}, "instrument", 3, 6},
      {{{"type", "plane"}}, "plane", 1, 3},
      {{{"type", "plane"}, {"shape", "cube_corner"}, {"length", 50.0}}, "plane", 1, 6},
      {{{"type", "sphere"}}, "sphere", 3, 3},
  };
}

const Machine& machine3d() {
  static const Plan plan = loadPlan(test_support::planFile("machine-tool-trunnion-2spheres.json"));
  return plan.machine;
}

TEST(ArtifactRegistry, EveryKindReadsThroughItsCodecAndAnswersAsTheMethodSays) {
  std::vector<std::string> seen;
  for (const Expected& expected : oneOfEach()) {
    std::vector<std::string> warnings;
    const Node entry(expected.entry, "/artifacts/a", "registry-test");
    const Artifact artifact = readArtifact("a", entry, machine3d(), warnings);
    EXPECT_EQ(artifactTypeName(artifact), expected.type_name);
    EXPECT_EQ(artifact.valuedPerFeature(), expected.valued) << expected.type_name;
    EXPECT_EQ(artifact.rigidDof(), expected.rigid_dof) << expected.type_name;
    EXPECT_TRUE(warnings.empty()) << expected.type_name;
    seen.push_back(expected.entry["type"].get<std::string>());
  }
  // Every registered codec was tried above: a kind added without a row here fails.
  for (const ArtifactCodec& codec : artifactCodecs())
    EXPECT_NE(std::find(seen.begin(), seen.end(), codec.type), seen.end()) << codec.type;
}

TEST(ArtifactRegistry, AnUnknownTypeNamesEveryRegisteredOne) {
  std::vector<std::string> warnings;
  const nlohmann::json document = {{"type", "ring_gauge"}};
  try {
    readArtifact("a", Node(document, "/artifacts/a", "registry-test"), machine3d(), warnings);
    FAIL() << "a ring gauge was read";
  } catch (const InputError& error) {
    const std::string message = error.describe();
    EXPECT_NE(message.find("/artifacts/a/type"), std::string::npos) << message;
    for (const ArtifactCodec& codec : artifactCodecs())
      EXPECT_NE(message.find(codec.type), std::string::npos) << message;
  }
}

}  // namespace artifact_registry_test
}  // namespace artcal
