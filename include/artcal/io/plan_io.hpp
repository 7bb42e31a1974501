#pragma once
// Reading and writing plan files (docs/plan-format.md). Every fault in the input raises InputError
// with the file and the JSON pointer of the offending value; outputs are written to a temporary
// file in the same folder and renamed, so that a reader never sees a half-written file.

#include <nlohmann/json.hpp>
#include <string>

#include "artcal/core/error.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/io/output_file.hpp"
#include "artcal/io/plan_file.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// Largest plan file read, bytes (a bound against unbounded allocation).
inline constexpr std::size_t kMaxPlanFileBytes = 256u << 20;

/// Deepest nesting of arrays and objects accepted in an input document: a plan needs 6 levels;
/// the bound keeps recursive consumers (dump, comparisons) far from the end of the stack.
inline constexpr int kMaxJsonDepth = 64;

/// Parses JSON text; InputError naming `source` when malformed or nested deeper than
/// kMaxJsonDepth.
nlohmann::json parseJsonText(const std::string& text, const std::string& source);

/// The whole content of an input file (plan, machine, CSV readings, URDF), a UTF-8 byte order
/// mark dropped; InputError when it is a directory or not a regular file (a device such as
/// /dev/zero, a FIFO: refused before reading), unreadable, larger than kMaxPlanFileBytes or
/// beyond the memory left. Notes the file as an input (noteInputFile): no output may replace it.
std::string readInputFile(const std::string& path);
/// Reads and parses a JSON file; InputError when unreadable, larger than kMaxPlanFileBytes,
/// malformed or nested deeper than kMaxJsonDepth.
nlohmann::json readJsonFile(const std::string& path);

/// Validates a plan document and converts it to internal units. `source` names it in errors.
/// `require_placements`: a plan for check/evaluate needs at least one; a design spec may have none.
/// Readings outside the joint limits are always refused. `check_plausibility`: also refuse
/// readings and poses that only wrong units explain (io/plausibility.hpp); off only for tests of
/// the numerics on such plans.
Plan parsePlan(const nlohmann::json& document, const std::string& source,
               bool require_placements = true, bool check_plausibility = true);

// loadPlan (readJsonFile + parsePlan): io/plan_file.hpp.

/// A placement's "pose" ({"center", "direction", "roll"}; 2-D: {"center", "angle"}) in internal
/// units; `centre_only`: an artifact placed by its centre alone may leave out its direction.
/// Unknown fields add to `warnings` (a misspelled one is refused). Also what checks a folder's
/// pose.json where import-readings reads it, against that file.
Pose parsePose(const Node& node, int dimension, std::vector<std::string>& warnings,
               bool centre_only);

/// The stylus a reading entry chooses: its "tip" (one of mech.stylusNames(), a chain's "tips")
/// or its "stylus" (an index); 0 when it names neither. InputError at the entry otherwise.
int readStylus(const Node& entry, const Mechanism& mech);

/// Joint values as a file writes them (deg per revolute joint, mm per prismatic one) in
/// internal units.
Eigen::VectorXd jointsFromFile(const Mechanism& mech, const Eigen::VectorXd& values);

/// The placements of a plan as plan-file JSON (file units), e.g. for a plan the tool writes.
nlohmann::json placementsToJson(const Plan& plan);
/// The machine block with the given full parameter vector as nominal values (file units).
nlohmann::json machineToJson(const Machine& machine, const Eigen::VectorXd& parameters);

}  // namespace artcal
