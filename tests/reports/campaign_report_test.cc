// The campaign report on a small real campaign (run once for the suite) with the hand-made
// tuning.json fixture (tests/reports/data/tuning.json): every plot is there with data, the
// heat map holds summary.json's confusion counts, nothing is fetched, text is escaped, and a
// missing tuning.json says what to run.
#include "reports/campaign_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "campaigns/campaign_summary.h"
#include "campaigns/runner.h"
#include "core/json_input.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::HasSubstr;
using testing::Not;

std::string ReadAll(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// The <svg> element with this id, or "" if there is none.
std::string SvgById(const std::string& html, const std::string& id) {
  const size_t at = html.find("<svg id=\"" + id + "\"");
  if (at == std::string::npos) return "";
  const size_t end = html.find("</svg>", at);
  return end == std::string::npos ? "" : html.substr(at, end + 6 - at);
}

// Data paths with non-empty path data.
int DataPaths(const std::string& svg) {
  static const std::regex data("<path class=\"data [^\"]*\"[^>]* d=\"M[^\"]+\"");
  return static_cast<int>(std::distance(std::sregex_iterator(svg.begin(), svg.end(), data), std::sregex_iterator()));
}

class CampaignReportTest : public testing::Test {
 protected:
  // One short campaign for the whole suite: a strong and a slight K_T fault (the slight one
  // is likely missed), a stuck sensor, two healthy runs.
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("armfault_report_test_" + std::to_string(getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    const json j = json::parse(R"({
      "name": "report-test", "seed": 11, "duration_s": 5,
      "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
      "faults": [
        {"family": "kt_degradation", "joint": 3, "kt_factor": [0.5, 0.97], "onset_s": 1.5},
        {"family": "torque_sensor_stuck", "joint": 3, "lead": ["supply", "open"], "onset_s": 2.0}
      ],
      "healthy": 2,
      "floors": {"detection_rate": 0.5, "per_family": {"torque_sensor_stuck": {"detection_rate": 0.99}}}
    })");
    campaign_ = new Campaign(CampaignFromJson(j, "report-test.json", "."));
    RunnerOptions o;
    o.output_dir = dir_->string();
    o.threads = 2;
    RunCampaign(*campaign_, o);
    SummaryBuilder builder;
    std::ifstream in(*dir_ / "results.jsonl");
    std::string line;
    while (std::getline(in, line)) builder.Add(RunRecordFromJson(json::parse(line)));
    std::ofstream(*dir_ / "summary.json") << builder.Build(campaign_->floors, campaign_->resolved, "test").dump(2);
    fs::copy_file(fs::path(ARMFAULT_SOURCE_DIR) / "tests/reports/data/tuning.json", *dir_ / "tuning.json");
    // Table 5-3 from a file, so the suite does not run the thesis experiments.
    std::ofstream(*dir_ / "thesis.json") << R"({"table_5_3": [
      {"kt_factor": 1.0, "thesis_pct": 80.5, "armfault_pct": 80.86, "thesis_ratio": 1, "armfault_ratio": 1, "windows": 4},
      {"kt_factor": 0.9, "thesis_pct": 73.7, "armfault_pct": 69.96, "thesis_ratio": 0.916, "armfault_ratio": 0.865, "windows": 4},
      {"kt_factor": 0.5, "thesis_pct": 38.19, "armfault_pct": 33.73, "thesis_ratio": 0.474, "armfault_ratio": 0.417, "windows": 4}]})";
    ReportOptions ro;
    ro.dir = dir_->string();
    data_ = new ReportData(GatherReportData(ro));
    html_ = new std::string(RenderReportHtml(*data_));
  }
  static void TearDownTestSuite() {
    delete html_;
    delete data_;
    delete campaign_;
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
  }

  static std::vector<RunRecord> Records() {
    std::vector<RunRecord> out;
    std::ifstream in(*dir_ / "results.jsonl");
    std::string line;
    while (std::getline(in, line)) out.push_back(RunRecordFromJson(json::parse(line)));
    return out;
  }

  static fs::path* dir_;
  static Campaign* campaign_;
  static ReportData* data_;
  static std::string* html_;
};

fs::path* CampaignReportTest::dir_ = nullptr;
Campaign* CampaignReportTest::campaign_ = nullptr;
ReportData* CampaignReportTest::data_ = nullptr;
std::string* CampaignReportTest::html_ = nullptr;

