#pragma once
// Length units a scene file may state (`units = "cm"`); everything inside is SI.
#include <optional>
#include <string_view>

namespace crumple {

// Metres per unit for "m", "cm", "mm", "in"; nullopt for anything else.
std::optional<double> metresPerUnit(std::string_view unit);

}  // namespace crumple
