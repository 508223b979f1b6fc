// results.csv: one flat row per run, quoted where a field holds a comma or a quote, empty where
// results.jsonl has null.
#include "campaigns/running/results_csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/base/csv.h"

namespace armfault {
namespace {

size_t Commas(const std::string& s) {
  size_t n = 0;
  bool quoted = false;
  for (char c : s) {
    if (c == '"') quoted = !quoted;
    n += c == ',' && !quoted;
  }
  return n;
}

TEST(ResultsCsv, QuotesRunIdsWithCommasAndLeavesNullsEmpty) {
  RunRecord r;
  r.case_index = 7;
  r.run_id = "p2p/friction_increase#1/friction_factor=1.5,onset_s=U[1,3]/j2/r0";
  r.trajectory = "p2p";
  r.group = "friction_increase friction_factor=1.5 joint=2";
  r.family = "friction_increase";
  r.joint = 2;
  r.onset_s = 1.25;
  r.magnitude_key = "friction_factor";
  r.magnitude = 1.5;
  r.seed = 42;
  r.variation = {{"unit", 3}, {"ambient_C", 31.5}};
  r.effect = {{"took_effect", true}};
  r.detected = true;
  r.detection_time_s = 2.0;
  r.latency_s = 0.75;
  r.isolated_family = "friction_increase";
  r.isolated_joint = 2;
  r.magnitude_name = "friction_factor";
  r.magnitude_estimate = 1.48;
  r.confidence = 0.99;
  r.failure_reason = "said \"no\"";
  const std::string row = ResultsCsvRow(r);
  EXPECT_EQ(row,
            "7,\"p2p/friction_increase#1/friction_factor=1.5,onset_s=U[1,3]/j2/r0\",p2p,"
            "friction_increase friction_factor=1.5 joint=2,friction_increase,2,1.25,friction_factor,1.5,42,0,3,31.5,ok,"
            "\"said \"\"no\"\"\",true,true,false,2,0.75,friction_increase,2,true,friction_factor,1.48,0.99,1,\n");
  EXPECT_EQ(Commas(row), Commas(ResultsCsvHeader()));

  RunRecord healthy;
  healthy.run_id = "exp1/healthy/0";
  healthy.trajectory = "exp1";
  const std::string h = ResultsCsvRow(healthy);
  EXPECT_EQ(Commas(h), Commas(ResultsCsvHeader()));
  EXPECT_EQ(h, "0,exp1/healthy/0,exp1,,,,,,,0,0,,,ok,,,false,false,,,,,,,,,,\n");
}

TEST(ResultsCsv, MagnitudeUnitAndMissReasonAreTheLastColumns) {
  EXPECT_THAT(ResultsCsvHeader(), ::testing::EndsWith(",confidence,magnitude_unit,miss_reason\n"));
  EXPECT_EQ(MagnitudeUnit("kt_factor"), "1");
  EXPECT_EQ(MagnitudeUnit("drag_fraction"), "1");
  EXPECT_EQ(MagnitudeUnit("resistance_ohm"), "Ω");
  EXPECT_EQ(MagnitudeUnit("drift_Nm_per_s"), "N m/s");
  RunRecord r;
  r.run_id = "exp1/kt/j3/r0";
  r.family = "torque_sensor_drift";
  r.joint = 3;
  r.magnitude_key = "drift_Nm_per_s";
  r.magnitude = -2;
  r.miss_reason = "no alarm; closest on joint 3: sensor_drift deviated 0.2, 0.3";
  EXPECT_THAT(ResultsCsvRow(r),
              ::testing::EndsWith(",N m/s,\"no alarm; closest on joint 3: sensor_drift deviated 0.2, 0.3\"\n"));
}

TEST(ResultsCsv, TextASpreadsheetWouldTakeForAFormulaOpensAsText) {
  RunRecord r;
  r.run_id = "=HYPERLINK(\"http://x\",\"y\")/kt#0/j3/r0";
  r.trajectory = "+1";
  r.group = "@SUM(A1)";
  r.family = "-kt";
  r.joint = 3;
  r.onset_s = -0.5;  // a number: as it is
  r.failure_reason = "\tcmd";
  r.ok = false;
  const std::string row = ResultsCsvRow(r);
  EXPECT_THAT(row, ::testing::StartsWith("0,\"'=HYPERLINK(\"\"http://x\"\",\"\"y\"\")/kt#0/j3/r0\",'+1,'@SUM(A1),'-kt,3,-0.5,"));
  EXPECT_THAT(row, ::testing::HasSubstr(",'\tcmd,"));
  EXPECT_EQ(CsvText("a=b"), "a=b");  // only the first character counts
  EXPECT_EQ(CsvText(""), "");
}

}  // namespace
}  // namespace armfault
