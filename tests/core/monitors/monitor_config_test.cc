// The monitor's settings: every tuned constant of its estimators is a named, range-checked
// setting that round-trips, and a bad one names its field, its value and the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/monitors/monitor_config.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;

TEST(MonitorSettings, EveryEstimatorConstantIsASettingThatRoundTrips) {
  MonitorConfig c;
  c.max_lubricant_slope_per_K = 0.015;
  c.friction_envelope_blocks = 90;
  c.winding_reading_error_K = 3.5;
  c.copper_resistance_per_K = 0.0039;
  const json written = MonitorConfigToJson(c);
  EXPECT_EQ(written["max_lubricant_slope_per_K"], 0.015);
  EXPECT_EQ(written["friction_envelope_blocks"], 90);
  EXPECT_EQ(written["winding_reading_error_K"], 3.5);
  EXPECT_EQ(MonitorConfigToJson(MonitorConfigFromJson(written, "", "m.json")), written);
  // The defaults are the shipped monitor's: the steepest lubricant slope is ln 3 / 50 K.
  EXPECT_DOUBLE_EQ(MonitorConfig().max_lubricant_slope_per_K, std::log(3.0) / 50.0);
  EXPECT_EQ(MonitorConfigFromJson(json::object(), "", "m.json").sensor_zero_time_constant_s, 120.0);
}

TEST(MonitorSettings, AConstantOutOfItsRangeNamesFieldValueAndFile) {
  const InputError copper =
      ErrorOf([] { MonitorConfigFromJson(json{{"copper_resistance_per_K", 0}}, "/monitor", "c.json"); });
  EXPECT_EQ(copper.source(), "c.json");
  EXPECT_EQ(copper.pointer(), "/monitor/copper_resistance_per_K");
  EXPECT_THAT(copper.message(), HasSubstr("0"));
  const InputError blocks =
      ErrorOf([] { MonitorConfigFromJson(json{{"friction_envelope_blocks", 0}}, "/monitor", "c.json"); });
  EXPECT_EQ(blocks.pointer(), "/monitor/friction_envelope_blocks");
  const InputError fraction =
      ErrorOf([] { MonitorConfigFromJson(json{{"rail_jump_fraction", 1.5}}, "/monitor", "c.json"); });
  EXPECT_EQ(fraction.pointer(), "/monitor/rail_jump_fraction");
  EXPECT_THAT(fraction.message(), HasSubstr("1.5"));
  const InputError type =
      ErrorOf([] { MonitorConfigFromJson(json{{"shown_friction_blocks", 2.5}}, "/monitor", "c.json"); });
  EXPECT_EQ(type.pointer(), "/monitor/shown_friction_blocks");
}

TEST(MonitorSettings, ConstantsThatBoundEachOtherAreCheckedTogether) {
  // The shown friction is the median of blocks the envelope's ring must hold.
  const InputError shown = ErrorOf([] {
    MonitorConfigFromJson(json{{"friction_envelope_blocks", 30}, {"shown_friction_blocks", 40}}, "/monitor", "c.json");
  });
  EXPECT_EQ(shown.pointer(), "/monitor/shown_friction_blocks");
  EXPECT_THAT(shown.message(), HasSubstr("40"));
  const InputError first =
      ErrorOf([] { MonitorConfigFromJson(json{{"min_shown_friction_blocks", 21}}, "/monitor", "c.json"); });
  EXPECT_EQ(first.pointer(), "/monitor/min_shown_friction_blocks");
  // The warm side's slope is no steeper than the steepest.
  const InputError slope = ErrorOf([] {
    MonitorConfigFromJson(json{{"min_lubricant_slope_per_K", 0.03}}, "/monitor", "c.json");
  });
  EXPECT_EQ(slope.pointer(), "/monitor/min_lubricant_slope_per_K");
  EXPECT_THAT(slope.message(), HasSubstr("0.03"));
  // Consistent values pass, and a field out of its own range is reported once.
  EXPECT_NO_THROW(MonitorConfigFromJson(json{{"friction_envelope_blocks", 30}, {"shown_friction_blocks", 30}}, "", "c.json"));
  const InputError once = ErrorOf([] { MonitorConfigFromJson(json{{"shown_friction_blocks", 20000}}, "", "c.json"); });
  EXPECT_EQ(once.errors().size(), 1u);
}

}  // namespace
}  // namespace armfault

namespace armfault {
namespace {

// The friction reference is one of two; a misspelt one is named with the nearest, and the arm
// model's constants are range-checked like every other.
TEST(MonitorSettings, AnUnknownFrictionReferenceIsNamedWithTheNearest) {
  EXPECT_EQ(MonitorConfigFromJson(json{{"friction_reference", "arm_model"}}, "", "m.json").friction_reference,
            kArmFrictionModel);
  const InputError wrong =
      ErrorOf([] { MonitorConfigFromJson(json{{"friction_reference", "arm_modle"}}, "/monitor", "c.json"); });
  EXPECT_EQ(wrong.source(), "c.json");
  EXPECT_EQ(wrong.pointer(), "/monitor/friction_reference");
  EXPECT_THAT(wrong.message(), HasSubstr("\"arm_modle\""));
  EXPECT_THAT(wrong.message(), HasSubstr("rules, arm_model"));
  EXPECT_EQ(wrong.hint(), "did you mean \"arm_model\"?");
  const InputError type = ErrorOf([] { MonitorConfigFromJson(json{{"friction_reference", 1}}, "/monitor", "c.json"); });
  EXPECT_EQ(type.pointer(), "/monitor/friction_reference");
  const InputError error =
      ErrorOf([] { MonitorConfigFromJson(json{{"friction_model_error", 0}}, "/monitor", "c.json"); });
  EXPECT_EQ(error.pointer(), "/monitor/friction_model_error");
  MonitorConfig c;
  c.friction_reference = "table";
  EXPECT_THROW(Validate(c, "/monitor", "c.json"), InputError);
}

}  // namespace
}  // namespace armfault
