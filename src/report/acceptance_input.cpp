// The input of an acceptance prediction (report/acceptance_input.hpp).

#include "artcal/report/acceptance_input.hpp"

#include "artcal/core/error.hpp"
#include "artcal/io/machine_covariance.hpp"
#include "artcal/io/truth_io.hpp"

namespace artcal {

AcceptanceInput acceptanceInputFromMachineFile(const nlohmann::json& machine,
                                               const std::string& machine_source, const Plan& plan,
                                               bool posterior) {
  const Eigen::VectorXd parameters = parseTruth(machine, machine_source, plan);
  auto uncertainty = parseMachineCovariance(machine, machine_source, plan);
  if (!uncertainty)
    throw InputError(machine_source, "/covariance",
                     "no covariance: write the machine with `artcal calibrate --write-machine`");
  if (posterior && !(uncertainty->birge_ratio > 0.0))
    throw InputError(machine_source, "/covariance/birge_ratio",
                     "--posterior needs the calibration's Birge ratio in the machine file");
  return acceptanceInputFromMachine(plan, parameters, std::move(*uncertainty), posterior);
}

}  // namespace artcal
