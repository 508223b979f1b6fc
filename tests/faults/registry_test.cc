// The family table's magnitude ranges (faults/registry.cc): what the loader accepts at and
// beyond each bound, and that docs/faults.md states the same range for every family.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/plant/robot/robot_config.h"
#include "faults/fault.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;

// A fault of `family` on joint 3 with its magnitude key at `value` (and the keys it requires).
json FaultWith(const std::string& family, double value) {
  json spec = {{"family", family}, {"joint", 3}, {FaultMagnitudeKey(family), value}};
  if (family == "inverter_short") spec["kind"] = "phase_phase";
  return spec;
}

bool Accepted(const std::string& family, double value) {
  try {
    MakeFault(FaultWith(family, value), "/faults/0", RobotPreset("mrr-config1"));
    return true;
  } catch (const InputError&) {
    return false;
  }
}

TEST(FaultMagnitudeRange, TheLoaderAcceptsExactlyTheStatedRange) {
  int families_with_range = 0;
  for (const std::string& family : FaultFamilyNames()) {
    FaultMagnitudeRange r;
    if (!FaultMagnitudeRangeOf(family, &r)) continue;
    ++families_with_range;
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(Accepted(family, r.min), !r.min_exclusive) << family;
    EXPECT_TRUE(Accepted(family, r.max)) << family;
    EXPECT_FALSE(Accepted(family, std::nextafter(r.min, -inf))) << family;
    EXPECT_FALSE(Accepted(family, std::nextafter(r.max, inf))) << family;
    EXPECT_TRUE(Accepted(family, std::nextafter(r.max, -inf))) << family;
    if (r.min < 0 && r.max > 0) {
      EXPECT_EQ(Accepted(family, 0.0), !r.zero_excluded) << family;
    }
  }
  EXPECT_EQ(families_with_range, 6);  // all but torque_sensor_stuck (a lead, no magnitude)
}

TEST(FaultMagnitudeRange, ErrorsNameThePointerAndTheValue) {
  const RobotConfig robot = RobotPreset("mrr-config1");
  InputError e = ErrorOf([&] { MakeFault(FaultWith("friction_increase", 101), "/faults/0", robot); });
  EXPECT_EQ(e.pointer(), "/faults/0/friction_factor");
  EXPECT_EQ(e.message(), "friction_increase: 101 is outside [1, 100]");
  e = ErrorOf([&] { MakeFault(FaultWith("kt_degradation", 0), "/faults/0", robot); });
  EXPECT_EQ(e.message(), "kt_degradation: 0 must be greater than 0");
  e = ErrorOf([&] { MakeFault(FaultWith("torque_sensor_drift", 0), "/faults/0", robot); });
  EXPECT_EQ(e.pointer(), "/faults/0/drift_Nm_per_s");
  EXPECT_EQ(e.message(), "torque_sensor_drift: 0 is no change");
  // An optional magnitude keeps its default when absent.
  EXPECT_NO_THROW(MakeFault({{"family", "inverter_short"}, {"joint", 3}, {"kind", "switch"}}, "/faults/0", robot));
}

TEST(FaultMagnitudeRange, DocsFaultsMdStatesEachFamilysRange) {
  std::ifstream in(std::string(ARMFAULT_SOURCE_DIR) + "/docs/faults.md");
  ASSERT_TRUE(in) << "docs/faults.md";
  std::stringstream text;
  text << in.rdbuf();
  for (const std::string& family : FaultFamilyNames()) {
    const std::string row_start = "| `" + family + "` |";
    const size_t at = text.str().find(row_start);
    ASSERT_NE(at, std::string::npos) << family << " has no row in the families table";
    const std::string row = text.str().substr(at, text.str().find('\n', at) - at);
    const std::string range = FaultMagnitudeRangeText(family);
    if (!range.empty()) {
      EXPECT_THAT(row, HasSubstr("| " + range)) << family;
    }
  }
  EXPECT_EQ(FaultMagnitudeRangeText("torque_sensor_drift"), "\u2212100 \u2264 `drift_Nm_per_s` \u2264 100, \u2260 0");
  EXPECT_EQ(FaultMagnitudeRangeText("kt_degradation"), "0 < `kt_factor` \u2264 1");
  EXPECT_EQ(FaultMagnitudeRangeText("torque_sensor_stuck"), "");
}

TEST(FaultMagnitudeRange, TheSchemaStatesEachFamilysRange) {
  std::ifstream in(std::string(ARMFAULT_SOURCE_DIR) + "/campaigns/spec/campaign.schema.json");
  ASSERT_TRUE(in);
  const json schema = json::parse(in);
  for (const std::string& family : FaultFamilyNames()) {
    FaultMagnitudeRange r;
    if (!FaultMagnitudeRangeOf(family, &r)) continue;
    const json& number = schema.at("$defs").at("sweep_" + family + "_" + FaultMagnitudeKey(family)).at("anyOf").at(0);
    EXPECT_EQ(number.at(r.min_exclusive ? "exclusiveMinimum" : "minimum").get<double>(), r.min) << family;
    EXPECT_EQ(number.at("maximum").get<double>(), r.max) << family;
    EXPECT_EQ(number.contains("not"), r.zero_excluded) << family;
  }
}

// The families that read the torque sensor are errors on a joint without one.
TEST(FaultRegistry, SensorFamiliesNeedTheJointsTorqueSensor) {
  RobotConfig robot = RobotPreset("mrr-config1");
  robot.modules[2].torque_sensor.present = false;
  const json stuck = {{"family", "torque_sensor_stuck"}, {"joint", 3}, {"lead", "supply"}};
  const InputError e = ErrorOf([&] { MakeFault(stuck, "/faults/0", robot); });
  EXPECT_EQ(e.pointer(), "/faults/0/joint");
  EXPECT_EQ(e.message(), "torque_sensor_stuck: joint 3 has no torque sensor (robot mrr-config1): this family needs one");
  EXPECT_THAT(ErrorOf([&] { MakeFault(FaultWith("torque_sensor_drift", 1.0), "/faults/0", robot); }).message(),
              HasSubstr("joint 3 has no torque sensor"));
  // The other families, and the sensor families on a joint that has one, are fine.
  EXPECT_NE(MakeFault(FaultWith("kt_degradation", 0.8), "/faults/0", robot), nullptr);
  json on_joint_2 = stuck;
  on_joint_2["joint"] = 2;
  EXPECT_NE(MakeFault(on_joint_2, "/faults/0", robot), nullptr);
}

}  // namespace
}  // namespace armfault
