// The campaign report on a small real campaign (run once for the suite) with the hand-made
// tuning.json fixture (tests/reports/page/data/tuning.json, given this campaign's hash): every plot
// is there with data and units, the heat map holds summary.json's confusion counts, nothing is
// fetched, text is escaped, only swept ROC curves are drawn (no extrapolated points, no AUC
// for the others), detection probability shows the runs as run, every empty plot says why,
// and files of another campaign are refused.
#include "reports/page/campaign_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/scoring/provenance.h"
#include "campaigns/running/runner.h"
#include "core/base/json_input.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::HasSubstr;
using testing::Not;
using testing_support::ErrorOf;
using testing_support::Lines;
using testing_support::ReadAll;
using testing_support::ScratchDir;

// The Vega-Lite spec (JSON text) of the plot with this id, or "" if there is none.
std::string SpecById(const std::string& html, const std::string& id) {
  const std::string open = "<script type=\"application/json\" class=\"vega-spec\" data-plot=\"" + id + "\">";
  const size_t at = html.find(open);
  if (at == std::string::npos) return "";
  const size_t end = html.find("</script>", at);
  EXPECT_NE(html.find("<div class=\"plot\" id=\"" + id + "\""), std::string::npos) << id;
  return end == std::string::npos ? "" : html.substr(at + open.size(), end - at - open.size());
}

// The layers of a plot's spec (one for a heat map: the spec itself, whose data is shared).
std::vector<json> Layers(const std::string& spec) {
  const json j = json::parse(spec);
  std::vector<json> out;
  if (j.contains("data")) {
    json layer = j;
    layer["mark"] = "heatmap";
    out.push_back(layer);
    return out;
  }
  for (const json& l : j.at("layer")) out.push_back(l);
  return out;
}

std::string MarkType(const json& layer) {
  const json& m = layer.at("mark");
  return m.is_string() ? m.get<std::string>() : m.at("type").get<std::string>();
}

// Data marks drawn from data: rows of lines, points, areas, rectangles, heat-map cells and
// rules spanning data (segments, error bars), not the marker lines and labels.
int DataPaths(const std::string& spec) {
  int n = 0;
  for (const json& l : Layers(spec)) {
    const std::string type = MarkType(l);
    for (const json& row : l.at("data").at("values")) {
      const bool drawn = type == "line" || type == "point" || type == "area" || type == "rect" || type == "heatmap" ||
                         (type == "rule" && (row.contains("x2") || row.contains("y2")));
      if (drawn && row.contains(type == "heatmap" ? "count" : "x")) ++n;
    }
  }
  return n;
}