TEST_F(CampaignReportTest, EveryPlotIsThereWithData) {
  for (const char* id : {"roc", "pod-kt_degradation", "pod-friction_increase", "pod-torque_sensor_stuck",
                         "latency-threshold-kt_degradation", "latency-threshold-friction_increase", "confusion",
                         "latency-distribution", "thesis-table-5-3", "run-j3-efficiency", "run-j3-current",
                         "run-j3-torque"}) {
    const std::string svg = SvgById(*html_, id);
    ASSERT_FALSE(svg.empty()) << id;
    EXPECT_GT(DataPaths(svg), 0) << id;
  }
  // Axis labels carry units.
  for (const char* label : {"time (s)", "current (A)", "torque (N m)", "efficiency η (%)", "latency after onset (s"}) {
    EXPECT_THAT(*html_, HasSubstr(label));
  }
  // AUCs in the ROC legend; a90 and a90/95 marked.
  EXPECT_THAT(SvgById(*html_, "roc"), HasSubstr("overall frontier (AUC 0.970)"));
  EXPECT_THAT(SvgById(*html_, "roc"), HasSubstr("kt_degradation (AUC 0.950)"));
  EXPECT_THAT(SvgById(*html_, "pod-kt_degradation"), HasSubstr("a90 = 0.87"));
  EXPECT_THAT(SvgById(*html_, "pod-kt_degradation"), HasSubstr("a90/95 = 0.8418"));
  // The run plot marks the onset and the alarm.
  EXPECT_THAT(SvgById(*html_, "run-j3-current"), HasSubstr("fault onset"));
}

TEST_F(CampaignReportTest, HeatMapHoldsTheSummaryConfusionCounts) {
  const json summary = ReadJsonFile((*dir_ / "summary.json").string());
  const json& labels = summary["confusion"]["labels"];
  const json& counts = summary["confusion"]["counts"];
  const std::string svg = SvgById(*html_, "confusion");
  std::map<std::pair<std::string, std::string>, long> cells;
  static const std::regex cell("data-row=\"([^\"]*)\" data-col=\"([^\"]*)\" data-count=\"([0-9]+)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), cell); it != std::sregex_iterator(); ++it) {
    cells[{(*it)[1].str(), (*it)[2].str()}] = std::stol((*it)[3].str());
  }
  // Every true class but "unknown" (never a true class) is a row; every label a column.
  EXPECT_EQ(cells.size(), (labels.size() - 1) * labels.size());
  for (size_t r = 0; r < labels.size(); ++r) {
    for (size_t c = 0; c < labels.size(); ++c) {
      const std::string row = labels[r], col = labels[c];
      if (row == "unknown") {
        EXPECT_EQ(counts[r][c].get<long>(), 0);
        continue;
      }
      auto it = cells.find({row, col});
      ASSERT_NE(it, cells.end()) << row << " / " << col;
      EXPECT_EQ(it->second, counts[r][c].get<long>()) << row << " / " << col;
    }
  }
}

TEST_F(CampaignReportTest, FetchesNothing) {
  EXPECT_THAT(*html_, Not(HasSubstr("http")));
  EXPECT_THAT(*html_, Not(HasSubstr("src=")));
  EXPECT_THAT(*html_, Not(HasSubstr("<script")));
  EXPECT_THAT(*html_, Not(HasSubstr("@import")));
  static const std::regex href("href=\"([^\"]*)\"");
  int links = 0;
  for (auto it = std::sregex_iterator(html_->begin(), html_->end(), href); it != std::sregex_iterator(); ++it) {
    EXPECT_EQ((*it)[1].str().substr(0, 1), "#") << (*it)[1].str();
    ++links;
  }
  EXPECT_GT(links, 0);
  static const std::regex url("url\\(([^)]*)\\)");
  for (auto it = std::sregex_iterator(html_->begin(), html_->end(), url); it != std::sregex_iterator(); ++it) {
    EXPECT_EQ((*it)[1].str().substr(0, 1), "#") << (*it)[1].str();
  }
}

TEST_F(CampaignReportTest, EscapesNamesFromTheFiles) {
  ReportData d = *data_;
  d.summary["campaign"]["name"] = "<script>alert('x')</script> & co";
  d.summary["per_family"]["kt_degradation\"><b>"] = d.summary["per_family"]["kt_degradation"];
  const std::string html = RenderReportHtml(d);
  EXPECT_THAT(html, Not(HasSubstr("<script>")));
  EXPECT_THAT(html, HasSubstr("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; co"));
  EXPECT_THAT(html, HasSubstr("kt_degradation&quot;&gt;&lt;b&gt;"));
}

TEST_F(CampaignReportTest, IsDeterministic) { EXPECT_EQ(RenderReportHtml(*data_), *html_); }

TEST_F(CampaignReportTest, PlotsTheFirstMissedFaultyRunElseTheFirstDetected) {
  std::string expected;
  for (const RunRecord& r : Records()) {
    if (r.ok && !r.family.empty() && !r.detected) {
      expected = r.run_id;
      break;
    }
  }
  if (expected.empty()) {
    for (const RunRecord& r : Records()) {
      if (r.ok && !r.family.empty()) {
        expected = r.run_id;
        break;
      }
    }
  }
  EXPECT_EQ(data_->run.run_id, expected);
  EXPECT_EQ(data_->run.joints, std::vector<int>{3});
}

TEST_F(CampaignReportTest, ReSimulationMatchesTheRunsRecord) {
  const RunSeries& s = data_->run;
  ASSERT_TRUE(s.error.empty()) << s.error;
  ASSERT_TRUE(s.stored.has_value());
  EXPECT_EQ(ToJson(s.record).dump(), ToJson(*s.stored).dump());
  EXPECT_FALSE(s.monitor.windows.empty());
  ASSERT_EQ(s.i_cmd_A.size(), 1u);
  EXPECT_EQ(s.i_cmd_A[0].size(), s.t_s.size());
  EXPECT_NEAR(s.t_s.back(), 5.0, 0.01);
}

