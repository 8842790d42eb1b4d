// Bad input is refused before any work starts with a message that names the
// field, the value and what is allowed; good input is read with its defaults.
#include "engine/case/fluid_case.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "engine/input/input_reader.hpp"

namespace flocsim::cases {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using json = nlohmann::json;

json valid_case() {
  return json::parse(R"({
    "scene": "fluid",
    "fluid": {"size": [32, 8, 8], "viscosity": 0.01,
              "initial": {"type": "shear_wave", "amplitude": 0.01}},
    "run": {"steps": 100}
  })");
}

// The message of the InputError that parsing `doc` throws.
std::string refusal(const json& doc) {
  try {
    parse_fluid_case(doc);
  } catch (const input::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted: " << doc.dump();
  return "";
}

TEST(FluidCase, ValidCaseIsReadWithDefaults) {
  const FluidCase c = parse_fluid_case(valid_case());
  EXPECT_EQ(c.size.nx, 32);
  EXPECT_DOUBLE_EQ(c.relaxation.viscosity, 0.01);
  EXPECT_DOUBLE_EQ(c.relaxation.magic_lambda, 0.25);
  EXPECT_EQ(c.precision, Precision::double_precision);
  EXPECT_EQ(c.initial.axis, 0);
  EXPECT_EQ(c.initial.component, 1);
  EXPECT_EQ(c.run.steps, 100);
  EXPECT_TRUE(c.warnings.empty());
  // the canonical form reads back to the same case
  EXPECT_EQ(parse_fluid_case(c.to_json()).to_json(), c.to_json());
}

TEST(FluidCase, ViscosityAtOrBelowZeroIsRefusedWithTheTauLimit) {
  for (double nu : {0.0, -0.01}) {
    json d = valid_case();
    d["fluid"]["viscosity"] = nu;
    EXPECT_THAT(refusal(d),
                AllOf(HasSubstr("fluid.viscosity"), HasSubstr("> 0"), HasSubstr("tau")));
  }
}

TEST(FluidCase, ViscosityBelowTheTestedRangeIsAcceptedWithAWarning) {
  json d = valid_case();
  d["fluid"]["viscosity"] = 0.002;
  const FluidCase c = parse_fluid_case(d);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_THAT(c.warnings[0], AllOf(HasSubstr("fluid.viscosity"), HasSubstr("0.005")));
}

TEST(FluidCase, NonPositiveOrFractionalSizesAreRefused) {
  json d = valid_case();
  d["fluid"]["size"] = {32, 0, 8};
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("fluid.size[1]"), HasSubstr("= 0"), HasSubstr(">= 1")));
  d["fluid"]["size"] = {32, -4, 8};
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("fluid.size[1]"), HasSubstr("-4")));
  d["fluid"]["size"] = {32.5, 8, 8};
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("fluid.size[0]"), HasSubstr("32.5"), HasSubstr("whole")));
  d["fluid"]["size"] = {32, 8};
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("fluid.size"), HasSubstr("array of 3")));
}

TEST(FluidCase, VelocitiesBeyondTheMachLimitAreRefused) {
  json d = valid_case();
  d["fluid"]["initial"]["amplitude"] = 0.2;
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("fluid.initial.amplitude"), HasSubstr("0.2"),
                                HasSubstr("Mach limit")));
  d = valid_case();
  d["fluid"]["initial"]["velocity"] = {0.08, 0, 0};
  d["fluid"]["initial"]["amplitude"] = 0.05;  // each allowed, their sum is not
  EXPECT_THAT(refusal(d),
              AllOf(HasSubstr("peak initial speed"), HasSubstr("0.13"), HasSubstr("Mach limit")));
}

TEST(FluidCase, BodyForceThatWouldAccelerateBeyondTheMachLimitIsRefused) {
  // periodic box, nothing balances the force: u(t) = f t = 1e-4 * 2000 = 0.2
  json d = valid_case();
  d["fluid"]["body_force"] = {1e-4, 0, 0};
  d["run"]["steps"] = 2000;
  EXPECT_THAT(refusal(d),
              AllOf(HasSubstr("fluid.body_force"), HasSubstr("0.2"), HasSubstr("Mach")));
  d["run"]["steps"] = 500;  // u = 0.05: fine
  EXPECT_NO_THROW(parse_fluid_case(d));
}

TEST(FluidCase, UnknownKeysAreRefusedWithTheKnownOnes) {
  json d = valid_case();
  d["fluid"]["viscocity"] = 0.01;
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("fluid.viscocity"), HasSubstr("unknown key"),
                                HasSubstr("viscosity")));
  d = valid_case();
  d["runs"] = json::object();
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("runs"), HasSubstr("unknown key")));
}

TEST(FluidCase, WrongTypesAreRefused) {
  json d = valid_case();
  d["fluid"]["viscosity"] = "0.01";
  EXPECT_THAT(refusal(d),
              AllOf(HasSubstr("fluid.viscosity"), HasSubstr("\"0.01\""), HasSubstr("number")));
  d = valid_case();
  d["run"]["steps"] = 10.5;
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("run.steps"), HasSubstr("whole number")));
  d = valid_case();
  d["precision"] = "quad";
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("precision"), HasSubstr("\"float\"")));
}

TEST(FluidCase, ShearWaveMustBeTransverseAndResolved) {
  json d = valid_case();
  d["fluid"]["initial"]["component"] = "x";
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("fluid.initial.component"), HasSubstr("transverse")));
  d = valid_case();
  d["fluid"]["initial"]["wavelengths"] = 9;  // 32 cells < 4 x 9
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("fluid.size[0]"), HasSubstr("36")));
}

TEST(FluidCase, MissingRequiredObjectIsNamed) {
  json d = valid_case();
  d.erase("fluid");
  EXPECT_THAT(refusal(d), AllOf(HasSubstr("fluid"), HasSubstr("missing")));
}

TEST(FluidCase, TaylorGreenInitialStateIsDivergenceFreeWithTheAnalyticPressure) {
  // Hand-worked: with k1 = k2 the velocity u_x = -U cos kx sin ky,
  // u_y = U sin kx cos ky and rho = 1 + 3 p, p = -U^2/4 (cos 2kx + cos 2ky).
  json d = valid_case();
  d["fluid"]["size"] = {16, 16, 2};
  d["fluid"]["initial"] = {{"type", "taylor_green"}, {"amplitude", 0.05}};
  const FluidCase c = parse_fluid_case(d);
  const double k = 2 * M_PI / 16, U = 0.05;
  for (int x : {0, 3, 7})
    for (int y : {1, 5, 12}) {
      const auto m = initial_state(c, x, y, 0);
      EXPECT_NEAR(m.velocity.x, -U * std::cos(k * x) * std::sin(k * y), 1e-15);
      EXPECT_NEAR(m.velocity.y, U * std::sin(k * x) * std::cos(k * y), 1e-15);
      EXPECT_NEAR(m.density, 1 - 0.75 * U * U * (std::cos(2 * k * x) + std::cos(2 * k * y)), 1e-15);
    }
  EXPECT_NEAR(analytic_decay_rate(c), 2 * 0.01 * k * k, 1e-15);
}

}  // namespace
}  // namespace flocsim::cases
