#pragma once
// A case of any scene, read and checked by the parser its scene names. This is
// what `flocsim run` does before any work starts, and what `flocsim sweep plan`
// does for every point of a grid: one code path, so a point the plan calls
// refused is refused by the run with the same message.
#include <nlohmann/json.hpp>

#include "engine/case/fluid_case.hpp"
#include "engine/case/suspension_case.hpp"

namespace flocsim::cases {

struct ParsedCase {
  bool fluid_scene = false;  // a scene without spheres: `fluid` holds it
  FluidCase fluid;
  SuspensionCase spheres;
};

// Throws input::InputError naming the field, the value and what is allowed.
ParsedCase parse_case(const nlohmann::json& document);

}  // namespace flocsim::cases
