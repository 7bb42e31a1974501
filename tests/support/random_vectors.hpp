#pragma once
// Reproducible random vectors for tests (std::mt19937_64: the same numbers on every platform).

#include <Eigen/Core>
#include <cstdint>
#include <random>

namespace artcal::test_support {

/// `size` numbers uniform in [-range, range] from the generator seeded with `seed`.
inline Eigen::VectorXd randomVector(int size, std::uint64_t seed, double range) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-range, range);
  Eigen::VectorXd v(size);
  for (int i = 0; i < size; ++i) v[i] = uniform(rng);
  return v;
}

}  // namespace artcal::test_support
