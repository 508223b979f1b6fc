// Randomized confounders (variation/confounders): every draw inside its range and a valid
// plant, the lubricant's steepness as asked, one draw per unit, bad input named.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>

#include "campaigns/spec/campaign.h"
#include "campaigns/spec/confounders.h"
#include "core/plant/parts/gear_thermal.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;

json RandomBench() {
  std::ifstream in(std::string(ARMFAULT_SOURCE_DIR) + "/campaigns/files/confounders-random-3j.json");
  return json::parse(in);
}

Campaign Parse(const json& j) {
  return CampaignFromJson(j, std::string(ARMFAULT_SOURCE_DIR) + "/campaigns/files/c.json",
                          std::string(ARMFAULT_SOURCE_DIR) + "/campaigns/files");
}

TEST(RandomizedConfounders, EveryDrawLiesInItsRangeAndIsAValidPlant) {
  const Campaign c = Parse(RandomBench());
  const ConfounderRanges r = DocumentedConfounderRanges();
  std::set<std::string> laws;
  std::set<int> units;
  int cold_starts = 0, runs = 0;
  for (long i = 0; i < CaseCount(c); ++i) {
    const CaseSpec cs = CaseAt(c, i);
    ASSERT_EQ(cs.confounder_draws.size(), 3u);
    units.insert(cs.unit);
    ++runs;
    if (!cs.warm_start) ++cold_starts;
    const RobotConfig robot = CaseRobot(c, cs);
    Validate(robot, "");  // no draw leaves the plant's accepted values
    const GearboxParams& g0 = robot.modules[0].gearbox;
    laws.insert(g0.vogel_C_C == -273.15 ? "arrhenius" : "vogel");
    // The viscous part's cold-to-warm ratio is the drawn one, whatever the law.
    const double ratio = LubricantFactor(g0, -10.0) / LubricantFactor(g0, 40.0);
    EXPECT_GE(ratio, r.cold_to_warm_ratio.low - 1e-9);
    EXPECT_LE(ratio, r.cold_to_warm_ratio.high + 1e-9);
    for (const ModuleParams& m : robot.modules) {
      const GearboxParams& g = m.gearbox;
      EXPECT_EQ(g.vogel_B_K, g0.vogel_B_K);  // one grease in the whole unit
      EXPECT_EQ(g.reference_C, g0.reference_C);
      EXPECT_GE(g.coulomb_exponent, r.coulomb_exponent.low);
      EXPECT_LE(g.coulomb_exponent, r.coulomb_exponent.high);
      EXPECT_GE(g.load_friction_backdriven, r.load_friction_backdriven.low);
      EXPECT_LE(g.load_friction_backdriven, r.load_friction_backdriven.high);
      const double drift = std::fabs(g.sensor_offset_Nm_per_K) / m.torque_sensor.full_scale_Nm;
      EXPECT_GE(drift, r.sensor_offset_fs_per_K.low - 1e-15);
      EXPECT_LE(drift, r.sensor_offset_fs_per_K.high + 1e-15);
      EXPECT_TRUE(m.ripple.enabled);
      EXPECT_LE(m.ripple.kinematic_error_2x_arcmin, r.kinematic_error_2x_arcmin.high);
      EXPECT_GE(g.thermal_time_constant_s, 1500 * r.thermal_time_constant_factor.low - 1e-9);
      EXPECT_LE(g.thermal_time_constant_s, 1500 * r.thermal_time_constant_factor.high + 1e-9);
    }
  }
  EXPECT_EQ(laws.size(), 2u);    // both law forms among the 20 units
  EXPECT_EQ(units.size(), 20u);
  EXPECT_GT(cold_starts, runs / 3);  // half the runs cold, within the draw's scatter
  EXPECT_LT(cold_starts, 2 * runs / 3);
}

TEST(RandomizedConfounders, AUnitsRunsShareItsDrawAndOtherDrawsDoNotMove) {
  const Campaign c = Parse(RandomBench());
  json plain = RandomBench();
  plain["variation"].erase("confounders");
  const Campaign p = Parse(plain);
  std::map<int, json> by_unit;
  for (long i = 0; i < CaseCount(c); ++i) {
    const CaseSpec cs = CaseAt(c, i);
    const json drawn = cs.VariationJson().at("confounders");
    auto [it, fresh] = by_unit.emplace(cs.unit, drawn);
    if (!fresh) {
      EXPECT_EQ(it->second, drawn) << cs.run_id;
    }
    // the same run without the key draws the same fault, payload, tolerances, ambient and start
    json without = cs.VariationJson();
    without.erase("confounders");
    const CaseSpec ps = CaseAt(p, i);
    EXPECT_EQ(without, ps.VariationJson()) << cs.run_id;
    EXPECT_EQ(cs.fault, ps.fault);
  }
}

TEST(RandomizedConfounders, BadRangesAndPlainDrivesAreNamed) {
  struct Case {
    json value;
    std::string pointer, text;
  };
  const std::vector<Case> cases = {
      {"catalogue", "/variation/confounders", "unknown confounder preset \"catalogue\""},
      {{{"coulomb_exponent", {0.9, 0.3}}}, "/variation/confounders/coulomb_exponent", "low end 0.9 above high end 0.3"},
      {{{"cold_to_warm_ratio", {0.5, 3}}}, "/variation/confounders/cold_to_warm_ratio/0", "0.5"},
      {{{"vogel_C_C", 3}}, "/variation/confounders/vogel_C_C", "expected a range [low, high]"},
      {{{"preset", "documented"}, {"grease", 1}}, "/variation/confounders/grease", "unknown key"},
      {{{"arrhenius_fraction", 2}}, "/variation/confounders/arrhenius_fraction", "2"},
  };
  for (const Case& k : cases) {
    json j = RandomBench();
    j["variation"]["confounders"] = k.value;
    const std::string e = ErrorOf([&] { Parse(j); }).what();
    EXPECT_THAT(e, HasSubstr(k.pointer)) << k.value.dump();
    EXPECT_THAT(e, HasSubstr(k.text)) << k.value.dump();
  }
  json plain = RandomBench();
  plain["robot"] = "mrr-config1";
  const std::string e = ErrorOf([&] { Parse(plain); }).what();
  EXPECT_THAT(e, HasSubstr("/variation/confounders"));
  EXPECT_THAT(e, HasSubstr("joint 1 has none"));
}

}  // namespace
}  // namespace armfault
