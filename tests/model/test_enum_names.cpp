// The enum name tables (core/enum_names.hpp): every value has one name, every name reads back to
// its value, an unknown name is no value; and the names are the ones files and messages use.

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "artcal/artifact/artifact.hpp"
#include "artcal/calibration/calibrator.hpp"
#include "artcal/core/enum_names.hpp"
#include "artcal/model/axis_error_functions.hpp"
#include "artcal/model/chain.hpp"
#include "artcal/model/mechanism.hpp"
#include "artcal/model/serial_dh.hpp"
#include "artcal/plan/plan.hpp"
#include "artcal/planning/optimizer.hpp"

namespace artcal {
namespace enum_names_test {

template <class Enum, std::size_t N>
void expectRoundTrip(const EnumNames<Enum, N>& table) {
  std::set<std::string> names;
  for (const auto& [value, name] : table) {
    EXPECT_EQ(nameOf(table, value), name);
    EXPECT_EQ(fromName(table, name), value) << name;
    names.insert(std::string(name));
  }
  EXPECT_EQ(names.size(), N);  // no two values share a name
  EXPECT_EQ(fromName(table, "no such name"), std::nullopt);
  EXPECT_EQ(fromName(table, ""), std::nullopt);
}

TEST(EnumNames, EveryTableReadsBackAndNamesAreUnique) {
  expectRoundTrip(kCriterionNames);
  expectRoundTrip(kRefineAlgorithmNames);
  expectRoundTrip(kForwardStatusNames);
  expectRoundTrip(kTerminationNames);
  expectRoundTrip(kChainJointTypeNames);
  expectRoundTrip(kAxisErrorNames);
  expectRoundTrip(kDHConventionNames);
}

TEST(EnumNames, TheNamesFilesAndMessagesUse) {
  EXPECT_EQ(criterionName(Criterion::WorstTip), "worst-tip");
  EXPECT_EQ(criterionName(Criterion::Pass), "pass");
  EXPECT_EQ(criterionFromName("mean-tip"), Criterion::MeanTip);
  EXPECT_EQ(criterionFromName("worst_tip"), std::nullopt);
  EXPECT_EQ(refineAlgorithmName(RefineAlgorithm::Subplex), "sbplx");
  EXPECT_EQ(refineAlgorithmFromName("neldermead"), RefineAlgorithm::NelderMead);
  EXPECT_EQ(forwardStatusName(ForwardStatus::Singular), "singular configuration");
  EXPECT_EQ(terminationName(TerminationType::NoConvergence), "no_convergence");
  EXPECT_EQ(fromName(kChainJointTypeNames, "prismatic"), ChainJointType::Prismatic);
  EXPECT_EQ(nameOf(kChainJointTypeNames, ChainJointType::Fixed), "fixed");
  EXPECT_EQ(axisErrorName(AxisError::Ry), "ry");
}

// Every value of each enum has its name (a value added without one would be caught here, not
// by a std::logic_error at run time): the tables are as long as the enums.
TEST(EnumNames, EveryValueOfTheNewTablesIsNamed) {
  for (int e = 0; e < kAxisErrorCount; ++e)
    EXPECT_EQ(axisErrorName(static_cast<AxisError>(e)).size(), 2u);
}

}  // namespace enum_names_test
}  // namespace artcal
