#include "artcal/model/mechanism.hpp"

namespace artcal {

int Mechanism::parameterIndex(const std::string& name) const {
  const auto& params = parameters();
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (params[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace artcal
