#pragma once
// The URDF module (libartcal_urdf.so): artcal's URDF import and export, the only code that needs
// urdfdom and tinyxml2, loaded by the io layer on first use (src/io/urdf.cpp). A run that reads
// no URDF (most of them, and every script's loop over plans) then loads neither library nor their
// console_bridge and tinyxml: about a quarter of the process' start-up.
//
// The module and the io layer are built from the same sources in one build: the table below is
// their whole interface, checked by kUrdfModuleAbi before any call.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "artcal/io/urdf.hpp"
#include "artcal/io/urdf_origin_edit.hpp"
#include "artcal/model/chain.hpp"

namespace artcal {

namespace urdf_module {
/// A URDF file's name (for messages) and its text, read by the program (io/urdf.cpp) so that
/// the file is one of the run's inputs (io/output_file.hpp: no output replaces it).
struct UrdfSource {
  std::string path;
  std::string text;
};
// The implementations behind io/urdf.hpp (src/urdf/urdf_import.cpp), same contracts.
nlohmann::json importUrdf(const UrdfSource& urdf, const std::string& base,
                          const std::vector<std::string>& tips);
/// The compliance block's "masses" of the chain from `base` to `tip` (docs/compliance.md
/// section 1): per chain joint, the link it reaches with the links folded into it.
nlohmann::json linkMasses(const UrdfSource& urdf, const std::string& base, const std::string& tip);
Eigen::VectorXd urdfNominal(const Chain& chain, const Eigen::VectorXd& p, const UrdfSource& urdf);
std::string exportUrdf(const Chain& chain, const Eigen::VectorXd& p, const UrdfSource& urdf,
                       const std::string& machine_source, const std::vector<int>& calibrated);
std::vector<OriginEdit> calibratedOrigins(const Chain& chain, const Eigen::VectorXd& p,
                                          const UrdfSource& urdf, const std::string& machine_source,
                                          const std::vector<int>& calibrated);
}  // namespace urdf_module

/// What the module and its loader must agree on: the artcal version, the compiler and the sizes
/// of the types that cross between them.
inline std::string urdfModuleAbi() {
  // "table 3": the entry points' signatures below (a module built before a change of them is
  // refused, not called with other arguments).
  return std::string("artcal " ARTCAL_VERSION_STRING "; table 3; " __VERSION__ "; ") +
         std::to_string(sizeof(nlohmann::json)) + " " + std::to_string(sizeof(Chain)) + " " +
         std::to_string(sizeof(std::string)) + " " + std::to_string(sizeof(Eigen::VectorXd)) + " " +
         std::to_string(sizeof(OriginEdit));
}

/// The module's entry points, returned by its one exported C function, kUrdfModuleSymbol.
struct UrdfModuleTable {
  std::string (*abi)();
  nlohmann::json (*import_urdf)(const urdf_module::UrdfSource&, const std::string&,
                                const std::vector<std::string>&);
  Eigen::VectorXd (*nominal)(const Chain&, const Eigen::VectorXd&, const urdf_module::UrdfSource&);
  std::string (*export_urdf)(const Chain&, const Eigen::VectorXd&, const urdf_module::UrdfSource&,
                             const std::string&, const std::vector<int>&);
  std::vector<OriginEdit> (*origins)(const Chain&, const Eigen::VectorXd&,
                                     const urdf_module::UrdfSource&, const std::string&,
                                     const std::vector<int>&);
  nlohmann::json (*link_masses)(const urdf_module::UrdfSource&, const std::string&,
                                const std::string&);
};
inline constexpr const char* kUrdfModuleSymbol = "artcal_urdf_module";

}  // namespace artcal
