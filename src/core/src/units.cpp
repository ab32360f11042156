#include "crumple/core/units.hpp"

namespace crumple {

std::optional<double> metresPerUnit(std::string_view unit) {
  if (unit == "m") return 1.0;
  if (unit == "cm") return 0.01;
  if (unit == "mm") return 0.001;
  if (unit == "in") return 0.0254;
  return std::nullopt;
}

}  // namespace crumple
