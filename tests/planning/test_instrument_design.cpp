// Planning an instrument session (planning/instrument_design.hpp, instruments.md): the 6-axis
// arm of the tracker reference case, 12 readings chosen from 300 candidates. Checked without the
// optimizer's own arithmetic: the chosen plan's G recomputed by the plan reader and evaluate of
// the written plan; the D value against a dense inverse of the full (p, r) normal matrix built
// from the model's Jacobians; the G choice beats the D choice in G and the D choice beats the G
// choice in log det; the sweep over readings is monotone; bad specs are refused with a pointer.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "artcal/estimation/evaluator.hpp"
#include "artcal/estimation/tip.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/planning/instrument_design.hpp"
#include "artcal/planning/optimizer.hpp"
#include "artcal/planning/placement_sweep.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace instrument_design_test {

nlohmann::json specDocument(const std::string& criterion = "worst-tip", int readings = 12) {
  std::ifstream in(test_support::testDataFile("ref-instrument-arm6-2stations.json"));
  nlohmann::json document = nlohmann::json::parse(in);
  document["placements"] = nlohmann::json::array();
  document.erase("predicted");
  document["workspace"] = {{"samples", 256}, {"seed", 3}};
  document["design"] = {{"artifact", "tracker"},
                        {"stations", 1},
                        {"readings", readings},
                        {"candidates", {{"samples", 300}, {"seed", 1}}},
                        {"criterion", criterion},
                        {"starts", 2},
                        {"seed", 1}};
  return document;
}

Plan spec(const std::string& criterion = "worst-tip", int readings = 12) {
  return parsePlan(specDocument(criterion, readings), "design.json", false);
}

OptimizerSummary optimize(const Plan& plan) {
  OptimizerOptions options = OptimizerOptions::fromDesign(*plan.design);
  options.threads = 1;
  return optimizePlan(plan, options);
}

/// The plan the command writes, read back by the plan reader (points left out: planning only).
Plan writtenPlan(const nlohmann::json& spec_document, const Plan& spec_plan,
                 const OptimizerSummary& summary) {
  Plan designed = spec_plan;
  appendDesignedPlacements(designed, summary.placements);
  nlohmann::json document = spec_document;
  document["placements"] = placementsToJson(designed);
  return parsePlan(document, "written.json");
}

std::string refusal(const nlohmann::json& document) {
  try {
    parsePlan(document, "design.json", false);
  } catch (const InputError& e) {
    return e.describe();
  }
  return "";
}

/// log det V_p from a dense inverse of the whole normal matrix over (p, r): whitened rows
/// [J_p | I, -[x]x] of every reading (the station at the machine frame), then the p block of
/// its inverse. Independent of the evaluator's Schur complement and rank policy.
double denseLogDetV(const Plan& plan) {
  const Machine& machine = plan.machine;
  const int n_p = machine.calibratedCount();
  const Placement& station = plan.placements.back();
  const int rows = 3 * static_cast<int>(station.measurements.size());
  Eigen::MatrixXd A(rows, n_p + 6);
  Eigen::VectorXd x;
  Eigen::MatrixXd J_p, J_q;
  const double s2 = plan.noise.probe * plan.noise.probe +
                    plan.artifacts[static_cast<std::size_t>(station.artifact)].noise *
                        plan.artifacts[static_cast<std::size_t>(station.artifact)].noise;
  for (std::size_t i = 0; i < station.measurements.size(); ++i) {
    const Measurement& m = station.measurements[i];
    if (machine.mechanism->forward(machine.nominal, m.joints, x, &J_p, &J_q) != ForwardStatus::Ok) {
      ADD_FAILURE() << "forward kinematics failed";
      return NAN;
    }
    Eigen::MatrixXd row(3, n_p + 6);
    for (int k = 0; k < n_p; ++k)
      row.col(k) = J_p.col(machine.calibrated[static_cast<std::size_t>(k)]);
    row.block(0, n_p, 3, 3).setIdentity();
    row.block(0, n_p + 3, 3, 3) << 0, x[2], -x[1], -x[2], 0, x[0], x[1], -x[0], 0;
    Eigen::Matrix3d sigma =
        J_q * plan.noise.encoder.array().square().matrix().asDiagonal() * J_q.transpose();
    sigma.diagonal().array() += s2;
    const Eigen::Matrix3d L = sigma.llt().matrixL();
    A.middleRows(3 * static_cast<int>(i), 3) = L.triangularView<Eigen::Lower>().solve(row);
  }
  const Eigen::MatrixXd V = (A.transpose() * A).inverse().topLeftCorner(n_p, n_p);
  return std::log(V.determinant());
}

TEST(InstrumentDesign, TheChosenPlansWorstTipIsWhatEvaluateOfTheWrittenPlanGives) {
  const nlohmann::json document = specDocument();
  const Plan plan = parsePlan(document, "design.json", false);
  const OptimizerSummary summary = optimize(plan);
  ASSERT_GE(summary.best_start, 0) << summary.message;
  ASSERT_EQ(summary.placements.size(), 1u);
  EXPECT_EQ(summary.placements[0].measurements.size(), 12u);
  EXPECT_EQ(summary.pool_size, 300);
  const Evaluation evaluation = evaluatePlan(writtenPlan(document, plan, summary));
  ASSERT_TRUE(evaluation.identifiable());
  EXPECT_NEAR(evaluation.tip->worst.total, summary.value, 1e-9 * summary.value);
  // Every chosen configuration is a candidate (within the limits narrowed by the margin).
  const std::vector<Eigen::VectorXd> candidates = instrumentCandidates(plan);
  for (const Measurement& m : summary.placements[0].measurements) {
    EXPECT_TRUE(std::any_of(candidates.begin(), candidates.end(),
                            [&](const Eigen::VectorXd& q) { return q == m.joints; }));
  }
  // The exchange never loses against its random start.
  for (const StartResult& s : summary.starts) EXPECT_LE(s.exchanged, s.initial);
}

