#include "follicle/core/units.hpp"

#include "follicle/core/error.hpp"

namespace follicle {

double unit_to_metres(LengthUnit u) {
  switch (u) {
    case LengthUnit::mm: return 1e-3;
    case LengthUnit::cm: return 1e-2;
    case LengthUnit::dm: return 1e-1;
    case LengthUnit::m: return 1.0;
  }
  return 1.0;
}

LengthUnit parse_length_unit(std::string_view s) {
  if (s == "mm") return LengthUnit::mm;
  if (s == "cm") return LengthUnit::cm;
  if (s == "dm") return LengthUnit::dm;
  if (s == "m") return LengthUnit::m;
  fail("unknown length unit '{}': expected one of mm, cm, dm, m", s);
}

std::string to_string(LengthUnit u) {
  switch (u) {
    case LengthUnit::mm: return "mm";
    case LengthUnit::cm: return "cm";
    case LengthUnit::dm: return "dm";
    case LengthUnit::m: return "m";
  }
  return "m";
}

}  // namespace follicle
