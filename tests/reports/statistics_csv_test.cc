// `trace --statistics`: every published statistic per tick and joint beside its threshold
// (reports/statistics_csv.h), for the built-in monitor and any monitor that publishes through a
// ThresholdTap (a C plugin, a Python monitor).
#include "reports/statistics_csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>

#include "campaigns/spec/campaign.h"
#include "campaigns/running/run_pipeline.h"
#include "core/monitors/threshold_statistics.h"

namespace armfault {
namespace {

struct Row {
  double t_s = 0;
  int joint = 0;
  std::string statistic, family;
  std::string value;  // "" when none
  double threshold = 0;
  std::string above;
};

std::vector<Row> Parse(const std::string& text, std::string* header) {
  std::istringstream in(text);
  std::getline(in, *header);
  std::vector<Row> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    if (line.back() == ',') f.push_back("");
    EXPECT_EQ(f.size(), 7u) << line;
    if (f.size() != 7) continue;
    rows.push_back({std::stod(f[0]), std::stoi(f[1]), f[2], f[3], f[4], std::stod(f[5]), f[6]});
  }
  return rows;
}

TEST(StatisticsCsvTest, WritesOneRowPerTickJointAndStatisticBesideItsThreshold) {
  std::string out;
  StatisticsCsvWriter writer([&](std::string_view text) { out += text; });
  writer.Declare({{"kt_deficit", "kt_degradation", 0.2, false}, {"z", "unknown", 3, true}}, 2);
  const double nan = std::nan("");
  const double values[] = {0.1, 3, 0.25, nan};  // joint 1: (0.1, 3), joint 2: (0.25, none)
  writer.Values(0.002, values);
  EXPECT_EQ(out,
            "t_s,joint,statistic,family,value,threshold,above\n"
            "0.002,1,kt_deficit,kt_degradation,0.1,0.2,0\n"
            "0.002,1,z,unknown,3,3,1\n"  // inclusive: value >= threshold passes
            "0.002,2,kt_deficit,kt_degradation,0.25,0.2,1\n"
            "0.002,2,z,unknown,,3,\n");
}

TEST(StatisticsCsvTest, ANameASpreadsheetWouldTakeForAFormulaIsWrittenAsText) {
  // A plugin names its statistics: "=HYPERLINK(...)" must open as the text it is (the
  // formula-injection guard of core/base/csv.h), and a comma in a name stays in one cell.
  std::string out;
  StatisticsCsvWriter writer([&](std::string_view text) { out += text; });
  writer.Declare({{"=HYPERLINK(\"x\")", "-1+1", 1, false}, {"a,b", "@sum", 1, false}}, 1);
  const double values[] = {0.5, 2};
  writer.Values(0.002, values);
  EXPECT_EQ(out,
            "t_s,joint,statistic,family,value,threshold,above\n"
            "0.002,1,\"'=HYPERLINK(\"\"x\"\")\",'-1+1,0.5,1,0\n"
            "0.002,1,\"a,b\",'@sum,2,1,1\n");
}

TEST(StatisticsCsvTest, AMonitorPublishingNoneGivesTheHeaderAlone) {
  std::string out;
  StatisticsCsvWriter writer([&](std::string_view text) { out += text; });
  writer.Declare({}, 3);
  const double none[1] = {0};
  writer.Values(0.002, none);
  EXPECT_EQ(out, "t_s,joint,statistic,family,value,threshold,above\n");
}

TEST(StatisticsCsvTest, AThresholdTapShowsEveryRecordedTick) {
  // What a C plugin's and a Python monitor's statistics go through.
  ThresholdTap tap({{"kt_deficit", "kt_degradation", 0.2, "/kt"}}, 2, 1.0);
  std::string out;
  StatisticsCsvWriter writer([&](std::string_view text) { out += text; });
  tap.ShowStatistics(&writer);
  const double first[] = {0.1, 0.3}, second[] = {0.15, std::nan("")};
  tap.recorder()->Record(0.5, first);
  tap.recorder()->Record(1.0, second);
  std::string header;
  const std::vector<Row> rows = Parse(out, &header);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[1].t_s, 0.5);
  EXPECT_EQ(rows[1].joint, 2);
  EXPECT_EQ(rows[1].value, "0.3");
  EXPECT_EQ(rows[1].above, "1");
  EXPECT_EQ(rows[3].value, "");
  EXPECT_EQ(rows[3].threshold, 0.2);
}

