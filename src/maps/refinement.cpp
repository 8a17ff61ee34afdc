#include "obsgroup/maps/local_map_builder.h"

#include <stdexcept>

namespace obsgroup {

std::string toString(Refinement refinement) {
  switch (refinement) {
    case Refinement::None: return "none";
    case Refinement::Icp: return "icp";
    case Refinement::Lum: return "lum";
  }
  return "?";
}

Refinement refinementFromString(const std::string& name) {
  if (name == "none") return Refinement::None;
  if (name == "icp") return Refinement::Icp;
  if (name == "lum") return Refinement::Lum;
  throw std::invalid_argument("unknown refinement '" + name + "' (expected none, icp or lum)");
}

}  // namespace obsgroup
