#include "artcal/planning/design_identifiability.hpp"

#include <algorithm>
#include <random>

#include "artcal/estimation/identifiability.hpp"
#include "artcal/planning/design_space.hpp"
#include "artcal/planning/instrument_design.hpp"

namespace artcal {

namespace {

// Enough random placements that the union's equations are at least twice the listed
// parameters, never fewer than 40 (generic poses: the union reaches the space's largest rank).
int candidateCount(const Plan& spec) {
  const DesignSpec& design = *spec.design;
  const Artifact& artifact = spec.artifacts[static_cast<std::size_t>(design.artifact)];
  const int per_placement =
      artifact.featureCount() * design.postures * artifact.valuedPerFeature() - artifact.rigidDof();
  const int listed = spec.machine.calibratedCount();
  const int needed = per_placement > 0 ? (2 * listed + per_placement - 1) / per_placement : 0;
  return std::clamp(needed, 40, 400);
}

// An instrument design: one station of up to 400 candidate configurations (every station sees
// the same parameters: its rigid motion absorbs the same base frame, wherever it stands).
std::optional<DesignIdentifiability> identifiableByInstrumentCandidates(const Plan& spec) {
  const std::vector<Eigen::VectorXd> candidates = instrumentCandidates(spec);
  std::vector<Placement> designed(1);
  designed[0].artifact = spec.design->artifact;
  for (std::size_t c = 0; c < std::min<std::size_t>(candidates.size(), 400); ++c) {
    Measurement m;
    m.joints = candidates[c];
    designed[0].measurements.push_back(std::move(m));
  }
  Plan plan = spec;
  plan.placements.clear();
  appendDesignedPlacements(plan, designed);
  DesignIdentifiability result;
  result.candidates = static_cast<int>(designed[0].measurements.size());
  std::vector<Placement> placements = spec.placements;
  placements.push_back(plan.placements.back());
  plan.placements = spec.placements;
  result.resolution = resolveListedSet(plan, placements);
  return result;
}

}  // namespace

std::optional<DesignIdentifiability> identifiableByDesigns(const Plan& spec, std::uint64_t seed) {
  if (spec.design->instrument) return identifiableByInstrumentCandidates(spec);
  const DesignSpace space(spec);
  // A stream of its own (not the optimizer's pool): the same spec and seed, the same answer.
  std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                         0x1dU};
  std::mt19937_64 rng(sequence);
  DesignIdentifiability result;
  std::vector<Placement> placements = spec.placements;
  const int count = candidateCount(spec);
  for (int i = 0; i < count; ++i) {
    if (auto drawn = space.randomPlacement(rng, 400))
      placements.push_back(std::move(drawn->second));
  }
  result.candidates = static_cast<int>(placements.size() - spec.placements.size());
  if (result.candidates == 0) return std::nullopt;
  result.resolution = resolveListedSet(spec, placements);
  return result;
}

}  // namespace artcal
