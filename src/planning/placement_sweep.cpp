#include "artcal/planning/placement_sweep.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include "artcal/core/error.hpp"
#include "artcal/planning/instrument_design.hpp"

namespace artcal {

namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();

/// The spec asking for `count` placements of the design's artifact besides `fixed` ones (an
/// instrument design: `count` readings per station).
Plan specFor(const Plan& spec, int count, const std::vector<Placement>& fixed) {
  Plan out = spec;
  if (out.design->instrument) {
    out.design->instrument->readings = count;
  } else {
    out.design->placements = count;
  }
  out.placements.insert(out.placements.end(), fixed.begin(), fixed.end());
  return out;
}

/// One search; the designed placements and the criterion (mm) of the whole design, or none.
struct Found {
  std::vector<Placement> designed;
  double value = kNone;
  std::string message;
  bool from_start_design = false;  ///< an instrument design's start 0 (the m - 1 design) won
};

Found search(const Plan& spec, const OptimizerOptions& options,
             const std::vector<Placement>* instrument_start = nullptr) {
  Found found;
  try {
    checkDesignCount(spec);
  } catch (const InputError& e) {
    found.message = e.what();
    return found;
  }
  const OptimizerSummary summary = spec.design->instrument
                                       ? optimizeInstrumentDesign(spec, options, instrument_start)
                                       : optimizePlan(spec, options);
  found.from_start_design = instrument_start && summary.best_start == 0;
  if (summary.best_start < 0 || !std::isfinite(summary.value)) {
    found.message = summary.message;
    return found;
  }
  found.designed = summary.placements;
  found.value = summary.value;
  return found;
}

}  // namespace

std::optional<std::pair<int, int>> parseCountRange(const std::string& text) {
  const auto separator = text.find("..");
  try {
    std::size_t used = 0;
    const std::string a = text.substr(0, separator);
    const int first = std::stoi(a, &used);
    if (used != a.size()) return std::nullopt;
    int last = first;
    if (separator != std::string::npos) {
      const std::string b = text.substr(separator + 2);
      last = std::stoi(b, &used);
      if (used != b.size()) return std::nullopt;
    }
    if (first < 1 || last < first || last > 1000) return std::nullopt;
    return std::make_pair(first, last);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

PlacementSweep sweepPlacements(const Plan& spec, const SweepOptions& options) {
  PlacementSweep sweep;
  const SweepPoint* previous = nullptr;
  for (int m = options.first; m <= options.last; ++m) {
    const auto start = std::chrono::steady_clock::now();
    SweepPoint point;
    point.placements = m;
    // An instrument design: one search whose start 0 is the design for m - 1 completed by one
    // reading per station (never worse), the other starts fresh.
    const bool seeded = spec.design->instrument && previous && !previous->designed.empty();
    const Found fresh =
        search(specFor(spec, m, {}), options.optimizer, seeded ? &previous->designed : nullptr);
    point.fresh = fresh.value;
    point.designed = fresh.designed;
    point.value = fresh.value;
    point.message = fresh.message;
    point.extended = fresh.from_start_design;
    if (!spec.design->instrument && previous && !previous->designed.empty()) {
      // The design for m - 1 kept, one placement added (docs/method.md section 3: never worse).
      const Found extension = search(specFor(spec, 1, previous->designed), options.optimizer);
      if (extension.value < point.value) {
        point.designed = previous->designed;
        point.designed.insert(point.designed.end(), extension.designed.begin(),
                              extension.designed.end());
        point.value = extension.value;
        point.extended = true;
        point.message.clear();
      }
    }
    point.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (options.progress) options.progress(m, point.value);
    sweep.points.push_back(std::move(point));
    previous = &sweep.points.back();
    if (options.target && !sweep.first_reaching && previous->value <= *options.target) {
      sweep.first_reaching = sweep.points.size() - 1;
    }
  }
  return sweep;
}

}  // namespace artcal
