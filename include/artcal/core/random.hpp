#pragma once
// Seeded random draws that give the same numbers on every platform and standard library:
// std::uniform_real_distribution and std::normal_distribution are implementation-defined, so
// workspaces, start designs and simulated readings draw their uniforms here.

#include <cstdint>
#include <random>

namespace artcal {

/// Uniform in [0, 1) from the top 53 bits of one draw of `rng`.
inline double unitUniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

/// Uniform in (0, 1] from the top 53 bits of one draw: never zero (a logarithm of it is finite).
inline double unitUniformNonZero(std::mt19937_64& rng) {
  return (static_cast<double>(rng() >> 11) + 1.0) * 0x1.0p-53;
}

}  // namespace artcal
