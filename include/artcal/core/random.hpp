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

/// A generator for stream `stream`, item `index` of `seed`: the same draws whichever thread
/// makes them (the planner's starts and candidates).
inline std::mt19937_64 seededGenerator(std::uint64_t seed, std::uint64_t stream,
                                       std::uint64_t index) {
  std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                         static_cast<std::uint32_t>(stream), static_cast<std::uint32_t>(index),
                         static_cast<std::uint32_t>(index >> 32)};
  return std::mt19937_64(sequence);
}

}  // namespace artcal