// The built-in monitor on ci.json: a K_T loss on joint 3 from 2 s; the healthy run beside it.
std::vector<Row> TraceStatistics(const std::string& run_id, RunRecord* record) {
  const Campaign campaign = ReadCampaignFile(ARMFAULT_SOURCE_DIR "/campaigns/files/ci.json");
  std::string out;
  StatisticsCsvWriter writer([&](std::string_view text) { out += text; });
  for (const CaseSpec& spec : ExpandCases(campaign)) {
    if (spec.run_id == run_id) *record = RunCase(campaign, spec, nullptr, nullptr, nullptr, &writer);
  }
  std::string header;
  const std::vector<Row> rows = Parse(out, &header);
  EXPECT_EQ(header, "t_s,joint,statistic,family,value,threshold,above");
  return rows;
}

// The first tick at which a detector's deviation and significance both pass (its alarm), on
// `joint`; -1 if never. before_s: also whether any detector alarmed on any joint before it.
double FirstAlarm(const std::vector<Row>& rows, const std::string& detector, int joint) {
  std::map<double, int> passed;  // t_s -> statistics of the pair that passed
  for (const Row& r : rows) {
    if (r.joint != joint || r.above != "1") continue;
    if (r.statistic == detector + "_deviation" || r.statistic == detector + "_significance") ++passed[r.t_s];
  }
  for (const auto& [t, n] : passed) {
    if (n == 2) return t;
  }
  return -1;
}

TEST(StatisticsCsvTest, BuiltInKtStatisticCrossesItsThresholdAfterOnsetAtTheDetection) {
  RunRecord record;
  const std::vector<Row> rows = TraceStatistics("exp1/kt_degradation#0/kt_factor=0.7/j3/r0", &record);
  ASSERT_TRUE(record.ok);
  ASSERT_TRUE(record.detected);
  ASSERT_EQ(record.onset_s, 2.0);
  // 8 statistics (4 detectors x deviation, significance) x 3 joints at every tick.
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(rows.size() % 24, 0u);
  double max_before = -1, max_after = -1, threshold = 0;
  for (const Row& r : rows) {
    if (r.joint != 3 || r.statistic != "kt_factor_deviation" || r.value.empty()) continue;
    EXPECT_EQ(r.family, "kt_degradation");
    threshold = r.threshold;
    (r.t_s < record.onset_s ? max_before : max_after) = std::max(r.t_s < record.onset_s ? max_before : max_after,
                                                                 std::stod(r.value));
  }
  EXPECT_NEAR(threshold, 0.05, 1e-12);  // 1 - the default kt_factor worn limit 0.95
  EXPECT_LE(max_before, threshold);
  EXPECT_GT(max_after, threshold);
  // Both statistics of the detector pass first exactly at the recorded detection.
  EXPECT_EQ(FirstAlarm(rows, "kt_factor", 3), record.detection_time_s.value());
  for (int j = 1; j <= 3; ++j) {
    for (const char* d : {"kt_factor", "resistance_factor", "friction_factor", "sensor_drift_Nm"}) {
      const double t = FirstAlarm(rows, d, j);
      EXPECT_TRUE(t < 0 || t >= record.onset_s) << d << " on joint " << j << " alarms at " << t;
    }
  }
}

TEST(StatisticsCsvTest, BuiltInKtStatisticStaysBelowItsThresholdInAHealthyRun) {
  RunRecord record;
  const std::vector<Row> rows = TraceStatistics("exp1/healthy/0", &record);
  ASSERT_TRUE(record.ok);
  ASSERT_FALSE(record.detected);
  ASSERT_FALSE(rows.empty());
  int kt_values = 0;
  for (const Row& r : rows) {
    if (r.statistic != "kt_factor_deviation" || r.value.empty()) continue;
    ++kt_values;
    EXPECT_LE(std::stod(r.value), r.threshold) << "joint " << r.joint << " at " << r.t_s;
    EXPECT_EQ(r.above, "0");
  }
  EXPECT_GT(kt_values, 0);
  for (int j = 1; j <= 3; ++j) {
    for (const char* d : {"kt_factor", "resistance_factor", "friction_factor", "sensor_drift_Nm"}) {
      EXPECT_EQ(FirstAlarm(rows, d, j), -1) << d << " on joint " << j;
    }
  }
}

}  // namespace
}  // namespace armfault
