// libFuzzer harness of the CSV reader of joint readings (models.md section 7): the input is a CSV
// file read for a machine of three joints (revolute, prismatic, revolute), in degrees and in
// radians and metres, and in both. An InputError is the proper answer; any other escape, a crash or
// a non-finite reading is a finding.

#include "artcal/io/csv_readings.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace artcal;
  if (size > fuzz::kMaxInputBytes) return 0;
  const std::string path = fuzz::writeInputFile(data, size, ".csv");
  const std::vector<JointKind> kinds = {JointKind::Revolute, JointKind::Prismatic,
                                        JointKind::Revolute};
  for (const char* unit : {"deg", "rad", "m", "rad+m"}) {
    try {
      for (const Eigen::VectorXd& row : readJointCsv(path, kinds, *readingUnitsFromName(unit))) {
        if (row.size() != 3 || !row.allFinite())
          fuzz::finding("a CSV row not of 3 finite readings");
      }
    } catch (const InputError&) {
    }
  }
  return 0;
}
