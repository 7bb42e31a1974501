// The blocked tip-variance kernel (estimation/tip_kernel.hpp): each build of it against a dense
// reference (the row norms of P L by Eigen) and against the other build, and the workspace's
// S_m^2 of a 6-axis arm (which takes the blocked form) against tr(J_p V_p J_p^T) configuration by
// configuration.

#include <gtest/gtest.h>

#include <cstdlib>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <random>

#include "artcal/artcal.hpp"
#include "artcal/estimation/tip.hpp"
#include "artcal/estimation/tip_kernel.hpp"
#include "plan_builders.hpp"

namespace artcal {
namespace tip_kernel_test {

struct Panels {
  int n = 0;
  int count = 0;
  std::vector<double> data;
  Eigen::MatrixXd rows;  ///< the same numbers as a (count * kTipPanelRows) x n matrix
};

Panels randomPanels(int n, int count, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Panels p{n, count, {}, Eigen::MatrixXd(count * kTipPanelRows, n)};
  p.data.resize(static_cast<std::size_t>(n) * kTipPanelRows * count);
  for (int q = 0; q < count; ++q) {
    for (int a = 0; a < n; ++a) {
      for (int i = 0; i < kTipPanelRows; ++i) {
        const double v = normal(rng) * std::pow(10.0, a % 4 - 2);  // columns of mixed scale
        p.data[static_cast<std::size_t>((q * n + a) * kTipPanelRows + i)] = v;
        p.rows(q * kTipPanelRows + i, a) = v;
      }
    }
  }
  return p;
}

Eigen::MatrixXd randomCovariance(int n, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n, n);
  for (double& v : A.reshaped()) v = normal(rng);
  return A * A.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
}

std::vector<double> run(TipKernel kernel, const Panels& p, const Eigen::MatrixXd& L, bool lower) {
  std::vector<double> squares(static_cast<std::size_t>(p.count) * kTipPanelRows, -1.0);
  tipKernelRowSquares(kernel, p.data.data(), p.count, p.n, L.data(), lower, squares.data());
  return squares;
}

void expectRelative(const std::vector<double>& a, const Eigen::VectorXd& b, double tolerance,
                    const char* what) {
  ASSERT_EQ(static_cast<Eigen::Index>(a.size()), b.size());
  for (Eigen::Index i = 0; i < b.size(); ++i) {
    EXPECT_NEAR(a[static_cast<std::size_t>(i)], b[i], tolerance * b[i]) << what << " row " << i;
  }
}

TEST(TipKernel, EachBuildMatchesTheDenseRowNormsAndTheOther) {
  std::mt19937_64 rng(5);
  for (const int n : {1, 3, 7, 21, 40}) {
    const Panels p = randomPanels(n, 3, rng);
    const Eigen::MatrixXd V = randomCovariance(n, rng);
    const Eigen::MatrixXd L = V.llt().matrixL();
    // A full (not triangular) root: the symmetric one.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(V);
    const Eigen::MatrixXd root = eig.eigenvectors() * eig.eigenvalues().cwiseSqrt().asDiagonal();
    const Eigen::VectorXd dense = (p.rows * V).cwiseProduct(p.rows).rowwise().sum();
    const std::vector<double> generic = run(TipKernel::Generic, p, L, true);
    expectRelative(generic, dense, 1e-12, "generic, lower");
    expectRelative(run(TipKernel::Generic, p, root, false), dense, 1e-12, "generic, full");
    const std::vector<double> active = run(activeTipKernel(), p, L, true);
    expectRelative(active, dense, 1e-12, "active, lower");
    // The dispatched kernel against the generic one: the same sums, rounded alike but for FMA.
    expectRelative(active, Eigen::Map<const Eigen::VectorXd>(generic.data(), generic.size()), 1e-13,
                   "active against generic");
    if (tipKernelAvailable(TipKernel::Avx2Fma)) {
      expectRelative(run(TipKernel::Avx2Fma, p, root, false), dense, 1e-12, "avx2, full");
    }
  }
}

TEST(TipKernel, ItsNameSaysWhichBuildRuns) {
  const TipKernel kernel = activeTipKernel();
  EXPECT_TRUE(tipKernelAvailable(kernel));
  EXPECT_TRUE(tipKernelName(kernel) == "generic" || tipKernelName(kernel) == "avx2-fma");
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
// The library reads CPUID itself at the first evaluation (no start-up cost); the compiler's own
// CPU model (libgcc, OS support of the YMM registers included) is the independent answer.
TEST(TipKernel, Avx2DetectionAgreesWithTheCompilersCpuModel) {
  __builtin_cpu_init();
  const bool compiler_says = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  EXPECT_EQ(tipKernelAvailable(TipKernel::Avx2Fma), compiler_says);
  if (std::getenv("ARTCAL_TIP_KERNEL") == nullptr) {
    EXPECT_EQ(activeTipKernel(), compiler_says ? TipKernel::Avx2Fma : TipKernel::Generic);
  }
}
#endif

// The 6-axis arm's 21 parameters over 1000 sampled configurations (16 per panel, the last one
// padded): S_m^2 against tr(J V J^T) of each configuration's own Jacobian (TipEvaluator::at).
TEST(TipKernel, WorkspaceVarianceOfASixAxisArmAgainstEachConfigurationsTrace) {
  const Plan plan = testing::aacmmPlan();
  WorkspaceSpec spec;
  spec.kind = WorkspaceSpec::Kind::Samples;
  spec.samples = 1000;
  spec.seed = 3;
  const TipEvaluator tip(plan.machine, plan.noise, workspaceConfigurations(plan.machine, spec));
  ASSERT_GT(tip.size(), 900);
  std::mt19937_64 rng(9);
  const Eigen::MatrixXd V = 1e-6 * randomCovariance(plan.machine.calibratedCount(), rng);
  Eigen::VectorXd S_m2;
  tip.kinematicVariance(V, S_m2);
  ASSERT_EQ(S_m2.size(), tip.size());
  for (int g = 0; g < tip.size(); ++g) {
    const double expected = tip.at(g, V).kinematic;
    EXPECT_NEAR(std::sqrt(S_m2[g]), expected, 1e-12 * expected) << g;
  }
}

}  // namespace tip_kernel_test
}  // namespace artcal
