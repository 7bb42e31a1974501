// The URDF module's one exported symbol (urdf_module.hpp): its table of entry points.
#include "urdf_module.hpp"

extern "C" __attribute__((visibility("default"))) const artcal::UrdfModuleTable*
artcal_urdf_module() {
  static const artcal::UrdfModuleTable table{
      artcal::urdfModuleAbi, artcal::urdf_module::importUrdf, artcal::urdf_module::urdfNominal,
      artcal::urdf_module::exportUrdf, artcal::urdf_module::calibratedOrigins,
      artcal::urdf_module::linkMasses};
  return &table;
}