TEST(InstrumentDesign, GChoiceBeatsDChoiceInGAndDChoiceBeatsGChoiceInLogDet) {
  const nlohmann::json g_document = specDocument("worst-tip");
  const nlohmann::json d_document = specDocument("D");
  const Plan g_spec = parsePlan(g_document, "design.json", false);
  const Plan d_spec = parsePlan(d_document, "design.json", false);
  const OptimizerSummary g_choice = optimize(g_spec);
  const OptimizerSummary d_choice = optimize(d_spec);
  ASSERT_GE(g_choice.best_start, 0);
  ASSERT_GE(d_choice.best_start, 0);
  const Plan g_plan = writtenPlan(g_document, g_spec, g_choice);
  const Plan d_plan = writtenPlan(d_document, d_spec, d_choice);
  const Evaluation g_eval = evaluatePlan(g_plan);
  const Evaluation d_eval = evaluatePlan(d_plan);
  ASSERT_TRUE(g_eval.identifiable() && d_eval.identifiable());
  EXPECT_LE(g_eval.tip->worst.total, d_eval.tip->worst.total * (1.0 + 1e-12));
  const double g_logdet = denseLogDetV(g_plan), d_logdet = denseLogDetV(d_plan);
  EXPECT_LE(d_logdet, g_logdet + 1e-9 * std::abs(g_logdet));
  // The evaluator's V_p of the D choice against the dense inverse.
  EXPECT_NEAR(std::log(d_eval.covariance->V.determinant()), d_logdet, 1e-6 * std::abs(d_logdet));
  // The D value: det(V_s)^(1/(2 N_p)), V_s with angles scaled by the reach (optimizer.hpp).
  const Machine& machine = d_plan.machine;
  double reach = 0.0;
  Eigen::VectorXd x;
  for (const Eigen::VectorXd& q : workspaceConfigurations(machine, d_plan.workspace)) {
    forwardOrThrow(*machine.mechanism, machine.nominal, q, x);
    reach = std::max(reach, x.norm());
  }
  double log_det_scaled = d_logdet;
  for (int k = 0; k < machine.calibratedCount(); ++k)
    if (machine.calibratedInfo(k).quantity.isAngle()) log_det_scaled += 2.0 * std::log(reach);
  const double n = machine.calibratedCount();
  EXPECT_NEAR(d_choice.value, std::exp(log_det_scaled / (2.0 * n)), 1e-6 * d_choice.value);
}

TEST(InstrumentDesign, TheSweepOverReadingsIsMonotoneAndEachPlanHasItsCount) {
  const Plan plan = spec("worst-tip", 10);
  SweepOptions options;
  options.first = 9;
  options.last = 11;
  options.optimizer = OptimizerOptions::fromDesign(*plan.design);
  options.optimizer.threads = 1;
  const PlacementSweep sweep = sweepPlacements(plan, options);
  ASSERT_EQ(sweep.points.size(), 3u);
  for (std::size_t i = 0; i < sweep.points.size(); ++i) {
    const SweepPoint& point = sweep.points[i];
    ASSERT_EQ(point.designed.size(), 1u) << point.message;
    EXPECT_EQ(static_cast<int>(point.designed[0].measurements.size()), point.placements);
    Plan designed = plan;
    designed.design->instrument->readings = point.placements;
    appendDesignedPlacements(designed, point.designed);
    EXPECT_NEAR(evaluatePlan(designed).tip->worst.total, point.value, 1e-9 * point.value);
    if (i > 0) {
      EXPECT_LE(point.value, sweep.points[i - 1].value);
    }
  }
}

TEST(InstrumentDesign, TooFewReadingsForTheCountingConditionAreRefused) {
  const Plan plan = spec("worst-tip", 8);  // 8 x 3 - 6 = 18 equations for 21 parameters
  try {
    optimize(plan);
    FAIL() << "expected a refusal";
  } catch (const InputError& e) {
    EXPECT_NE(e.describe().find("/design/readings"), std::string::npos) << e.describe();
  }
}

TEST(InstrumentDesign, BadInstrumentDesignsAreRefusedWithTheirPointer) {
  nlohmann::json document = specDocument();
  document["design"]["placements"] = 2;
  EXPECT_NE(refusal(document).find("/design/placements"), std::string::npos) << refusal(document);
  document = specDocument();
  document["design"]["readings"] = 2;
  EXPECT_NE(refusal(document).find("/design/readings"), std::string::npos) << refusal(document);
  document = specDocument();
  document["design"]["candidates"]["samples"] = "many";
  EXPECT_NE(refusal(document).find("/design/candidates/samples"), std::string::npos)
      << refusal(document);
}

}  // namespace instrument_design_test
}  // namespace artcal