TEST_F(CampaignReportTest, RunOptionPicksAnyRunAndRejectsUnknownOnes) {
  // A detected stuck-sensor run: its monitor's first alarm is its detection time.
  ReportOptions ro;
  ro.dir = dir_->string();
  ro.run_id = "exp1/torque_sensor_stuck#1/lead=supply/j3/r0";
  const ReportData d = GatherReportData(ro);
  ASSERT_TRUE(d.run.error.empty()) << d.run.error;
  EXPECT_EQ(d.run.why, "chosen with --run");
  ASSERT_TRUE(d.run.record.detected);
  ASSERT_TRUE(d.run.first_alarm_s.has_value());
  EXPECT_DOUBLE_EQ(*d.run.first_alarm_s, *d.run.record.detection_time_s);
  EXPECT_THAT(SvgById(RenderReportHtml(d), "run-j3-torque"), HasSubstr("first alarm"));

  ro.run_id = "exp1/healthy/1";
  EXPECT_EQ(GatherReportData(ro).run.joints, std::vector<int>{3});  // the moving joint

  ro.run_id = "exp1/nope";
  try {
    GatherReportData(ro);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("no run \"exp1/nope\""));
  }
}

TEST_F(CampaignReportTest, WithoutTuningTheTunedSectionsSayWhatToRun) {
  ReportData d = *data_;
  d.tuning.reset();
  const std::string html = RenderReportHtml(d);
  EXPECT_EQ(SvgById(html, "roc"), "");
  EXPECT_EQ(SvgById(html, "pod-kt_degradation"), "");
  EXPECT_EQ(SvgById(html, "latency-threshold-kt_degradation"), "");
  const std::string hint = "run <code>armfault tune " + dir_->string() + "</code> first";
  size_t n = 0;
  for (size_t p = html.find(hint); p != std::string::npos; p = html.find(hint, p + 1)) ++n;
  EXPECT_EQ(n, 4u);  // operating point, ROC, detection probability, latency against threshold
  // The rest is still there.
  EXPECT_FALSE(SvgById(html, "confusion").empty());
  EXPECT_FALSE(SvgById(html, "run-j3-efficiency").empty());
  EXPECT_THAT(RenderReportMarkdown(d), HasSubstr("run `armfault tune " + dir_->string() + "` first"));

  // The tuning source is one swappable function.
  ReportOptions ro;
  ro.dir = dir_->string();
  int calls = 0;
  ro.tuning = [&](const std::string& dir) -> std::optional<json> {
    ++calls;
    EXPECT_EQ(dir, dir_->string());
    return std::nullopt;
  };
  EXPECT_FALSE(GatherReportData(ro).tuning.has_value());
  EXPECT_EQ(calls, 1);
}

TEST_F(CampaignReportTest, MarkdownHasHeadlineOperatingPointA90AndFloors) {
  const std::string md = RenderReportMarkdown(*data_);
  EXPECT_THAT(md, HasSubstr("# armfault report: report-test"));
  EXPECT_THAT(md, HasSubstr("| detection |"));
  EXPECT_THAT(md, HasSubstr("| false alarm |"));
  EXPECT_THAT(md, HasSubstr("Rule: max_detection (false_alarm_ceiling = 0.05)"));
  EXPECT_THAT(md, HasSubstr("kt_factor.worn = 0.95"));
  EXPECT_THAT(md, HasSubstr("| kt_degradation | kt_factor | 0.87 | 0.8418 |"));
  EXPECT_THAT(md, HasSubstr("| torque_sensor_stuck | lead | no fit | no fit |"));
  EXPECT_THAT(md, HasSubstr("| detection_rate | ≥ 0.500 |"));
  EXPECT_THAT(md, HasSubstr("| per_family/torque_sensor_stuck/detection_rate |"));
}

TEST_F(CampaignReportTest, WritesHtmlAndMarkdownWhereAsked) {
  ReportOptions ro;
  ro.dir = dir_->string();
  ro.output = (*dir_ / "elsewhere" / "page.html").string();
  const ReportPaths p = WriteCampaignReport(ro);
  EXPECT_EQ(p.html, ro.output);
  EXPECT_EQ(p.markdown, (*dir_ / "elsewhere" / "page.md").string());
  EXPECT_THAT(ReadAll(p.html), testing::StartsWith("<!DOCTYPE html>"));
  EXPECT_THAT(ReadAll(p.markdown), testing::StartsWith("# armfault report"));
}

TEST(ReadTuning, AbsentIsNulloptAndBrokenIsAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("armfault_read_tuning_" + std::to_string(getpid()));
  fs::create_directories(dir);
  EXPECT_FALSE(ReadTuning(dir.string()).has_value());
  std::ofstream(dir / "tuning.json") << "{\"roc\": ";
  EXPECT_THROW(ReadTuning(dir.string()), InputError);
  std::ofstream(dir / "tuning.json") << "{\"roc\": {}}";
  EXPECT_TRUE(ReadTuning(dir.string()).has_value());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace armfault
