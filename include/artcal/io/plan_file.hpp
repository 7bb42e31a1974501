#pragma once
// Loading a plan file (docs/plan-format.md): the public way in, without the JSON library's types
// (the document itself, parsePlan and the writers are in io/plan_io.hpp, internal). Every fault
// in the input raises InputError with the file and the JSON pointer of the offending value.

#include <string>

#include "artcal/core/error.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// Reads a plan file, validates it and converts it to internal units (mm, rad).
/// `require_placements`: a plan for check/evaluate needs at least one; a design spec may have
/// none. InputError naming the file and the JSON pointer of the first fault.
Plan loadPlan(const std::string& path, bool require_placements = true);

}  // namespace artcal
