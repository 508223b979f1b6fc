#include "core/plant/robot/robot_config.h"

#include "core/base/json_input.h"
#include "tests/core/test_support.h"
#include "core/run_config.h"
#include "core/plant/simulation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace armfault {
namespace {

using nlohmann::json;
using testing::ElementsAre;
using testing::HasSubstr;

using testing_support::ErrorOf;
using testing_support::ErrorTexts;

InputError RobotError(const json& value, const std::string& pointer = "") {
  return ErrorOf([&] { RobotFromJson(value, pointer); });
}

// A two-joint robot JSON with default modules and links; tests modify it.
json TwoJoints() { return {{"modules", {json::object(), json::object()}}, {"links", {json::object(), json::object()}}}; }

// ---------------------------------------------------------------- presets

TEST(RobotConfigPresets, NamesInTableOrder) {
  EXPECT_THAT(RobotPresetNames(), ElementsAre("mrr-config1", "pendulum", "ur-class"));
}

TEST(RobotConfigPresets, EveryPresetValidatesAndHasOneBodyPerModule) {
  for (const std::string& name : RobotPresetNames()) {
    const RobotConfig r = RobotPreset(name);
    EXPECT_EQ(r.name, name);
    EXPECT_FALSE(r.modules.empty()) << name;
    // One link (the shorthand) or one body (the general form, a URDF robot) per module.
    EXPECT_EQ(r.links.empty() ? r.bodies.size() : r.links.size(), r.modules.size()) << name;
    EXPECT_TRUE(r.links.empty() || r.bodies.empty()) << name;
    EXPECT_NO_THROW(Validate(r, "")) << name;
    EXPECT_NO_THROW(Validate(r, "/robot")) << name;
    // A preset name is also accepted as the robot JSON.
    EXPECT_EQ(RobotToJson(RobotFromJson(json(name), "/robot")), RobotToJson(r)) << name;
  }
}

TEST(RobotConfigPresets, MrrConfig1IsMrr1WithTwoMrr2) {
  const RobotConfig r = RobotPreset("mrr-config1");
  ASSERT_EQ(r.modules.size(), 3u);
  EXPECT_EQ(r.modules[0].type, "MRR1");
  EXPECT_EQ(r.modules[1].type, "MRR2");
  EXPECT_EQ(r.modules[2].type, "MRR2");
  ASSERT_EQ(r.links.size(), 3u);
  // Base joint vertical, the two upper joints horizontal.
  EXPECT_EQ(r.links[0].joint_axis, (std::array<double, 3>{0, 0, 1}));
  EXPECT_EQ(r.links[1].joint_axis, (std::array<double, 3>{0, -1, 0}));
  EXPECT_EQ(r.links[2].joint_axis, (std::array<double, 3>{0, -1, 0}));
  EXPECT_EQ(r.physics_rate_Hz, 1000);
  EXPECT_EQ(r.payload_kg, 2.0);  // tool at the flange
}

TEST(RobotConfigPresets, MrrConfig1CarriesTheThesisValues) {
  const RobotConfig r = RobotPreset("mrr-config1");
  ASSERT_EQ(r.modules.size(), 3u);
  // Drive train and power stage of every module (thesis table 5-1).
  for (size_t i = 0; i < r.modules.size(); ++i) {
    const ModuleParams& m = r.modules[i];
    EXPECT_EQ(m.drive.ratio, 101.0) << "module " << i;
    EXPECT_EQ(m.inverter.bus_voltage_V, 70.0) << "module " << i;
    EXPECT_EQ(m.inverter.current_per_volt_A_per_V, 4.0) << "module " << i;
    EXPECT_EQ(m.controller.rate_Hz, 500.0) << "module " << i;
  }
  // The MRR2 modules (thesis table 5-2 and appendix C).
  for (size_t i : {1u, 2u}) {
    const ModuleParams& m = r.modules[i];
    EXPECT_EQ(m.motor.kt_Nm_per_A, 0.165) << "module " << i;
    EXPECT_EQ(m.motor.rotor_inertia_kg_m2, 3.46e-5) << "module " << i;
    EXPECT_EQ(m.controller.kt_hat_Nm_per_A, 0.167) << "module " << i;
    EXPECT_EQ(m.controller.im_hat_kg_m2, 3.46e-5) << "module " << i;
    EXPECT_EQ(m.friction.viscous_Nm_s_per_rad, 0.00124) << "module " << i;
    EXPECT_EQ(m.friction.coulomb_Nm, 0.025) << "module " << i;
    EXPECT_EQ(m.friction.static_Nm, 0.027) << "module " << i;
    EXPECT_EQ(m.friction.stribeck_s2_per_rad2, 15.0) << "module " << i;
    EXPECT_EQ(m.min_angle_deg, -120.0) << "module " << i;
    EXPECT_EQ(m.max_angle_deg, 120.0) << "module " << i;
    EXPECT_EQ(m.encoder.counts_per_rev, 2540) << "module " << i;
    EXPECT_EQ(m.torque_sensor.full_scale_Nm, 28.0) << "module " << i;
    EXPECT_EQ(m.torque_sensor.offset_Nm, 3.5077) << "module " << i;
  }
  EXPECT_EQ(r.modules[0].min_angle_deg, -60.0);
  EXPECT_EQ(r.modules[0].max_angle_deg, 60.0);
}

TEST(RobotConfigPresets, PendulumIsOneHangingLink) {
  const RobotConfig r = RobotPreset("pendulum");
  ASSERT_EQ(r.modules.size(), 1u);
  ASSERT_EQ(r.links.size(), 1u);
  EXPECT_EQ(r.links[0].direction, (std::array<double, 3>{0, 0, -1}));
  EXPECT_EQ(r.links[0].length_m, 0.5);
}

TEST(RobotConfigPresets, UnknownPresetListsTheKnownOnes) {
  InputError e = ErrorOf([] { RobotPreset("nope", "/robot"); });
  EXPECT_EQ(e.pointer(), "/robot");
  EXPECT_EQ(e.message(), "unknown robot preset \"nope\" (known: mrr-config1, pendulum, ur-class)");
  e = RobotError(json("mrr-config2"), "/robot");
  EXPECT_EQ(e.pointer(), "/robot");
  EXPECT_THAT(e.message(), HasSubstr("unknown robot preset \"mrr-config2\" (known: mrr-config1, pendulum, ur-class)"));
  // Preset names are case-sensitive.
  EXPECT_EQ(RobotError(json("MRR-CONFIG1")).pointer(), "");
}

TEST(RobotConfigPresets, ModuleDefaultsByType) {
  EXPECT_EQ(ModuleDefaults("MRR2", "").type, "MRR2");
  EXPECT_EQ(ModuleDefaults("MRR1", "").type, "MRR1");
  EXPECT_EQ(ModuleDefaults("MRR1", "").motor.kt_Nm_per_A, 0.12);
  const InputError e = ErrorOf([] { ModuleDefaults("mrr2", "/modules/4/type"); });
  EXPECT_EQ(e.pointer(), "/modules/4/type");
  EXPECT_EQ(e.message(), "unknown module type \"mrr2\" (known: MRR1, MRR2, industrial-small, industrial-large, industrial-small-thermal, industrial-large-thermal)");
}

// ---------------------------------------------------------------- RobotFromJson

TEST(RobotConfigFromJson, MinimalRobotUsesDefaults) {
  const RobotConfig r = RobotFromJson({{"modules", {json::object()}}, {"links", {json::object()}}}, "");
  EXPECT_EQ(r.name, "custom");
  ASSERT_EQ(r.modules.size(), 1u);
  EXPECT_EQ(r.modules[0].type, "MRR2");
  EXPECT_EQ(r.modules[0].motor.kt_Nm_per_A, 0.165);
  EXPECT_EQ(r.links[0].mass_kg, 1.0);
  EXPECT_FALSE(r.links[0].has_inertia);
  EXPECT_EQ(r.gravity_m_s2, 9.81);
  EXPECT_EQ(r.electrical_substeps, 20);
}

TEST(RobotConfigFromJson, TorqueSensorNullRemovesTheSensorAndWritesBackAsNull) {
  json j = TwoJoints();
  j["modules"][1] = {{"torque_sensor", nullptr}};
  const RobotConfig r = RobotFromJson(j, "/robot");
  EXPECT_TRUE(r.modules[0].torque_sensor.present);
  EXPECT_FALSE(r.modules[1].torque_sensor.present);
  const json written = RobotToJson(r);
  EXPECT_TRUE(written["modules"][1]["torque_sensor"].is_null());
  EXPECT_FALSE(RobotFromJson(written, "/robot").modules[1].torque_sensor.present);
  // An object puts it back, with the type's values under what it overrides.
  j["modules"][1] = {{"torque_sensor", {{"noise_Nm", 0.1}}}};
  EXPECT_TRUE(RobotFromJson(j, "/robot").modules[1].torque_sensor.present);
  j["modules"][1] = {{"torque_sensor", 5}};
  const InputError e = RobotError(j, "/robot");
  EXPECT_EQ(e.pointer(), "/robot/modules/1/torque_sensor");
  EXPECT_EQ(e.message(), "expected an object (the sensor's parameters) or null (no torque sensor), got number 5");
}

TEST(RobotConfigFromJson, ModuleFieldOverridesItsTypeDefault) {
  json j = TwoJoints();
  j["name"] = "mine";
  j["modules"][0] = {{"type", "MRR1"}, {"motor", {{"kt_Nm_per_A", 0.2}}}, {"max_angle_deg", 90}};
  j["modules"][1] = {{"friction", {{"coulomb_Nm", 0.04}}}, {"controller", {{"velocity_window", 8}}}};
  const RobotConfig r = RobotFromJson(j, "/robot");
  EXPECT_EQ(r.name, "mine");
  ASSERT_EQ(r.modules.size(), 2u);
  EXPECT_EQ(r.modules[0].type, "MRR1");
  EXPECT_EQ(r.modules[0].motor.kt_Nm_per_A, 0.2);
  // Untouched fields keep the MRR1 defaults, not the MRR2 struct defaults.
  EXPECT_EQ(r.modules[0].motor.phase_resistance_ohm, 0.15);
  EXPECT_EQ(r.modules[0].motor.rotor_inertia_kg_m2, 1.5e-4);
  EXPECT_EQ(r.modules[0].controller.kt_hat_Nm_per_A, 0.12);
  EXPECT_EQ(r.modules[0].min_angle_deg, -60.0);
  EXPECT_EQ(r.modules[0].max_angle_deg, 90.0);
  EXPECT_EQ(r.modules[1].type, "MRR2");
  EXPECT_EQ(r.modules[1].friction.coulomb_Nm, 0.04);
  EXPECT_EQ(r.modules[1].friction.static_Nm, 0.027);
  EXPECT_EQ(r.modules[1].controller.velocity_window, 8);
}

TEST(RobotConfigFromJson, LinkAndTopLevelFields) {
  json j = TwoJoints();
  j["links"][1] = {{"mass_kg", 2.0}, {"direction", {0, 0, 1}}, {"inertia_kg_m2", {0.01, 0.02, 0.03}}};
  j["base_position_m"] = {1, 2, 3};
  j["payload_kg"] = 0.5;
  j["physics_rate_Hz"] = 2000;
  j["electrical_substeps"] = 10;
  const RobotConfig r = RobotFromJson(j, "");
  EXPECT_EQ(r.links[1].mass_kg, 2.0);
  EXPECT_EQ(r.links[1].direction, (std::array<double, 3>{0, 0, 1}));
  EXPECT_TRUE(r.links[1].has_inertia);
  EXPECT_EQ(r.links[1].inertia_kg_m2, (std::array<double, 3>{0.01, 0.02, 0.03}));
  EXPECT_EQ(r.base_position_m, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(r.payload_kg, 0.5);
  EXPECT_EQ(r.physics_rate_Hz, 2000);
  EXPECT_EQ(r.electrical_substeps, 10);
}

// ---------------------------------------------------------------- errors

TEST(RobotConfigErrors, OutOfRangeModuleFieldNamesItsPointer) {
  json j = TwoJoints();
  j["modules"][1]["motor"] = {{"kt_Nm_per_A", -0.1}};
  InputError e = RobotError(j);
  EXPECT_EQ(e.source(), "");
  EXPECT_EQ(e.pointer(), "/modules/1/motor/kt_Nm_per_A");
  EXPECT_EQ(e.message(), "-0.1 must be greater than 0");
  j["modules"][1]["motor"] = {{"kt_Nm_per_A", 0}};
  EXPECT_EQ(RobotError(j).message(), "0 must be greater than 0");
  j["modules"][1]["motor"] = {{"kt_Nm_per_A", 20}};
  EXPECT_EQ(RobotError(j).message(), "20 is outside [0, 10]");
  // Under a parent pointer.
  j["modules"][1]["motor"] = {{"kt_Nm_per_A", -0.1}};
  EXPECT_EQ(RobotError(j, "/robot").pointer(), "/robot/modules/1/motor/kt_Nm_per_A");
}

TEST(RobotConfigErrors, EveryGroupChecksItsRanges) {
  const struct {
    const char* group;
    const char* key;
    json value;
    const char* message;
  } cases[] = {
      {"inverter", "bus_voltage_V", -70, "-70 must be greater than 0"},
      {"inverter", "diode_drop_V", -0.1, "-0.1 is outside [0, 10]"},
      {"drive", "ratio", 0.5, "0.5 is outside [2, 10000]"},
      {"drive", "ratio", 1, "1 is outside [2, 10000]"},  // ODE's gear asserts radii > 0 at 1
      {"motor", "rotor_inertia_kg_m2", 1e-300, "1e-300 is outside [1e-09, 1]"},
      {"drive", "mesh_loss_fraction", 1, "1 is outside [0, 0.9]"},
      {"friction", "viscous_Nm_s_per_rad", -1, "-1 is outside [0, 10]"},
      {"brake", "holding_torque_Nm", -1, "-1 is outside [0, 1000]"},
      {"torque_sensor", "adc_bits", 30, "30 is outside [4, 24]"},
      {"torque_sensor", "adc_bits", 12.5, "expected a whole number, got 12.5"},
      {"encoder", "counts_per_rev", 2540.5, "expected a whole number, got 2540.5"},
      {"controller", "velocity_window", 65, "65 is outside [1, 64]"},
      {"controller", "epsilon_robust", 0, "0 must be greater than 0"},
      {"motor", "pole_pairs", "3", "expected a number, got string \"3\""},
  };
  for (const auto& c : cases) {
    json j = TwoJoints();
    j["modules"][0][c.group] = {{c.key, c.value}};
    const InputError e = RobotError(j, "/robot");
    EXPECT_EQ(e.pointer(), std::string("/robot/modules/0/") + c.group + "/" + c.key);
    EXPECT_EQ(e.message(), c.message) << c.group << "/" << c.key;
  }
}

TEST(RobotConfigErrors, UnknownKeysAreReportedWhereTheyAre) {
  json j = TwoJoints();
  j["modules"][0]["motr"] = {{"kt_Nm_per_A", 0.2}};
  InputError e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/modules/0/motr");
  EXPECT_EQ(e.message(), "unknown key \"motr\"");

  j = TwoJoints();
  j["modules"][1]["motor"] = {{"kt", 0.2}};
  EXPECT_EQ(RobotError(j).pointer(), "/modules/1/motor/kt");

  j = TwoJoints();
  j["links"][1]["mass"] = 2;
  EXPECT_EQ(RobotError(j).pointer(), "/links/1/mass");

  j = TwoJoints();
  j["gravity"] = 9.81;
  e = RobotError(j, "/robot");
  EXPECT_EQ(e.pointer(), "/robot/gravity");
  EXPECT_EQ(e.message(), "unknown key \"gravity\"");
}

TEST(RobotConfigErrors, LinkCountMustMatchModuleCount) {
  json j = TwoJoints();
  j["links"] = {json::object()};
  InputError e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/links");
  EXPECT_EQ(e.message(), "1 links for 2 modules: give one link per joint module");
  j["links"] = {json::object(), json::object(), json::object()};
  EXPECT_EQ(RobotError(j, "/robot").pointer(), "/robot/links");
  EXPECT_EQ(RobotError(j, "/robot").message(), "3 links for 2 modules: give one link per joint module");
  j["links"] = json::array();
  EXPECT_EQ(RobotError(j).message(), "0 links for 2 modules: give one link per joint module");
}

// Every independent part of a robot is checked: all errors at once, in document order.
TEST(RobotConfigErrors, EveryBadModuleLinkAndFieldIsReported) {
  json j = TwoJoints();
  j["modules"][0]["motr"] = json::object();
  j["modules"][0]["inverter"] = {{"bus_voltage_V", -1}, {"pwm_frequency_Hz", 0}};
  j["modules"][1]["type"] = "MRR3";
  j["modules"][1]["encoder"] = {{"counts_per_rev", 2.5}};
  j["links"][1] = {{"mass_kg", 0}, {"direction", {0, 0, 0}}};
  j["payload_kg"] = 500;
  EXPECT_THAT(ErrorTexts(RobotError(j, "/robot")),
              ElementsAre("/robot/modules/0/motr: unknown key \"motr\"; did you mean \"motor\"?",
                          "/robot/modules/0/inverter/bus_voltage_V: -1 must be greater than 0",
                          "/robot/modules/0/inverter/pwm_frequency_Hz: 0 must be greater than 0",
                          "/robot/modules/1/type: unknown module type \"MRR3\" (known: MRR1, MRR2, industrial-small, industrial-large, industrial-small-thermal, industrial-large-thermal)",
                          "/robot/modules/1/encoder/counts_per_rev: expected a whole number, got 2.5",
                          "/robot/links/1/mass_kg: 0 is outside [0.001, 1000]",
                          "/robot/links/1/direction: the link direction must not be the zero vector",
                          // The cross-field checks still run: bad values left their defaults.
                          "/robot/payload_kg: 500 is outside [0, 100]"));
}

TEST(RobotConfigErrors, CrossFieldChecksNeedTheTopLevelValues) {
  json j = TwoJoints();
  j["links"] = {json::object()};           // a count mismatch, found by Validate()
  j["physics_rate_Hz"] = "fast";           // ... which is skipped: the rate is unreadable
  EXPECT_THAT(ErrorTexts(RobotError(j)), ElementsAre("/physics_rate_Hz: expected a number, got string \"fast\""));
  j.erase("physics_rate_Hz");
  j["gravity_m_s2"] = -1;
  j["modules"][1]["controller"] = {{"rate_Hz", 300}};
  EXPECT_THAT(ErrorTexts(RobotError(j)), ElementsAre("/links: 1 links for 2 modules: give one link per joint module",
                                                "/gravity_m_s2: -1 is outside [0, 100]",
                                                "/modules/1/controller/rate_Hz: 300 Hz must divide the physics rate 1000 Hz"));
}

TEST(RobotConfigErrors, UnknownModuleType) {
  json j = TwoJoints();
  j["modules"][0]["type"] = "MRR3";
  InputError e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/modules/0/type");
  EXPECT_EQ(e.message(), "unknown module type \"MRR3\" (known: MRR1, MRR2, industrial-small, industrial-large, industrial-small-thermal, industrial-large-thermal)");
  j["modules"][0]["type"] = 1;
  e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/modules/0/type");
  EXPECT_EQ(e.message(), "expected a string, got number 1");
}

TEST(RobotConfigErrors, ModulesAndLinksAreRequiredArrays) {
  InputError e = RobotError({{"links", json::array()}});
  EXPECT_EQ(e.pointer(), "/modules");
  EXPECT_EQ(e.message(), "required key is missing");
  EXPECT_EQ(RobotError({{"modules", {json::object()}}}).pointer(), "/links");
  e = RobotError({{"modules", json::array()}, {"links", json::array()}});
  EXPECT_EQ(e.pointer(), "/modules");
  EXPECT_EQ(e.message(), "expected a non-empty array of modules, got []");
  e = RobotError({{"modules", {json::object()}}, {"links", json::object()}});
  EXPECT_EQ(e.pointer(), "/links");
  EXPECT_EQ(e.message(), "expected an array of links, got {}");
  e = RobotError({{"modules", {3}}, {"links", {json::object()}}});
  EXPECT_EQ(e.pointer(), "/modules/0");
  EXPECT_EQ(e.message(), "expected an object, got number 3");
  e = RobotError({{"modules", {{{"motor", 1}}}}, {"links", {json::object()}}});
  EXPECT_EQ(e.pointer(), "/modules/0/motor");
  EXPECT_THAT(e.message(), HasSubstr("expected an object"));
  e = RobotError(json(42), "/robot");
  EXPECT_EQ(e.pointer(), "/robot");
  EXPECT_EQ(e.message(), "expected an object, got number 42");
}

TEST(RobotConfigErrors, LinkValues) {
  json j = TwoJoints();
  j["links"][1] = {{"mass_kg", 0}};
  InputError e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/links/1/mass_kg");
  EXPECT_EQ(e.message(), "0 is outside [0.001, 1000]");

  j["links"][1] = {{"com_fraction", 1.5}};
  EXPECT_EQ(RobotError(j).pointer(), "/links/1/com_fraction");
  EXPECT_EQ(RobotError(j).message(), "1.5 is outside [0, 1]");

  j["links"][1] = {{"direction", {1, 0}}};
  e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/links/1/direction");
  EXPECT_EQ(e.message(), "expected an array of 3 numbers, got [1,0]");

  j["links"][1] = {{"direction", {1, "0", 0}}};
  EXPECT_EQ(RobotError(j).pointer(), "/links/1/direction/1");

  j["links"][1] = {{"direction", {0, 0, 0}}};
  e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/links/1/direction");
  EXPECT_EQ(e.message(), "the link direction must not be the zero vector");

  j["links"][1] = {{"joint_axis", {0, 0, 0}}};
  EXPECT_EQ(RobotError(j).pointer(), "/links/1/joint_axis");

  j["links"][1] = {{"inertia_kg_m2", {0.1, 0, 0.1}}};
  e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/links/1/inertia_kg_m2/1");
  EXPECT_EQ(e.message(), "0 is outside [1e-09, 100000]");
}

TEST(RobotConfigErrors, TopLevelValues) {
  json j = TwoJoints();
  j["physics_rate_Hz"] = 50;
  InputError e = RobotError(j, "/robot");
  EXPECT_EQ(e.pointer(), "/robot/physics_rate_Hz");
  EXPECT_EQ(e.message(), "50 is outside [100, 100000]");

  j = TwoJoints();
  j["electrical_substeps"] = 0;
  EXPECT_EQ(RobotError(j).pointer(), "/electrical_substeps");
  j["electrical_substeps"] = 2.5;
  EXPECT_EQ(RobotError(j).message(), "expected a whole number, got 2.5");

  j = TwoJoints();
  j["constraint_force_mixing"] = 1e-5;  // soft enough to move accelerations by 2.6x
  EXPECT_EQ(RobotError(j).pointer(), "/constraint_force_mixing");
  EXPECT_EQ(RobotError(j).message(), "1e-05 is outside [0, 1e-06]");
  j["constraint_force_mixing"] = -1e-12;
  EXPECT_EQ(RobotError(j).pointer(), "/constraint_force_mixing");

  j = TwoJoints();
  j["payload_kg"] = -1;
  EXPECT_EQ(RobotError(j).pointer(), "/payload_kg");
  j = TwoJoints();
  j["base_position_m"] = {0, 0};
  EXPECT_EQ(RobotError(j).pointer(), "/base_position_m");
  j = TwoJoints();
  j["name"] = 5;
  EXPECT_EQ(RobotError(j).pointer(), "/name");
}

TEST(RobotConfigErrors, JointRange) {
  json j = TwoJoints();
  j["modules"][1] = {{"min_angle_deg", 10}, {"max_angle_deg", -10}};
  InputError e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/modules/1/max_angle_deg");
  EXPECT_THAT(e.message(), HasSubstr("deg is empty"));
  // The range need not contain the zero pose (URDF arms have joints limited to one side of
  // it; a joint resting at 0 outside its range is the run's error: run_config_test.cc).
  j["modules"][1] = {{"min_angle_deg", 10}};
  EXPECT_NO_THROW(RobotFromJson(j, ""));
  j["modules"][1] = {{"min_angle_deg", -400}};
  e = RobotError(j);
  EXPECT_EQ(e.pointer(), "/modules/1/min_angle_deg");
  EXPECT_EQ(e.message(), "-400 is outside [-360, 360]");
  j["modules"][1] = {{"max_angle_deg", 400}};
  EXPECT_EQ(RobotError(j).pointer(), "/modules/1/max_angle_deg");
}

TEST(RobotConfigErrors, ControllerRateMustDivideThePhysicsRate) {
  json j = TwoJoints();
  j["modules"][1]["controller"] = {{"rate_Hz", 300}};
  InputError e = RobotError(j, "/robot");
  EXPECT_EQ(e.pointer(), "/robot/modules/1/controller/rate_Hz");
  EXPECT_THAT(e.message(), HasSubstr("must divide the physics rate"));
  // Faster than the physics: not a whole number of steps per tick either.
  j["modules"][1]["controller"] = {{"rate_Hz", 2000}};
  EXPECT_EQ(RobotError(j).pointer(), "/modules/1/controller/rate_Hz");
  // 1500 Hz physics, 500 Hz controller: 3 steps per tick.
  j["modules"][1]["controller"] = {{"rate_Hz", 500}};
  j["physics_rate_Hz"] = 1500;
  EXPECT_NO_THROW(RobotFromJson(j, ""));
}

TEST(RobotConfigErrors, ValidateChecksAHandBuiltConfig) {
  RobotConfig r;
  InputError e = ErrorOf([&] { Validate(r, "/robot"); });
  EXPECT_EQ(e.pointer(), "/robot/modules");
  EXPECT_EQ(e.message(), "the robot has no modules");
  r = RobotPreset("mrr-config1");
  r.links.pop_back();
  EXPECT_EQ(ErrorOf([&] { Validate(r, ""); }).pointer(), "/links");
  r = RobotPreset("mrr-config1");
  r.modules[2].controller.rate_Hz = 400;
  EXPECT_EQ(ErrorOf([&] { Validate(r, ""); }).pointer(), "/modules/2/controller/rate_Hz");
}

// Values that would abort the process inside ODE: each is an error naming its field and value, with a physical floor or ceiling (docs/assumptions.md).
TEST(RobotConfigErrors, PhysicalLimitsOfLinksAndBase) {
  const struct {
    json link;
    const char* pointer;
    const char* message;
  } cases[] = {
      {{{"mass_kg", 5e-324}}, "/links/1/mass_kg", "4.94065645841e-324 is outside [0.001, 1000]"},  // was dMassCheck's abort
      {{{"mass_kg", 1e-300}}, "/links/1/mass_kg", "1e-300 is outside [0.001, 1000]"},
      {{{"mass_kg", 1e300}}, "/links/1/mass_kg", "1e+300 is outside [0.001, 1000]"},
      {{{"length_m", 1e300}}, "/links/1/length_m", "1e+300 is outside [0, 10]"},
      {{{"radius_m", 1e-300}}, "/links/1/radius_m", "1e-300 is outside [0.001, 1]"},
      {{{"radius_m", 2}}, "/links/1/radius_m", "2 is outside [0.001, 1]"},
      {{{"joint_axis", {1.7e308, 0, 0}}}, "/links/1/joint_axis/0", "1.7e+308 is outside [-1000000, 1000000]"},
      {{{"direction", {0, -1e200, 0}}}, "/links/1/direction/1", "-1e+200 is outside [-1000000, 1000000]"},
      {{{"direction", {1e-12, 0, 0}}}, "/links/1/direction", "the link direction must not be the zero vector"},
      {{{"inertia_kg_m2", {1e-300, 0.01, 0.01}}}, "/links/1/inertia_kg_m2/0", "1e-300 is outside [1e-09, 100000]"},
      {{{"inertia_kg_m2", {1, 1e-6, 1e-6}}},
       "/links/1/inertia_kg_m2/0",
       "1 kg m^2 exceeds the sum of the other two principal moments (2e-06 kg m^2): no rigid body has these moments"},
      // A ton with the moments of a micromotor's rotor (this one aborted in ODE as a run).
      {{{"mass_kg", 1000}, {"inertia_kg_m2", {1e-9, 1e-9, 1e-9}}},
       "/links/1/inertia_kg_m2/0",
       "1e-09 kg m^2 is below 0.00025 kg m^2, the smallest moment of a 1000 kg link (a disc of radius 1 mm about a "
       "diameter)"},
      // Each value in range, the body they make is not: a 1 g, 1 mm cylinder.
      {{{"mass_kg", 0.001}, {"radius_m", 0.001}, {"length_m", 0}},
       "/links/1/radius_m",
       "link 2's body (a solid cylinder of 0.001 kg, radius 0.001 m and length 0 m): smallest principal moment of "
       "inertia 2.5e-10 kg m^2 is below 1e-09 kg m^2"},
  };
  for (const auto& c : cases) {
    json j = TwoJoints();
    j["links"][1] = c.link;
    const InputError e = RobotError(j);
    EXPECT_EQ(e.count(), 1u) << c.link.dump();
    EXPECT_EQ(e.pointer(), c.pointer) << c.link.dump();
    EXPECT_EQ(e.message(), c.message) << c.link.dump();
  }
  json j = TwoJoints();
  j["base_position_m"] = {0, 1e300, 0};
  EXPECT_EQ(RobotError(j).pointer(), "/base_position_m/1");
  EXPECT_EQ(RobotError(j).message(), "1e+300 is outside [-1000, 1000]");
}

TEST(RobotConfigErrors, ValuesOnTheFloorsAndCeilingsAreAccepted) {
  json j = TwoJoints();
  j["modules"][0]["motor"] = {{"rotor_inertia_kg_m2", 1e-9}};
  j["modules"][0]["drive"] = {{"ratio", 2}};
  j["modules"][1]["drive"] = {{"ratio", 10000}};
  j["links"][0] = {{"mass_kg", 0.001}, {"inertia_kg_m2", {1e-9, 1e-9, 1e-9}}, {"direction", {1e6, -1e6, 0}}};
  j["links"][1] = {{"mass_kg", 1000}, {"length_m", 10}, {"radius_m", 1}, {"inertia_kg_m2", {0.01, 0.02, 0.03}}};
  j["base_position_m"] = {-1000, 1000, 0};
  j["payload_kg"] = 100;
  RobotConfig robot;
  ASSERT_NO_THROW(robot = RobotFromJson(j, ""));
  // ODE takes the bodies; the run may diverge (a failed run), but the process goes on.
  const ArmModel model(robot);
  RunSpec spec;
  spec.duration_s = 0.2;
  EXPECT_NO_THROW(Simulate(model, spec, nullptr));
}

// A robot built in code (or changed by a campaign's tolerance draws) is checked by Validate,
// which ArmModel calls: what ODE would assert on never reaches it.
TEST(RobotConfigErrors, ValidateChecksTheBodiesOdeGets) {
  RobotConfig r = RobotPreset("mrr-config1");
  r.modules[2].motor.rotor_inertia_kg_m2 = 0.5e-9;  // a rotor drawn 50 % under the floor
  InputError e = ErrorOf([&] { Validate(r, ""); });
  EXPECT_EQ(e.pointer(), "/modules/2/motor/rotor_inertia_kg_m2");
  EXPECT_EQ(e.message(), "the rotor body's smallest principal moment of inertia 5e-10 kg m^2 is below 1e-09 kg m^2");
  r = RobotPreset("mrr-config1");
  r.links[0].mass_kg = 5e-324;
  EXPECT_EQ(ErrorOf([&] { Validate(r, ""); }).pointer(), "/links/0/mass_kg");
  r = RobotPreset("mrr-config1");
  r.links[1].joint_axis = {0, 0, 0};
  EXPECT_EQ(ErrorOf([&] { Validate(r, ""); }).message(), "the joint axis must not be the zero vector");
  r = RobotPreset("mrr-config1");
  r.links[2].has_inertia = true;
  r.links[2].inertia_kg_m2 = {1e-300, 1e-300, 1e-300};
  EXPECT_EQ(ErrorOf([&] { Validate(r, ""); }).pointer(), "/links/2/inertia_kg_m2/0");
}

// ---------------------------------------------------------------- round trip

TEST(RobotConfigRoundTrip, PresetsSurviveToJsonAndBack) {
  for (const std::string& name : RobotPresetNames()) {
    const json once = RobotToJson(RobotPreset(name));
    const json twice = RobotToJson(RobotFromJson(once, ""));
    EXPECT_EQ(twice, once) << name;
    EXPECT_EQ(once.at("name"), name);
  }
}

TEST(RobotConfigRoundTrip, CustomRobotWithOverridesAndInertia) {
  json j = TwoJoints();
  j["name"] = "custom arm";
  j["modules"][0] = {{"type", "MRR1"}, {"motor", {{"kt_Nm_per_A", 0.2}}}, {"drive", {{"ratio", 161}}}};
  j["links"][1] = {{"inertia_kg_m2", {0.01, 0.02, 0.03}}, {"com_fraction", 0.3}};
  j["payload_kg"] = 0.25;
  j["gravity_m_s2"] = 0;
  const RobotConfig r = RobotFromJson(j, "");
  const json once = RobotToJson(r);
  EXPECT_EQ(once["modules"][0]["motor"]["kt_Nm_per_A"], 0.2);
  EXPECT_EQ(once["modules"][0]["drive"]["ratio"], 161.0);
  EXPECT_FALSE(once["links"][0].contains("inertia_kg_m2"));
  EXPECT_EQ(once["links"][1]["inertia_kg_m2"], json({0.01, 0.02, 0.03}));
  const json twice = RobotToJson(RobotFromJson(once, ""));
  EXPECT_EQ(twice, once);
  // Through text as well, as a campaign record would store it.
  EXPECT_EQ(RobotToJson(RobotFromJson(ParseJsonText(once.dump(2), "robot.json"), "")), once);
}

// ---------------------------------------------------------------- ripple (optional group)

TEST(RobotConfigRipple, AbsentIsOffAndNotWrittenGivenIsOnWithDefaults) {
  json j = TwoJoints();
  RobotConfig r = RobotFromJson(j, "");
  EXPECT_FALSE(r.modules[0].ripple.enabled);
  EXPECT_FALSE(RobotToJson(r)["modules"][0].contains("ripple"));  // campaign.json as before
  j["modules"][1]["ripple"] = {{"cogging_Nm", 0.02}, {"phase_2x_deg", 45}};
  r = RobotFromJson(j, "");
  EXPECT_FALSE(r.modules[0].ripple.enabled);
  ASSERT_TRUE(r.modules[1].ripple.enabled);
  EXPECT_EQ(r.modules[1].ripple.cogging_Nm, 0.02);
  EXPECT_EQ(r.modules[1].ripple.phase_2x_deg, 45);
  EXPECT_EQ(r.modules[1].ripple.kinematic_error_2x_arcmin, RippleParams{}.kinematic_error_2x_arcmin);
  const json written = RobotToJson(r);
  EXPECT_EQ(written["modules"][1]["ripple"]["cogging_Nm"], 0.02);
  EXPECT_EQ(written["modules"][1]["ripple"].size(), 8u);
  EXPECT_EQ(RobotToJson(RobotFromJson(written, "")), written);  // and back
  j["modules"][1]["ripple"] = json::object();  // empty: on, every default
  EXPECT_TRUE(RobotFromJson(j, "").modules[1].ripple.enabled);
}

TEST(RobotConfigRipple, BadValuesNameTheirPointerAndValue) {
  const struct {
    json group;
    const char* key;
    const char* message;
  } cases[] = {
      {{{"kinematic_error_2x_arcmin", 11}}, "kinematic_error_2x_arcmin", "11 is outside [0, 10]"},
      {{{"kinematic_error_1x_arcmin", -0.1}}, "kinematic_error_1x_arcmin", "-0.1 is outside [0, 10]"},
      {{{"phase_2x_deg", 400}}, "phase_2x_deg", "400 is outside [-360, 360]"},
      {{{"phase_1x_deg", "0"}}, "phase_1x_deg", "expected a number, got string \"0\""},
      {{{"drive_stiffness_Nm_per_rad", -1}}, "drive_stiffness_Nm_per_rad", "-1 is outside [0, 10000000]"},
      {{{"drive_stiffness_Nm_per_rad", 1e300}}, "drive_stiffness_Nm_per_rad", "1e+300 is outside [0, 10000000]"},
      {{{"cogging_Nm", -0.01}}, "cogging_Nm", "-0.01 is outside [0, 10]"},
      {{{"cogging_Nm", true}}, "cogging_Nm", "expected a number, got boolean true"},
      {{{"cogging_periods_per_rev", 0}}, "cogging_periods_per_rev", "0 is outside [1, 1000]"},
      {{{"cogging_periods_per_rev", 18.5}}, "cogging_periods_per_rev", "expected a whole number, got 18.5"},
      {{{"cogging_phase_deg", -361}}, "cogging_phase_deg", "-361 is outside [-360, 360]"},
  };
  for (const auto& c : cases) {
    json j = TwoJoints();
    j["modules"][1]["ripple"] = c.group;
    const InputError e = RobotError(j, "/robot");
    EXPECT_EQ(e.pointer(), std::string("/robot/modules/1/ripple/") + c.key) << c.key;
    EXPECT_EQ(e.message(), c.message) << c.key;
  }
  json j = TwoJoints();
  j["modules"][0]["ripple"] = {{"coging_Nm", 0.01}};
  EXPECT_EQ(RobotError(j).pointer(), "/modules/0/ripple/coging_Nm");
  for (const json& not_object : {json(true), json(nullptr), json(0.3), json::array()}) {
    j["modules"][0]["ripple"] = not_object;
    EXPECT_EQ(RobotError(j).pointer(), "/modules/0/ripple") << not_object.dump();
    EXPECT_THAT(RobotError(j).message(), HasSubstr("expected an object")) << not_object.dump();
  }
}

// A robot built or changed in code: Validate checks the same ranges (NaN and infinity too).
TEST(RobotConfigRipple, ValidateChecksRippleBuiltInCode) {
  RobotConfig r = RobotPreset("mrr-config1");
  r.modules[2].ripple.cogging_Nm = -1;  // off: not checked, not used
  EXPECT_NO_THROW(Validate(r, ""));
  r.modules[2].ripple.enabled = true;
  EXPECT_EQ(ErrorOf([&] { Validate(r, "/robot"); }).pointer(), "/robot/modules/2/ripple/cogging_Nm");
  r.modules[2].ripple.cogging_Nm = std::nan("");
  EXPECT_THAT(ErrorOf([&] { Validate(r, ""); }).text(), HasSubstr("/modules/2/ripple/cogging_Nm"));
  r.modules[2].ripple.cogging_Nm = 0.01;
  r.modules[2].ripple.drive_stiffness_Nm_per_rad = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ErrorOf([&] { Validate(r, ""); }).pointer(), "/modules/2/ripple/drive_stiffness_Nm_per_rad");
  r.modules[2].ripple.drive_stiffness_Nm_per_rad = 13000;
  r.modules[2].ripple.cogging_periods_per_rev = 2.5;
  EXPECT_EQ(ErrorOf([&] { Validate(r, ""); }).message(), "expected a whole number, got 2.5");
}

// ---------------------------------------------------------------- gearbox group

TEST(RobotConfigGearbox, AbsentIsOffAndNotWrittenAThermalTypeIsOnAndNullSwitchesItOff) {
  const RobotConfig plain = RobotFromJson(TwoJoints(), "");
  EXPECT_FALSE(plain.modules[0].gearbox.present);
  EXPECT_FALSE(RobotToJson(plain)["modules"][0].contains("gearbox"));
  json j = TwoJoints();
  j["modules"][0] = {{"type", "industrial-large-thermal"}};
  j["modules"][1] = {{"type", "industrial-small-thermal"}, {"gearbox", nullptr}};
  const RobotConfig r = RobotFromJson(j, "");
  EXPECT_TRUE(r.modules[0].gearbox.present);
  EXPECT_EQ(r.modules[0].gearbox.vogel_B_K, 277);
  EXPECT_FALSE(r.modules[1].gearbox.present);
  const json written = RobotToJson(r);
  EXPECT_EQ(written["modules"][0]["gearbox"]["load_friction_backdriven"], 0.1);
  // What it writes reads back the same.
  EXPECT_EQ(RobotToJson(RobotFromJson(written, "")), written);
  j["modules"][1] = {{"gearbox", {{"load_friction_driving", 0.07}}}};
  EXPECT_TRUE(RobotFromJson(j, "").modules[1].gearbox.present);
  EXPECT_EQ(RobotFromJson(j, "").modules[1].gearbox.load_friction_driving, 0.07);
}

TEST(RobotConfigGearbox, EveryBadValueNamesItsPointerAndValue) {
  json j = TwoJoints();
  j["modules"][0]["gearbox"] = {{"thermal_resistance_K_per_W", 0},     {"thermal_time_constant_s", -5},
                                {"vogel_C_C", 10},                      {"coulomb_exponent", "half"},
                                {"sensor_offset_Nm_per_K", 7},          {"warm_copper_loss_W", -1},
                                {"reference_C", nullptr},               {"thermal_resistanse_K_per_W", 1}};
  j["modules"][1]["gearbox"] = 3;
  EXPECT_THAT(ErrorTexts(RobotError(j, "/robot")),
              ElementsAre("/robot/modules/0/gearbox/thermal_resistanse_K_per_W: unknown key \"thermal_resistanse_K_per_W\"; did you mean \"thermal_resistance_K_per_W\"?",
                          "/robot/modules/0/gearbox/thermal_resistance_K_per_W: 0 must be greater than 0",
                          "/robot/modules/0/gearbox/thermal_time_constant_s: -5 must be greater than 0",
                          "/robot/modules/0/gearbox/reference_C: expected a number, got null null",
                          "/robot/modules/0/gearbox/vogel_C_C: 10 is outside [-273.15, -60]",
                          "/robot/modules/0/gearbox/coulomb_exponent: expected a number, got string \"half\"",
                          "/robot/modules/0/gearbox/sensor_offset_Nm_per_K: 7 is outside [-1, 1]",
                          "/robot/modules/0/gearbox/warm_copper_loss_W: -1 is outside [0, 10000]",
                          "/robot/modules/1/gearbox: expected an object (the gearbox's thermal, lubricant, load-friction and "
                          "sensor-drift parameters) or null (off), got number 3"));
}

TEST(RobotConfigGearbox, ValidateChecksARobotBuiltInCodeAndTheCrossFieldLimits) {
  RobotConfig r = RobotPreset("mrr-config1");
  r.modules[2].gearbox.present = true;
  r.modules[2].gearbox.load_friction_backdriven = std::nan("");
  InputError e = ErrorOf([&] { Validate(r, "/robot"); });
  EXPECT_EQ(e.pointer(), "/robot/modules/2/gearbox/load_friction_backdriven");
  r.modules[2].gearbox.load_friction_backdriven = 0.8;  // + mesh loss 0.24: locks
  e = ErrorOf([&] { Validate(r, "/robot"); });
  EXPECT_EQ(e.pointer(), "/robot/modules/2/gearbox/load_friction_backdriven");
  EXPECT_THAT(e.message(), HasSubstr("the gear would lock under its own load"));
  r.modules[2].gearbox.load_friction_backdriven = 0.1;
  r.modules[2].gearbox.vogel_B_K = 3000;
  e = ErrorOf([&] { Validate(r, "/robot"); });
  EXPECT_EQ(e.pointer(), "/robot/modules/2/gearbox/vogel_B_K");
  r.modules[2].gearbox.vogel_B_K = 277;
  r.modules[2].gearbox.thermal_time_constant_s = 0.05;  // 50 physics steps
  e = ErrorOf([&] { Validate(r, "/robot"); });
  EXPECT_EQ(e.pointer(), "/robot/modules/2/gearbox/thermal_time_constant_s");
  r.modules[2].gearbox.thermal_time_constant_s = 100;
  r.modules[2].gearbox.warm_friction_loss_W = 100;  // 2 K/W: 200 K above ambient
  e = ErrorOf([&] { Validate(r, "/robot"); });
  EXPECT_EQ(e.pointer(), "/robot/modules/2/gearbox/warm_friction_loss_W");
  EXPECT_THAT(e.message(), HasSubstr("holds the winding 0 K and the gearbox 200 K above ambient: at most 150 K"));
  r.modules[2].gearbox.warm_friction_loss_W = 0;
  r.modules[2].gearbox.winding_coupling_W_per_K = 100;  // R_w 11 K/W: 900 s / 1101
  EXPECT_NO_THROW(Validate(r, "/robot"));
  r.modules[2].motor.thermal_time_constant_s = 10;
  e = ErrorOf([&] { Validate(r, "/robot"); });
  EXPECT_EQ(e.pointer(), "/robot/modules/2/gearbox/winding_coupling_W_per_K");
}

}  // namespace
}  // namespace armfault
