#pragma once
// Umbrella header of the PUBLIC interface of the artcal library: what a program or a Python
// module includes to build or read a plan, choose a model, evaluate, optimize, calibrate and
// verify. `cmake --install` installs exactly these headers and the ones they include (the closure
// is computed in cmake/artcal_install.cmake); `find_package(artcal)` then `artcal::artcal`.
//
// Public (stable; changes are noted in the changelog):
//   plan in memory     artcal/plan/plan.hpp, artcal/artifact/artifact.hpp,
//                      artcal/artifact/rigid_transform.hpp
//   plan files         artcal/io/plan_file.hpp (loadPlan; no JSON types), artcal/core/error.hpp
//   units              artcal/core/units.hpp (internal units mm and rad; file units mm and deg)
//   models             artcal/model/machine.hpp, artcal/model/mechanism.hpp and one header per
//                      family: planar2r, serial_dh, chain, hexapod, cartesian, machine_tool
//   evaluate           artcal/estimation/evaluator.hpp (evaluatePlan, EvaluateOptions,
//                      Evaluation, PlanEvaluator)
//   optimize           artcal/planning/optimizer.hpp (optimizePlan, OptimizerOptions,
//                      OptimizerSummary)
//   calibrate          artcal/calibration/calibrate_readings.hpp (calibrateReadings,
//                      CalibrationOptions, Calibration; artcal/calibration/calibrator.hpp)
//   verify             artcal/calibration/verification.hpp (verifyMachine, Verification)
//
// Everything else under include/artcal (plan documents as JSON: io/plan_io.hpp, parsePlan and
// the writers; report/, the codecs and the model registry, the design matrix and normal-matrix
// internals, acceptance, the command line's helpers) is INTERNAL: used by the tools and the tests
// of this project, free to change. The project's own code may include artcal/internal.hpp for
// all of it. The umbrella includes no JSON header (tests/consumer checks that the installed tree
// has none). Some internal headers are still reached through the classes' private members
// (PlanEvaluator, Calibrator, the optimizer) and installed with them.

#include "artcal/artifact/artifact.hpp"
#include "artcal/artifact/rigid_transform.hpp"
#include "artcal/calibration/calibrate_readings.hpp"
#include "artcal/calibration/calibrator.hpp"
#include "artcal/calibration/verification.hpp"
#include "artcal/core/error.hpp"
#include "artcal/core/units.hpp"
#include "artcal/estimation/evaluator.hpp"
#include "artcal/io/plan_file.hpp"
#include "artcal/model/cartesian.hpp"
#include "artcal/model/chain.hpp"
#include "artcal/model/hexapod.hpp"
#include "artcal/model/machine_tool.hpp"
#include "artcal/model/machine.hpp"
#include "artcal/model/mechanism.hpp"
#include "artcal/model/planar2r.hpp"
#include "artcal/model/serial_dh.hpp"
#include "artcal/plan/plan.hpp"
#include "artcal/planning/optimizer.hpp"
