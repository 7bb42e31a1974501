#pragma once
// Everything of the library for the project's own tools, tests, fuzz harnesses and benchmarks:
// the public interface (artcal/artcal.hpp) and the internal headers it used to reach. Not
// installed; a program outside the project includes artcal/artcal.hpp.

#include "artcal/artcal.hpp"
#include "artcal/calibration/confirmation.hpp"
#include "artcal/calibration/levenberg_marquardt.hpp"
#include "artcal/calibration/simulation.hpp"
#include "artcal/core/linear_algebra.hpp"
#include "artcal/core/parallel.hpp"
#include "artcal/core/random.hpp"
#include "artcal/estimation/design_matrix.hpp"
#include "artcal/estimation/error_functions.hpp"
#include "artcal/estimation/identifiability.hpp"
#include "artcal/estimation/normal_matrix.hpp"
#include "artcal/estimation/tip.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/truth_io.hpp"
#include "artcal/model/inverse_kinematics.hpp"
#include "artcal/planning/design_space.hpp"
#include "artcal/planning/procedure.hpp"
#include "artcal/report/calibration_report.hpp"
#include "artcal/report/html_report.hpp"
#include "artcal/report/report.hpp"
#include "artcal/report/svg.hpp"
