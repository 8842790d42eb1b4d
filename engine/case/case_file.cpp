#include "engine/case/case_file.hpp"

#include "engine/case/scene.hpp"

namespace flocsim::cases {

ParsedCase parse_case(const nlohmann::json& document) {
  ParsedCase c;
  // the scene decides which parser and which time loop take the case
  c.fluid_scene = !modules_of(scene_of(document)).spheres;
  if (c.fluid_scene)
    c.fluid = parse_fluid_case(document);
  else
    c.spheres = parse_suspension_case(document);
  return c;
}

}  // namespace flocsim::cases
