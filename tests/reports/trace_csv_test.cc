#include "reports/trace_csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

#include <nlohmann/json.hpp>

#include "campaigns/data/export.h"

namespace armfault {
namespace {

TEST(TraceCsvTest, HasEveryColumnThePlantIssueAsksForPerJoint) {
  const std::vector<std::string> columns = TraceCsvColumns(3);
  EXPECT_EQ(columns.front(), "t_s");
  for (int j = 1; j <= 3; ++j) {
    for (const char* name : {"q_ref_rad", "q_rad", "qd_rad_s", "tau_sensor_Nm", "tau_true_Nm", "i_cmd_A", "i_phase_a_A",
                             "i_supply_A", "v_bus_meas_V", "brake_engaged", "p_supply_W", "p_copper_W", "p_inverter_W",
                             "p_friction_W", "p_mech_out_W"}) {
      EXPECT_THAT(columns, ::testing::Contains(std::string(name) + "_j" + std::to_string(j)));
    }
  }
}

// One naming scheme: a signal the monitor reads has the same column name in a trace as in an
// export's runs/*.csv.gz, and the same unit and source in channels.json.
TEST(TraceCsvTest, SharesTheExportsNamesUnitsAndSourcesForWhatAMonitorReads) {
  const std::vector<Channel> trace = TraceCsvChannels(2);
  const std::vector<Channel> exported = MonitorSignalChannels(2);
  int shared = 0;
  for (const Channel& e : exported) {
    for (const Channel& t : trace) {
      if (t.Name() != e.Name()) continue;
      ++shared;
      EXPECT_EQ(t.unit, e.unit) << t.Name();
      EXPECT_EQ(t.source, e.source) << t.Name();
      EXPECT_EQ(t.joint, e.joint) << t.Name();
    }
  }
  // All but qd_ref_rad_s and winding_temp_C, which the trace does not write: t_s + 2 x 7.
  EXPECT_EQ(shared, 1 + 2 * 7);
  for (const Channel& t : trace) {
    EXPECT_TRUE(t.source == "sensor" || t.source == "truth") << t.Name();
    EXPECT_FALSE(t.unit.empty()) << t.Name();
  }
  const nlohmann::json j = nlohmann::json::parse(ChannelsJson(trace, "t.csv"));
  EXPECT_EQ(j["file"], "t.csv");
  ASSERT_EQ(j["channels"].size(), trace.size());
  EXPECT_EQ(j["channels"][0]["name"], "t_s");
  EXPECT_TRUE(j["channels"][0]["joint"].is_null());
  EXPECT_EQ(j["channels"][7]["name"], "tau_true_Nm_j1");
  EXPECT_EQ(j["channels"][7]["unit"], "N m");
  EXPECT_EQ(j["channels"][7]["source"], "truth");
  EXPECT_EQ(j["channels"][7]["joint"], 1);
  EXPECT_EQ(ChannelsSidecarPath("out/trace.csv"), "out/trace.channels.json");
  EXPECT_EQ(ChannelsSidecarPath("x"), "x.channels.json");
}

TEST(TraceCsvTest, WritesHeaderAndOneExactRowPerTick) {
  std::ostringstream out;
  TraceCsvWriter writer(&out, 1);
  std::vector<JointTick> joints(1);
  joints[0].signals.q_ref_rad = 0.1;
  joints[0].signals.tau_sensor_Nm = -2.5;
  joints[0].brake_engaged = true;
  writer.Write(Tick{0.002, &joints});
  std::istringstream in(out.str());
  std::string header, row, extra;
  std::getline(in, header);
  std::getline(in, row);
  EXPECT_FALSE(std::getline(in, extra));
  EXPECT_THAT(header, ::testing::StartsWith("t_s,q_ref_rad_j1,q_rad_j1,qd_rad_s_j1,"));
  EXPECT_THAT(row, ::testing::StartsWith("0.002,0.1,0,0,0,0,-2.5,"));
  // Shortest round-trip formatting: values read back exactly.
  EXPECT_EQ(std::count(row.begin(), row.end(), ','), std::count(header.begin(), header.end(), ','));
}

}  // namespace
}  // namespace armfault
