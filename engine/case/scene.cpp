#include "engine/case/scene.hpp"

#include <stdexcept>

#include "engine/input/input_reader.hpp"

namespace flocsim::cases {

namespace {
const SceneEntry& entry(Scene scene) {
  for (const auto& e : kScenes)
    if (e.scene == scene) return e;
  throw std::logic_error("scene missing from kScenes");
}
}  // namespace

std::string_view scene_name(Scene scene) {
  return entry(scene).name;
}

const SceneModules& modules_of(Scene scene) {
  return entry(scene).modules;
}

std::vector<std::string> scene_names(bool with_spheres) {
  std::vector<std::string> out;
  for (const auto& e : kScenes)
    if (e.modules.spheres == with_spheres) out.emplace_back(e.name);
  return out;
}

std::vector<std::string> scene_names() {
  std::vector<std::string> out;
  for (const auto& e : kScenes) out.emplace_back(e.name);
  return out;
}

Scene scene_from_name(const std::string& name, const std::string& field) {
  for (const auto& e : kScenes)
    if (e.name == name) return e.scene;
  std::string list;
  for (const auto& e : kScenes) list += (list.empty() ? "\"" : ", \"") + std::string(e.name) + "\"";
  throw input::InputError(field + " = \"" + name + "\": must be one of " + list);
}

Scene scene_of(const nlohmann::json& case_document) {
  input::InputReader root(case_document, "");
  return scene_from_name(root.choice("scene", scene_names()));
}

}  // namespace flocsim::cases
