#pragma once
// Umbrella header: the whole public interface of the artcal library.

#include "artcal/artifact.hpp"
#include "artcal/design_matrix.hpp"
#include "artcal/error.hpp"
#include "artcal/evaluator.hpp"
#include "artcal/identifiability.hpp"
#include "artcal/inverse_kinematics.hpp"
#include "artcal/mechanism.hpp"
#include "artcal/normal_matrix.hpp"
#include "artcal/plan.hpp"
#include "artcal/plan_io.hpp"
#include "artcal/planar2r.hpp"
#include "artcal/report.hpp"
#include "artcal/rigid_transform.hpp"
#include "artcal/serial_dh.hpp"
#include "artcal/tip.hpp"
#include "artcal/units.hpp"