class CampaignReportTest : public testing::Test {
 protected:
  // One short campaign for the whole suite: K_T faults from strong to slight (the slight one
  // is likely missed; four magnitudes, enough for a fit), a stuck sensor, two healthy runs.
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("armfault_report_test_" + std::to_string(getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    const json j = json::parse(R"({
      "name": "report-test", "seed": 11, "duration_s": 5,
      "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
      "faults": [
        {"family": "kt_degradation", "joint": 3, "kt_factor": [0.5, 0.7, 0.9, 0.97], "onset_s": 1.5},
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
    // The fixture, as `armfault tune` would have written it for this campaign.
    json tuning = ReadJsonFile((fs::path(ARMFAULT_SOURCE_DIR) / "tests/reports/page/data/tuning.json").string());
    tuning["campaign_hash"] = CampaignHash(campaign_->resolved);
    std::ofstream(*dir_ / "tuning.json") << tuning.dump(1);
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
  for (const char* id : {"roc", "pod-kt_degradation", "pod-torque_sensor_stuck", "latency-threshold-kt_degradation",
                         "latency-threshold-friction_increase", "confusion", "latency-distribution",
                         "thesis-table-5-3", "run-j3-efficiency", "run-j3-current", "run-j3-torque"}) {
    const std::string spec = SpecById(*html_, id);
    ASSERT_FALSE(spec.empty()) << id;
    EXPECT_GT(DataPaths(spec), 0) << id;
  }
  // Every axis label carries its unit.
  for (const char* label : {"time (s)", "current (A)", "torque (N m)", "efficiency η (%)", "efficiency (fraction)",
                            "latency after onset (s", "false-alarm rate (fraction of healthy runs alarmed",
                            "detection rate (fraction of faulty runs", "detection probability (fraction of runs)",
                            "kt_factor (× nominal K_T), fault magnitude", "kt_factor.worn (× nominal K_T), threshold",
                            "friction_factor.worn (× nominal friction), threshold", "lead (named fault variant)"}) {
    EXPECT_THAT(*html_, HasSubstr(label));
  }
  // The run plot marks the onset and the alarm.
  EXPECT_THAT(SpecById(*html_, "run-j3-current"), HasSubstr("fault onset"));
}

// The tooltips of the points of a plot: "RUN_ID: tip" for a point of a run, else its tip.
std::vector<std::string> PointTips(const std::string& spec) {
  std::vector<std::string> out;
  for (const json& l : Layers(spec)) {
    if (MarkType(l) != "point") continue;
    for (const json& row : l.at("data").at("values")) {
      if (!row.contains("tip")) continue;
      out.push_back(row.contains("run") ? row["run"].get<std::string>() + ": " + row["tip"].get<std::string>()
                                        : row["tip"].get<std::string>());
    }
  }
  return out;
}

TEST_F(CampaignReportTest, RocDrawsOnlySweptCurvesWithMeasuredPointsAndTheOperatingPoint) {
  const std::string roc = SpecById(*html_, "roc");
  // The three swept curves (5 points each) and four marked points, nothing else: no point was
  // added at (0, 0) or (1, 1).
  const std::vector<std::string> tips = PointTips(roc);
  EXPECT_EQ(tips.size(), 3u * 5 + 4);
  for (const std::string& tip : tips) {
    EXPECT_THAT(tip, Not(HasSubstr("false alarms 0.0 %, detection 0.0 %")));
    EXPECT_THAT(tip, Not(HasSubstr("false alarms 100.0 %")));
  }
  // Each curve's line joins its five measured points, no extrapolated ends.
  int lines = 0;
  for (const json& l : Layers(roc)) {
    if (MarkType(l) != "line") continue;
    ++lines;
    EXPECT_EQ(l["data"]["values"].size(), 5u) << l.dump();
  }
  EXPECT_EQ(lines, 3);
  // AUCs only as measured; none for the families without a swept threshold, which are not drawn.
  EXPECT_THAT(roc, HasSubstr("overall frontier, AUC 0.238 over false alarms 0 to 0.25"));
  EXPECT_THAT(roc, HasSubstr("kt_degradation (kt_factor.worn swept), AUC 0.188 over false alarms 0 to 0.1875"));
  for (const char* family : {"brake_lock", "inverter_short", "torque_sensor_stuck"}) {
    EXPECT_THAT(roc, Not(HasSubstr(family)));
    EXPECT_THAT(*html_, HasSubstr(std::string("Not drawn: <b>") + family +
                                  "</b>: no threshold of its own is swept (its detectors are not on the grid)"));
  }
  // The false-alarm axis is zoomed to a little above the largest rate (0.25), and says so.
  EXPECT_THAT(roc, HasSubstr("false-alarm rate (fraction of healthy runs alarmed; axis 0 to 0.3)"));
  // The chosen operating point, over every run and on each half.
  EXPECT_THAT(roc, HasSubstr("operating point (all runs): false alarms 0.0 %, detection 94.4 %"));
  EXPECT_THAT(roc, HasSubstr("operating point on the held-out runs: false alarms 12.5 %, detection 89.5 %"));
  EXPECT_THAT(roc, HasSubstr("thresholds as run"));
}

TEST_F(CampaignReportTest, RocWithoutASweptCurveSaysWhyInsteadOfDrawing) {
  ReportData d = *data_;
  json& roc = (*d.tuning)["roc"];
  roc["overall"]["points"] = json::array({roc["overall"]["points"][0]});
  roc["kt_degradation"]["points"] = json::array({roc["kt_degradation"]["points"][2]});
  roc.erase("friction_increase");
  const std::string html = RenderReportHtml(d);
  EXPECT_EQ(SpecById(html, "roc"), "");
  EXPECT_THAT(html, HasSubstr("No ROC curve to draw"));
  EXPECT_THAT(html, HasSubstr("Not drawn: <b>overall frontier</b>: one operating point only (false alarms 0.0 %, "
                              "detection 61.0 %): every setting of the grid gave these rates; no AUC."));
  EXPECT_THAT(html, HasSubstr("Not drawn: <b>kt_degradation</b>: one operating point only"));
  // A curve that varies but sits at one false-alarm rate is drawn without an AUC.
  d = *data_;
  (*d.tuning)["roc"]["kt_degradation"]["auc"] = 1.0;
  (*d.tuning)["roc"]["kt_degradation"]["auc_false_alarm_range"] = {0, 0};
  EXPECT_THAT(SpecById(RenderReportHtml(d), "roc"),
              HasSubstr("kt_degradation (kt_factor.worn swept), no AUC: every point at one false-alarm rate"));
}

TEST_F(CampaignReportTest, RocZoomsOnTheLowEndWhenTheCurvesReachFar) {
  ReportData d = *data_;
  (*d.tuning)["roc"]["overall"]["points"].push_back({{"false_alarm_rate", 0.9}, {"detection_rate", 1.0}});
  const std::string html = RenderReportHtml(d);
  EXPECT_THAT(SpecById(html, "roc"), HasSubstr("false-alarm rate (fraction of healthy runs alarmed; axis 0 to 1)"));
  const std::string low = SpecById(html, "roc-low-false-alarms");
  EXPECT_THAT(low, HasSubstr("false-alarm rate (fraction of healthy runs alarmed; axis 0 to 0.2)"));
  EXPECT_THAT(low, HasSubstr("Zoomed to false alarms 0 to 0.2: 3 points lie beyond the axis"));
  // Without far points, one plot is enough.
  EXPECT_EQ(SpecById(*html_, "roc-low-false-alarms"), "");
}

TEST_F(CampaignReportTest, DetectionProbabilityShowsEveryRunAsRunAndTheFit) {
  const std::string pod = SpecById(*html_, "pod-kt_degradation");
  const std::vector<std::string> tips = PointTips(pod);
  long runs = 0, missed = 0;
  for (const RunRecord& r : Records()) {
    if (r.family != "kt_degradation") continue;
    ++runs;
    missed += r.detected ? 0 : 1;
    const std::string expected = r.run_id + (r.detected ? ": detected" : ": missed");
    EXPECT_NE(std::find(tips.begin(), tips.end(), expected), tips.end()) << expected;
  }
  ASSERT_EQ(runs, 4);
  // One dot per run and one detected fraction per magnitude, with its Wilson interval.
  EXPECT_EQ(tips.size(), 4u + 4u);
  EXPECT_THAT(pod, HasSubstr("detected fraction as run (95 % Wilson)"));
  EXPECT_THAT(pod, HasSubstr("kt_factor 0.5: 1 of 1 runs detected (100.0 %, 95 % Wilson [20.7, 100.0] %)"));
  EXPECT_THAT(pod, HasSubstr("4 runs at 4 magnitudes: " + std::to_string(runs - missed) + " detected, " +
                             std::to_string(missed) + " missed"));
  EXPECT_THAT(pod, HasSubstr("fitted as run"));
  // Named variants: their runs and fractions, no curve.
  const std::string stuck = SpecById(*html_, "pod-torque_sensor_stuck");
  const std::vector<std::string> stuck_tips = PointTips(stuck);
  EXPECT_TRUE(std::any_of(stuck_tips.begin(), stuck_tips.end(), [](const std::string& t) {
    return t.rfind("exp1/torque_sensor_stuck#1/lead=supply/j3/r0: ", 0) == 0;
  }));
  EXPECT_THAT(stuck, HasSubstr("Named variants: no fitted curve."));
}

TEST_F(CampaignReportTest, MissesAreVisibleAtZero) {
  ReportData d = *data_;
  PodAsRun p;
  p.magnitude_key = "friction_factor";
  for (double m : {1.2, 1.5, 2.0}) {
    PodAsRun::Cell& c = p.by_magnitude[m];
    for (int k = 0; k < 3; ++k) {
      const bool hit = m > 1.3 && k < 2;
      const std::string id = "exp1/friction_increase#0/friction_factor=" + FormatNumber(m) + "/j3/r" + std::to_string(k);
      ++c.runs;
      c.detected += hit;
      (hit ? c.hit_ids : c.miss_ids).push_back(id);
      p.severities.push_back(m - 1);
      p.hits.push_back(hit);
    }
  }
  d.pod = {{"friction_increase", p}};
  const std::string pod = SpecById(RenderReportHtml(d), "pod-friction_increase");
  EXPECT_THAT(pod, HasSubstr("runs missed (at 0)"));
  const std::vector<std::string> tips = PointTips(pod);
  EXPECT_NE(std::find(tips.begin(), tips.end(), "exp1/friction_increase#0/friction_factor=1.2/j3/r2: missed"), tips.end());
  EXPECT_THAT(pod, HasSubstr("friction_factor 1.2: 0 of 3 runs detected (0.0 %"));
  EXPECT_THAT(pod, HasSubstr("9 runs at 3 magnitudes: 4 detected, 5 missed"));
  EXPECT_THAT(pod, HasSubstr("\"#c62828\""));  // the misses' own colour
}

TEST_F(CampaignReportTest, EveryEmptyPlotSaysWhy) {
  // One magnitude per family: no curve, and the section says why.
  ReportData d = *data_;
  PodAsRun one;
  one.magnitude_key = "kt_factor";
  one.by_magnitude[0.6] = PodAsRun::Cell{2, 1, {"a"}, {"b"}, {3}, {3}};
  one.severities = {0.4, 0.4};
  one.hits = {true, false};
  d.pod = {{"kt_degradation", one}};
  std::string html = RenderReportHtml(d);
  EXPECT_THAT(SpecById(html, "pod-kt_degradation"), HasSubstr("One magnitude only: no curve (a fit needs 2 or more)."));
  EXPECT_THAT(html, HasSubstr("No family had more than one magnitude: no detection-probability curve could be fitted"));

  // No faulty runs at all.
  d = *data_;
  d.pod.clear();
  d.latencies_s.clear();
  d.misses.clear();
  html = RenderReportHtml(d);
  EXPECT_THAT(html, HasSubstr("No detection-probability plots: results.jsonl holds no completed faulty runs."));
  EXPECT_THAT(html, HasSubstr("No latencies: results.jsonl holds no completed faulty runs."));

  // Faulty runs, none detected.
  d = *data_;
  d.latencies_s.clear();
  d.misses = {{"kt_degradation", 3}};
  EXPECT_THAT(RenderReportHtml(d), HasSubstr("No latencies: none of the 3 faulty runs was detected."));

  // A latency curve with one threshold value.
  d = *data_;
  (*d.tuning)["latency"]["kt_degradation"]["points"] = json::array({(*d.tuning)["latency"]["kt_degradation"]["points"][0]});
  html = RenderReportHtml(d);
  EXPECT_EQ(SpecById(html, "latency-threshold-kt_degradation"), "");
  EXPECT_THAT(html, HasSubstr("kt_degradation: one threshold value only (kt_factor.worn not swept): no curve."));
}

// A sequential monitor's tuning: the page and report.md show each target rate beside the one
// measured, and whether the count seen lies inside the target's interval.
TEST_F(CampaignReportTest, ASequentialMonitorsRatesAreShownSetForBesideMeasured) {
  ReportData d = *data_;
  ASSERT_TRUE(d.tuning.has_value());
  EXPECT_EQ(RenderReportMarkdown(d).find("set for and measured"), std::string::npos);  // none without it
  (*d.tuning)["rate_calibration"] = json::parse(R"({"parameter": "target_false_alarms_per_hour", "as_run": 1,
    "points": [{"target_per_hour": 1, "healthy_hours": 19.9, "false_alarms": 1, "measured_per_hour": 0.0503,
                "measured_interval_per_hour": [0.00127, 0.281], "target_count_interval": [12, 29], "consistent": false,
                "faulty_runs": 36, "detected": 36, "detection_rate": 1.0, "median_latency_s": 3.63, "families": {}}]})");
  const std::string md = RenderReportMarkdown(d);
  EXPECT_THAT(md, HasSubstr("| 1 | 19.9 | 1 | 0.0503 (0.00127 to 0.281) | 12 to 29 | outside | 100.0 % | 3.630 s |"));
  EXPECT_THAT(RenderReportHtml(d), HasSubstr("<td>0.0503 (0.00127 to 0.281)</td><td>12 to 29</td><td>outside</td>"));
}

TEST_F(CampaignReportTest, ExplainsEveryMetricAndItsInterval) {
  const std::string md = RenderReportMarkdown(*data_);
  for (const char* metric : {"detection rate", "false-alarm rate", "alarm-before-onset rate", "isolation accuracy",
                             "latency median / p95", "magnitude error", "95 % Wilson score interval"}) {
    EXPECT_THAT(*html_, HasSubstr(std::string("<li><b>") + metric + "</b>: ")) << metric;
    EXPECT_THAT(md, HasSubstr(std::string("- **") + metric + "**: ")) << metric;
  }
  EXPECT_THAT(md, HasSubstr("0 of 10 still allows up to 27.8 %"));
}

TEST_F(CampaignReportTest, ShowsTheCampaignHashOfEveryFile) {
  const std::string hash = CampaignHash(campaign_->resolved);
  EXPECT_EQ(data_->campaign_hash, hash);
  EXPECT_EQ(data_->hashed_files, (std::vector<std::string>{"campaign.json", "summary.json", "tuning.json"}));
  EXPECT_THAT(*html_, HasSubstr("<meta name=\"armfault-campaign-hash\" content=\"" + hash + "\">"));
  EXPECT_THAT(*html_, HasSubstr("Campaign hash <code>" + hash +
                                "</code> (SHA-256 of the resolved campaign), carried by campaign.json, summary.json "
                                "and tuning.json, which agree."));
  EXPECT_THAT(RenderReportMarkdown(*data_), HasSubstr("Campaign hash `" + hash + "`"));
}

TEST_F(CampaignReportTest, HeatMapHoldsTheSummaryConfusionCounts) {
  const json summary = ReadJsonFile((*dir_ / "summary.json").string());
  const json& labels = summary["confusion"]["labels"];
  const json& counts = summary["confusion"]["counts"];
  const std::string spec = SpecById(*html_, "confusion");
  std::map<std::pair<std::string, std::string>, long> cells;
  const json parsed = json::parse(spec);
  for (const json& row : parsed.at("data").at("values")) {
    cells[{row.at("row").get<std::string>(), row.at("col").get<std::string>()}] = row.at("count").get<long>();
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

// The page without the text of its <script> elements (the inlined libraries and the specs),
// and the opening tags of those elements.
std::string WithoutScripts(const std::string& html, std::vector<std::string>* tags) {
  std::string out;
  size_t from = 0;
  for (size_t at = html.find("<script"); at != std::string::npos; at = html.find("<script", from)) {
    const size_t tag_end = html.find('>', at);
    const size_t end = html.find("</script>", at);
    if (tag_end == std::string::npos || end == std::string::npos) break;
    tags->push_back(html.substr(at, tag_end + 1 - at));
    out += html.substr(from, at - from);
    from = end + 9;
  }
  return out + html.substr(from);
}

TEST_F(CampaignReportTest, FetchesNothing) {
  std::vector<std::string> tags;
  const std::string page = WithoutScripts(*html_, &tags);
  EXPECT_THAT(page, Not(HasSubstr("http")));
  EXPECT_THAT(page, Not(HasSubstr("src=")));
  EXPECT_THAT(page, Not(HasSubstr("@import")));
  // Scripts: the three libraries and the page's own, inline, then one spec per plot; none
  // names a source.
  ASSERT_GE(tags.size(), 4u);
  EXPECT_EQ(std::count(tags.begin(), tags.end(), "<script>"), 4);
  for (const std::string& tag : tags) {
    EXPECT_TRUE(tag == "<script>" || tag.rfind("<script type=\"application/json\" class=\"vega-spec\" data-plot=\"", 0) == 0)
        << tag;
  }
  EXPECT_THAT(*html_, HasSubstr("vegaEmbed"));
  EXPECT_THAT(*html_, Not(HasSubstr("sourceMappingURL")));
  static const std::regex href("href=\"([^\"]*)\"");
  int links = 0;
  for (auto it = std::sregex_iterator(page.begin(), page.end(), href); it != std::sregex_iterator(); ++it) {
    EXPECT_EQ((*it)[1].str().substr(0, 1), "#") << (*it)[1].str();
    ++links;
  }
  EXPECT_GT(links, 0);
  static const std::regex url("url\\(([^)]*)\\)");
  for (auto it = std::sregex_iterator(page.begin(), page.end(), url); it != std::sregex_iterator(); ++it) {
    EXPECT_EQ((*it)[1].str().substr(0, 1), "#") << (*it)[1].str();
  }
}

TEST_F(CampaignReportTest, RunMarksNameTheirRunAndTheCampaignOfItsTraceCommand) {
  // The run view: every layer carries the run by calculation, and its tooltip names it.
  const json eff = json::parse(SpecById(*html_, "run-j3-efficiency"));
  const std::string run_id = data_->run.run_id;
  for (const json& layer : eff.at("layer")) {
    ASSERT_TRUE(layer.contains("transform")) << layer.dump();
    const json& t = layer["transform"];
    EXPECT_NE(std::find(t.begin(), t.end(), json({{"calculate", json(run_id).dump()}, {"as", "run"}})), t.end());
    EXPECT_TRUE(layer["encoding"].contains("tooltip")) << layer.dump();
  }
  // Every plot zooms: one interval selection bound to its scales (the heat map excepted).
  for (const char* id : {"roc", "pod-kt_degradation", "latency-distribution", "run-j3-current", "thesis-table-5-3"}) {
    int zooms = 0;
    const json plot = json::parse(SpecById(*html_, id));
    for (const json& layer : plot.at("layer")) {
      if (layer.contains("params")) zooms += layer["params"][0].value("bind", "") == "scales";
    }
    EXPECT_EQ(zooms, 1) << id;
  }
  // The latency dots name their runs, with family and joint.
  int named = 0;
  const json latency = json::parse(SpecById(*html_, "latency-distribution"));
  for (const json& layer : latency.at("layer")) {
    for (const json& row : layer["data"]["values"]) {
      if (!row.contains("run")) continue;
      ++named;
      EXPECT_TRUE(row.contains("family") && row.contains("joint")) << row.dump();
    }
  }
  EXPECT_GT(named, 0);
  // The command's campaign file, for the click handler.
  EXPECT_THAT(*html_, HasSubstr("<body data-campaign=\"" + (*dir_ / "campaign.json").string() + "\">"));
  EXPECT_THAT(*html_, HasSubstr("'armfault trace ' + quote(campaign) + ' --run ' + quote(d.run)"));
}

TEST_F(CampaignReportTest, RunViewShowsEveryJointTheFaultedOneFirst) {
  // The robot has three joints; the run's fault is on joint 3, which comes first.
  EXPECT_EQ(data_->run.joints, (std::vector<int>{3, 1, 2}));
  size_t last = 0;
  for (int j : {3, 1, 2}) {
    for (const char* panel : {"efficiency", "current", "torque"}) {
      const std::string id = "run-j" + std::to_string(j) + "-" + panel;
      EXPECT_FALSE(SpecById(*html_, id).empty()) << id;
    }
    const size_t at = html_->find("data-plot=\"run-j" + std::to_string(j) + "-efficiency\"");
    EXPECT_GT(at, last) << j;
    last = at;
  }
  EXPECT_THAT(*html_, HasSubstr("<h3>Joint 3 (faulted: kt_degradation)</h3>"));
  // Joint 1 does not move: its efficiency plot says why it is empty.
  EXPECT_THAT(SpecById(*html_, "run-j1-efficiency"), HasSubstr("Empty: the monitor judged no window of this joint"));
}

TEST_F(CampaignReportTest, SmallMultiplesShowEveryMissedOrMisnamedFaultyRun) {
  std::vector<std::string> expected;
  for (const RunRecord& r : Records()) {
    if (r.ok && !r.family.empty() && !r.miss_reason.empty() && r.excited()) expected.push_back(r.run_id);
  }
  ASSERT_FALSE(expected.empty()) << "the slight K_T loss is expected to be missed";
  ASSERT_EQ(data_->wrong_runs.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(data_->wrong_runs[k].run_id, expected[k]);
    const std::string spec = SpecById(*html_, "wrong-" + std::to_string(k));
    ASSERT_FALSE(spec.empty()) << k;
    const json plot = json::parse(spec);
    EXPECT_EQ(plot["title"]["text"], expected[k]);
    EXPECT_GT(DataPaths(spec), 0) << k;
    // Each of its marks is the run's: a click copies its trace command.
    for (const json& layer : plot["layer"]) {
      const json& t = layer["transform"];
      EXPECT_NE(std::find(t.begin(), t.end(), json({{"calculate", json(expected[k]).dump()}, {"as", "run"}})), t.end());
    }
  }
  EXPECT_EQ(SpecById(*html_, "wrong-" + std::to_string(expected.size())), "");
  // At most kSmallMultiples, however many were wrong; none without wrong faulty runs.
  ReportData d = *data_;
  d.wrong_runs.clear();
  EXPECT_THAT(RenderReportHtml(d), HasSubstr("None: every faulty run was detected and named with its family and joint"));
}

TEST_F(CampaignReportTest, EscapesNamesFromTheFiles) {
  ReportData d = *data_;
  d.summary["campaign"]["name"] = "<script>alert('x')</script> & co";
  d.summary["per_family"]["kt_degradation\"><b>"] = d.summary["per_family"]["kt_degradation"];
  const std::string html = RenderReportHtml(d);
  EXPECT_THAT(html, Not(HasSubstr("<script>alert")));
  EXPECT_THAT(html, HasSubstr("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; co"));
  EXPECT_THAT(html, HasSubstr("kt_degradation&quot;&gt;&lt;b&gt;"));
}

TEST_F(CampaignReportTest, ListsEveryWrongRunWithItsReasonAndTheNotExcitedApart) {
  long wrong = 0;
  std::string first_id, first_reason;
  for (const RunRecord& r : Records()) {
    if (!r.ok || r.miss_reason.empty()) continue;
    if (wrong++ == 0) first_id = r.run_id, first_reason = r.miss_reason;
  }
  ASSERT_GT(wrong, 0) << "the slight K_T loss is expected to be missed";
  EXPECT_EQ(data_->wrong_count, wrong);
  EXPECT_THAT(*html_, HasSubstr("<section id=\"why\"><h2>Runs scored wrong, and why</h2><p>" + std::to_string(wrong) + " runs missed"));
  EXPECT_THAT(*html_, HasSubstr("<tr><td><code>" + first_id + "</code></td><td>"));
  EXPECT_THAT(*html_, HasSubstr("None: every fault changed the hardware where a monitor could see it."));
  ReportData d = *data_;
  d.not_excited = {{"exp1/x/j2/r0", "joint 2 was asked to move 0 rad after the onset"}};
  d.not_excited_count = 1;
  EXPECT_THAT(RenderReportHtml(d), HasSubstr("Left out of every rate (summary.json lists them under not_excited_runs)."));
  EXPECT_THAT(RenderReportHtml(d), HasSubstr("<td>joint 2 was asked to move 0 rad after the onset</td>"));
}

TEST_F(CampaignReportTest, IsDeterministic) { EXPECT_EQ(RenderReportHtml(*data_), *html_); }

// The ids of the <section>s of a page, and the targets of its nav links, in page order.
std::vector<std::string> Matches(const std::string& html, const std::regex& re) {
  std::vector<std::string> out;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), re); it != std::sregex_iterator(); ++it) {
    out.push_back((*it)[1].str());
  }
  return out;
}

TEST_F(CampaignReportTest, NavLinksEverySectionOnceAndTheBoundaryOnlyWithBoundaryJson) {
  static const std::regex section("<section id=\"([^\"]+)\">");
  static const std::regex link("<a href=\"#([^\"]+)\">");
  const std::string nav = html_->substr(html_->find("<nav>"), html_->find("</nav>") - html_->find("<nav>"));
  const std::vector<std::string> ids = Matches(*html_, section);
  EXPECT_EQ(Matches(nav, link), ids);
  EXPECT_THAT(ids, Not(testing::Contains("boundary")));

  ReportData with_boundary = *data_;
  with_boundary.boundary = json{{"cells", json::array()}};
  const std::string html = RenderReportHtml(with_boundary);
  const std::string nav_b = html.substr(html.find("<nav>"), html.find("</nav>") - html.find("<nav>"));
  std::vector<std::string> sections = Matches(html, section);
  std::vector<std::string> links = Matches(nav_b, link);
  // The boundary section follows detection probability; its link comes last.
  EXPECT_EQ(sections, (std::vector<std::string>{"summary", "operating-point", "roc", "pod", "boundary",
                                                "latency-threshold", "confusion", "why", "wrong-runs", "latency", "thesis",
                                                "run"}));
  ASSERT_FALSE(links.empty());
  EXPECT_EQ(links.back(), "boundary");
  std::sort(sections.begin(), sections.end());
  std::sort(links.begin(), links.end());
  EXPECT_EQ(links, sections);
}

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
  EXPECT_EQ(data_->run.joints, (std::vector<int>{3, 1, 2}));  // every joint, the faulted one first
}

TEST_F(CampaignReportTest, ReSimulationMatchesTheRunsRecord) {
  const RunSeries& s = data_->run;
  ASSERT_TRUE(s.error.empty()) << s.error;
  ASSERT_TRUE(s.stored.has_value());
  EXPECT_EQ(ToJson(s.record).dump(), ToJson(*s.stored).dump());
  EXPECT_FALSE(s.monitor.windows.empty());
  ASSERT_EQ(s.i_cmd_A.size(), 3u);  // every joint
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
  EXPECT_THAT(SpecById(RenderReportHtml(d), "run-j3-torque"), HasSubstr("first alarm"));

  ro.run_id = "exp1/healthy/1";
  EXPECT_EQ(GatherReportData(ro).run.joints, (std::vector<int>{1, 2, 3}));  // no fault: every joint in order

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
  d.tuning_source = (*dir_ / "tuning.json").string() + " is absent: run `armfault tune " + dir_->string() + "`";
  const std::string html = RenderReportHtml(d);
  EXPECT_EQ(SpecById(html, "roc"), "");
  EXPECT_EQ(SpecById(html, "latency-threshold-kt_degradation"), "");
  const std::string hint = "No tuning results: " + (*dir_ / "tuning.json").string() +
                           " is absent: run <code>armfault tune " + dir_->string() + "</code>.";
  size_t n = 0;
  for (size_t p = html.find(hint); p != std::string::npos; p = html.find(hint, p + 1)) ++n;
  EXPECT_EQ(n, 3u);  // operating point, ROC, latency against threshold
  // Detection probability as run needs no tuning; it says the tuned curve is missing and why.
  EXPECT_GT(DataPaths(SpecById(html, "pod-kt_degradation")), 0);
  EXPECT_THAT(html, HasSubstr("No tuned curve: " + (*dir_ / "tuning.json").string() + " is absent"));
  // The rest is still there.
  EXPECT_FALSE(SpecById(html, "confusion").empty());
  EXPECT_FALSE(SpecById(html, "run-j3-efficiency").empty());
  EXPECT_THAT(RenderReportMarkdown(d), HasSubstr("No tuning results: " + (*dir_ / "tuning.json").string() +
                                                 " is absent: run `armfault tune " + dir_->string() + "`."));

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

TEST_F(CampaignReportTest, WithoutTuningJsonTheTunersDefaultsAreShownAndSaidSo) {
  ScratchDir scratch("report_no_tuning");
  fs::copy(*dir_, scratch.path(), fs::copy_options::recursive);
  fs::remove(scratch.path() / "tuning.json");
  ReportOptions ro;
  ro.dir = scratch.path().string();
  const ReportData d = GatherReportData(ro);
  ASSERT_TRUE(d.tuning.has_value());
  EXPECT_EQ((*d.tuning)["campaign_hash"], d.campaign_hash);
  EXPECT_THAT(d.tuning_source, HasSubstr("computed now with the tuner's defaults"));
  EXPECT_THAT(RenderReportHtml(d), HasSubstr("run <code>armfault tune " + ro.dir + "</code> to write it"));
}

TEST_F(CampaignReportTest, RefusesFilesOfAnotherCampaign) {
  ScratchDir scratch("report_mixed");
  fs::copy(*dir_, scratch.path(), fs::copy_options::recursive);
  ReportOptions ro;
  ro.dir = scratch.path().string();
  const std::string tuning = (scratch.path() / "tuning.json").string();
  const std::string campaign = (scratch.path() / "campaign.json").string();
  json t = ReadJsonFile(tuning);

  // tuning.json of another campaign.
  t["campaign_hash"] = "sha256:" + std::string(64, '0');
  std::ofstream(tuning, std::ios::trunc) << t.dump();
  InputError e = ErrorOf([&] { GatherReportData(ro); });
  EXPECT_EQ(e.source(), tuning);
  EXPECT_THAT(e.what(), HasSubstr("belongs to campaign sha256:0000"));
  EXPECT_THAT(e.what(), HasSubstr("but " + campaign + " to campaign " + CampaignHash(campaign_->resolved)));
  EXPECT_THAT(e.what(), HasSubstr("run `armfault tune " + ro.dir + "` to tune this directory's campaign again"));

  // tuning.json without a hash (an older armfault, or another campaign).
  t.erase("campaign_hash");
  std::ofstream(tuning, std::ios::trunc) << t.dump();
  e = ErrorOf([&] { GatherReportData(ro); });
  EXPECT_EQ(e.source(), tuning);
  EXPECT_THAT(e.what(), HasSubstr("carries no campaign_hash"));
  EXPECT_THAT(e.what(), HasSubstr("run `armfault tune " + ro.dir + "`"));

  // summary.json of another campaign.
  fs::copy_file(*dir_ / "tuning.json", tuning, fs::copy_options::overwrite_existing);
  json s = ReadJsonFile((scratch.path() / "summary.json").string());
  s["campaign"]["seed"] = 12;
  s["campaign_hash"] = CampaignHash(s["campaign"]);
  std::ofstream(scratch.path() / "summary.json", std::ios::trunc) << s.dump();
  e = ErrorOf([&] { GatherReportData(ro); });
  EXPECT_EQ(e.source(), (scratch.path() / "summary.json").string());
  EXPECT_THAT(e.what(), HasSubstr(campaign));

  // results.jsonl of another campaign (the same run ids, another seed).
  fs::copy_file(*dir_ / "summary.json", scratch.path() / "summary.json", fs::copy_options::overwrite_existing);
  std::string lines;
  for (RunRecord r : Records()) {
    r.seed ^= 1;
    lines += ToJson(r).dump() + "\n";
  }
  std::ofstream(scratch.path() / "results.jsonl", std::ios::trunc) << lines;
  e = ErrorOf([&] { GatherReportData(ro); });
  EXPECT_EQ(e.source(), (scratch.path() / "results.jsonl").string());
  EXPECT_THAT(e.what(), HasSubstr("line 1: run \"" + Records().front().run_id + "\" has seed"));
}

TEST_F(CampaignReportTest, MarkdownHasHeadlineOperatingPointA90AndFloors) {
  const std::string md = RenderReportMarkdown(*data_);
  EXPECT_THAT(md, HasSubstr("# armfault report: report-test"));
  EXPECT_THAT(md, HasSubstr("| detection |"));
  EXPECT_THAT(md, HasSubstr("| false alarm |"));
  EXPECT_THAT(md, HasSubstr("| alarm before onset |"));
  EXPECT_THAT(md, HasSubstr("Rule: max_detection (false_alarm_ceiling = 0.05)"));
  EXPECT_THAT(md, HasSubstr("kt_factor.worn = 0.95"));
  EXPECT_THAT(md, HasSubstr("| family | magnitude | a90 as run | a90/95 as run | a90 at the operating point |"));
  EXPECT_THAT(md, HasSubstr("| kt_degradation | kt_factor | "));
  EXPECT_THAT(md, HasSubstr("| 0.87 | 0.8418 |"));  // the fixture's fit at the operating point
  EXPECT_THAT(md, HasSubstr("| torque_sensor_stuck | lead | named variants | named variants |"));
  EXPECT_THAT(md, HasSubstr("| detection_rate | ≥ 0.500 |"));
  EXPECT_THAT(md, HasSubstr("| per_family/torque_sensor_stuck/detection_rate |"));
}

TEST_F(CampaignReportTest, MarkdownCarriesNoRawHtmlFromTheInputs) {
  ReportData d = *data_;
  d.summary["campaign"]["name"] = "<script>alert(1)</script> & co";
  d.tuning.reset();
  d.tuning_source = "dir <b>x</b>";
  const std::string md = RenderReportMarkdown(d);
  EXPECT_THAT(md, HasSubstr("# armfault report: &lt;script&gt;alert(1)&lt;/script&gt; &amp; co"));
  EXPECT_THAT(md, HasSubstr("No tuning results: dir &lt;b&gt;x&lt;/b&gt;."));
  EXPECT_THAT(md, Not(HasSubstr("<script>")));
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
