// The scene table: every scene's name reads back to it, an unknown name is
// refused naming the field, the value and every allowed name (it falls
// through to no scene), and each scene composes the modules the solver's
// documentation says.
#include "engine/case/scene.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "engine/input/input_reader.hpp"

namespace flocsim::cases {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

TEST(Scene, NamesRoundTrip) {
  for (const auto& e : kScenes) {
    EXPECT_EQ(scene_from_name(std::string(e.name)), e.scene);
    EXPECT_EQ(scene_name(e.scene), e.name);
  }
  EXPECT_EQ(scene_names().size(), kScenes.size());
  EXPECT_EQ(scene_names(true).size() + scene_names(false).size(), kScenes.size());
}

TEST(Scene, UnknownNameIsRefusedWithTheAllowedNames) {
  try {
    scene_from_name("sedimenting-bed");
    FAIL() << "accepted an unknown scene";
  } catch (const input::InputError& e) {
    EXPECT_THAT(e.what(),
                AllOf(HasSubstr("scene = \"sedimenting-bed\""), HasSubstr("\"suspension\""),
                      HasSubstr("\"fixed-array\""), HasSubstr("\"single-sphere\""),
                      HasSubstr("\"granular\""), HasSubstr("\"fluid\"")));
  }
  EXPECT_THROW(scene_of(nlohmann::json{{"scene", "granular-bed"}}), input::InputError);
  EXPECT_THROW(scene_of(nlohmann::json{{"phi", 0.2}}), input::InputError);  // no scene
  EXPECT_EQ(scene_of(nlohmann::json{{"scene", "fluid"}}), Scene::fluid);
}

TEST(Scene, ModulesOfEachScene) {
  const SceneModules& s = modules_of(Scene::suspension);
  EXPECT_TRUE(s.liquid && s.spheres && s.spheres_move && s.contacts && s.lubrication);
  const SceneModules& f = modules_of(Scene::fixed_array);
  EXPECT_TRUE(f.liquid && f.spheres && !f.spheres_move && !f.contacts && !f.lubrication);
  const SceneModules& one = modules_of(Scene::single_sphere);
  EXPECT_TRUE(one.liquid && one.spheres_move && !one.contacts && !one.lubrication);
  const SceneModules& g = modules_of(Scene::granular);
  EXPECT_TRUE(!g.liquid && g.spheres_move && g.contacts && !g.lubrication);
  const SceneModules& fluid = modules_of(Scene::fluid);
  EXPECT_TRUE(fluid.liquid && !fluid.spheres);
}

}  // namespace
}  // namespace flocsim::cases
