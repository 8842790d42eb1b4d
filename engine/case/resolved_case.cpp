#include "engine/case/resolved_case.hpp"

#include "engine/case/fluid_case.hpp"
#include "engine/case/scene.hpp"
#include "engine/case/suspension_case.hpp"

namespace flocsim::cases {

nlohmann::json resolved_case(const nlohmann::json& document) {
  // the scene decides the parser, as in `flocsim run`
  if (!modules_of(scene_of(document)).spheres) return parse_fluid_case(document).to_json();
  return parse_suspension_case(document).to_json();
}

}  // namespace flocsim::cases
