#include "reports/trace_csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

namespace armfault {
namespace {

TEST(TraceCsvTest, HasEveryColumnThePlantIssueAsksForPerJoint) {
  const std::vector<std::string> columns = TraceCsvColumns(3);
  EXPECT_EQ(columns.front(), "t");
  for (int j = 1; j <= 3; ++j) {
    for (const char* name : {"q_ref", "q", "qd", "tau_sensor", "tau_true", "i_cmd", "i_phase_a", "i_supply", "v_bus",
                             "brake", "p_supply", "p_copper", "p_inverter", "p_friction", "p_mech_out"}) {
      EXPECT_THAT(columns, ::testing::Contains(std::string(name) + "_" + std::to_string(j)));
    }
  }
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
  EXPECT_THAT(header, ::testing::StartsWith("t,q_ref_1,q_1,qd_1,"));
  EXPECT_THAT(row, ::testing::StartsWith("0.002,0.1,0,0,0,0,-2.5,"));
  // Shortest round-trip formatting: values read back exactly.
  EXPECT_EQ(std::count(row.begin(), row.end(), ','), std::count(header.begin(), header.end(), ','));
}

}  // namespace
}  // namespace armfault
