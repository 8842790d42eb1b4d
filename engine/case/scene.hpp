#pragma once
// The scenes a case may ask for ("scene" in a case file), and which modules
// each composes. One table, read by the case parsers, the run loops and the
// command line: a new scene is a row here and, where it places its spheres
// differently, a branch in the sphere run's placement.
//
//   scene          liquid + IB   spheres   sphere motion   contacts   lubrication
//   suspension     yes           yes       IB + gravity    yes        yes
//   fixed-array    yes           yes       held still      -          -
//   single-sphere  yes           yes       IB + gravity    -          -
//   granular       -             yes       ballistic       yes        -
//   fluid          yes (no IB)   -         -               -          -
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace flocsim::cases {

enum class Scene { suspension, fixed_array, single_sphere, granular, fluid };

struct SceneModules {
  bool liquid = false;        // lattice liquid (+ immersed boundary where there are spheres)
  bool spheres = false;       // a sphere set: run by the sphere time loop, else the fluid one
  bool spheres_move = false;  // sphere equations of motion (else held still)
  bool contacts = false;      // event-driven collisions and square well
  bool lubrication = false;   // radial lubrication below s0
};

struct SceneEntry {
  Scene scene;
  std::string_view name;  // as written in a case file
  SceneModules modules;
};

inline constexpr std::array<SceneEntry, 5> kScenes = {{
    {Scene::suspension, "suspension", {true, true, true, true, true}},
    {Scene::fixed_array, "fixed-array", {true, true, false, false, false}},
    {Scene::single_sphere, "single-sphere", {true, true, true, false, false}},
    {Scene::granular, "granular", {false, true, true, true, false}},
    {Scene::fluid, "fluid", {true, false, false, false, false}},
}};

std::string_view scene_name(Scene scene);
const SceneModules& modules_of(Scene scene);

// The names of the scenes with spheres (with_spheres) or without, in table order.
std::vector<std::string> scene_names(bool with_spheres);
// Every scene's name, in table order.
std::vector<std::string> scene_names();

// The scene of `name`; an unknown name throws input::InputError naming the
// field, the value and the allowed names.
Scene scene_from_name(const std::string& name, const std::string& field = "scene");

// The scene a case document asks for, read before the rest of it decides
// which parser and which time loop take it; refused like scene_from_name.
Scene scene_of(const nlohmann::json& case_document);

}  // namespace flocsim::cases
