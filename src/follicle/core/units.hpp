#pragma once
// Length units a mesh or hair file may declare; everything is converted to metres on load.
#include <string>
#include <string_view>

namespace follicle {

enum class LengthUnit { mm, cm, dm, m };

/// Metres per one unit.
double unit_to_metres(LengthUnit u);
/// Parses "mm", "cm", "dm", "m"; throws follicle::Error naming the allowed values otherwise.
LengthUnit parse_length_unit(std::string_view s);
std::string to_string(LengthUnit u);

}  // namespace follicle
