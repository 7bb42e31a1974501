#pragma once
// The planar2r machine block (docs/plan-format.md): {"model": "planar2r", "parameters": {"l1": mm,
// "l2": mm, "dt2": deg (default 0)}}.

#include "artcal/io/model_registry.hpp"

namespace artcal {

ModelCodec planar2rCodec();

}  // namespace artcal
