#pragma once
// The proof of a pool choice (issue 45, `artcal compare-designs`, docs/optimize.md "Does the
// choice win on a real machine?"): from recorded readings and held-out readings of the same
// machine, subsets of N recorded readings are chosen by each criterion (reading_pool.hpp), by
// random draws and by the spread heuristic (farthest points in joint space); each subset is
// calibrated alone (calibrateReadings, as `artcal calibrate` of those readings) and scored on
// the held-out readings in the station the calibration estimated (verifyStations' in-frame
// deviations: `verify --frame-of`). The held-out error against N is the answer.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "artcal/plan/plan.hpp"
#include "artcal/planning/reading_pool.hpp"

namespace artcal {

struct ComparisonOptions {
  std::vector<int> sizes{8, 12, 16, 25, 50};
  std::vector<Criterion> criteria{Criterion::WorstTip, Criterion::MeanTip, Criterion::D,
                                  Criterion::A};
  int draws = 12;  ///< random subsets per size (generator (seed, draw))
  std::uint64_t seed = 1;
  double prior_tolerance = 1.0;  ///< mm (ReadingPool)
  /// Each subset calibrates the set resolved on every recorded reading (the tool's offset
  /// calibrated at every N, issue 45's protocol), or the set its own readings resolve.
  ReadingPool::CalibratedSet calibrated_set = ReadingPool::CalibratedSet::Pool;
  PoolWorkspace workspace = PoolWorkspace::Plan;     ///< where G and I look (ReadingPool)
  PoolOptions pool;                                  ///< its criterion is set per criterion
  std::function<void(const std::string&)> progress;  ///< one line per subset scored
};

/// One subset calibrated and scored.
struct SubsetScore {
  std::vector<int> readings;  ///< pool indices
  double criterion = 0.0;     ///< G of the subset (mm): every row of the table is ranked alike
  bool calibrated = false;    ///< false: the calibration failed (`failure` says why)
  std::string failure;
  double held_out_mean = 0.0;  ///< mm, mean 3-D deviation in the calibration's station
  double held_out_rms = 0.0;   ///< mm
};

struct MethodScore {
  std::string method;                ///< a criterion's name, "farthest" or "random"
  std::vector<SubsetScore> subsets;  ///< one, or the random draws
  /// Over the calibrated subsets: the held-out mean's median, min and max (one subset: itself).
  double median = 0.0, min = 0.0, max = 0.0;
  int failed = 0;
  double seconds = 0.0;  ///< choosing the subset(s)
};

struct SizeComparison {
  int size = 0;
  std::vector<MethodScore> methods;  ///< the criteria in order, then farthest, then random
};

struct DesignComparison {
  int pool = 0;
  int held_out = 0;
  SubsetScore all;  ///< every recorded reading calibrated: the floor of the comparison
  std::vector<SizeComparison> sizes;
};

/// The comparison; InputError when the held-out plan has no instrument station to score, or a
/// size is not below the pool's.
DesignComparison compareDesigns(const Plan& recorded, const Plan& held_out,
                                const ComparisonOptions& options);

}  // namespace artcal
