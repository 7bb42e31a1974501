// A consumer of the installed artcal library: reads a plan file, evaluates it and prints the
// standard uncertainty of every calibrated parameter, in file units, one per line:
//   NAME U UNIT
// with U to 17 significant digits (%.17g: the same text for the same double, as CMake's
// string(JSON) prints the numbers of `artcal evaluate --json`).
#include <artcal/artcal.hpp>
#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: artcal_consumer PLAN.json\n");
    return 2;
  }
  try {
    const artcal::Plan plan = artcal::loadPlan(argv[1]);
    const artcal::Evaluation evaluation = artcal::evaluatePlan(plan);
    if (!evaluation.identifiable()) {
      std::fprintf(stderr, "not identifiable\n");
      return 1;
    }
    for (int k = 0; k < plan.machine.calibratedCount(); ++k) {
      const artcal::ParameterInfo& info = plan.machine.calibratedInfo(k);
      const double u = artcal::toFileUnit(info.quantity, evaluation.covariance->u(k));
      std::printf("%s %.17g %s\n", info.name.c_str(), u,
                  std::string(artcal::unitName(info.quantity)).c_str());
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 2;
  }
  return 0;
}
