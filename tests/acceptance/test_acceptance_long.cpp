// The long Monte-Carlo run of the ISO 10360-2 prediction (spec acceptance.md): 10^6 trials with a
// fixed seed (about 5 s of CPU, hence a test binary of its own, labelled `stress` in
// tests/CMakeLists.txt) against the adaptive run of another seed and against the shared
// reference case's own 10^6-trial P(pass), each within 3 combined standard errors.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "artcal/acceptance/length_acceptance.hpp"
#include "artcal/internal.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace acceptance_long_test {

TEST(LengthTestLongRun, MillionTrialsAgreeWithTheAdaptiveRunAndTheReference) {
  const Plan plan = loadPlan(test_support::testDataFile("ref-acceptance-cmm-3planes.json"));
  AcceptanceInput input = *acceptanceInputFromPlan(plan, evaluatePlan(plan));
  LengthTestOptions options;
  options.mpe = *parseMpe("2.3 + L/2600");
  const LengthTestPrediction linear = predictLengthTestLinear(input, options);
  const LinearGaussianTest model = lengthTestModel(linear, input);
  MonteCarloOptions long_run;
  long_run.trials = 1000000;
  long_run.seed = 1;
  const MonteCarloSummary reference_run = runMonteCarlo(model, long_run);
  MonteCarloOptions adaptive;
  adaptive.seed = 2;
  const MonteCarloSummary run = runMonteCarlo(model, adaptive);
  EXPECT_TRUE(run.stable);
  EXPECT_NEAR(run.p_pass, reference_run.p_pass,
              3.0 * std::hypot(run.p_pass_standard_error, reference_run.p_pass_standard_error));
  std::ifstream in(test_support::testDataFile("ref-acceptance-cmm-3planes.expected.json"));
  const nlohmann::json expected = nlohmann::json::parse(in);
  EXPECT_NEAR(
      reference_run.p_pass, expected["p_pass"].get<double>(),
      3.0 * std::hypot(reference_run.p_pass_standard_error, expected["p_pass_se"].get<double>()));
}

}  // namespace acceptance_long_test
}  // namespace artcal
