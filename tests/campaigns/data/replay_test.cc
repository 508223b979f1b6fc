// `armfault replay`: a monitor run over an export's recorded signals gives the campaign's own
// results, line for line; unlabelled runs count for false alarms only, per hour of operation;
// --commission fits the monitor on a named healthy run; bad inputs name their path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <sstream>

#include "campaigns/spec/campaign.h"
#include "campaigns/data/export.h"
#include "campaigns/data/replay.h"
#include "campaigns/running/run_dir.h"
#include "campaigns/running/runner.h"
#include "core/base/distributions.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::ScratchDir;

namespace fs = std::filesystem;

// Compound and drawn onsets, commissioned units with datasheet tolerances: what the replay must
// reproduce without the plant.
Campaign Bench() {
  return CampaignFromJson(json::parse(R"({
    "name": "replay", "seed": 5, "duration_s": 4,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.6, "onset_s": 1.0},
               {"family": "friction_increase", "joint": 3, "friction_factor": 2.5, "onset_s": {"uniform": [1.0, 2.0]}},
               {"compound": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.6, "onset_s": 1.5},
                             {"family": "friction_increase", "joint": 3, "friction_factor": 3, "onset_s": 1.0}],
                "name": "kt+friction"}],
    "healthy": 3,
    "variation": {"tolerances": "datasheet", "units": 1},
    "commissioning": true
  })"),
                          "c.json", ".");
}

std::string Slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

std::vector<json> ReadLines(const fs::path& path) {
  std::ifstream in(path);
  std::vector<json> out;
  std::string line;
  while (std::getline(in, line)) out.push_back(json::parse(line));
  return out;
}

std::string ExportTo(const Campaign& c, const fs::path& dir) {
  ExportOptions o;
  o.output_dir = dir.string();
  o.threads = 2;
  ExportCampaign(c, o);
  return o.output_dir;
}

ReplayOptions Replay(const std::string& dir, const fs::path& out, int threads = 2) {
  ReplayOptions o;
  o.dir = dir;
  o.output_dir = out.string();
  o.threads = threads;
  return o;
}

TEST(Replay, AnExportReplayedIsTheRunLineForLine) {
  const Campaign c = Bench();
  ScratchDir dir("replay_same");
  RunnerOptions ro;
  ro.output_dir = (dir.path() / "run").string();
  ro.threads = 2;
  RunCampaign(c, ro);
  const std::string x = ExportTo(c, dir.path() / "x");
  const ReplayResult r = ReplayDirectory(Replay(x, dir.path() / "r2", 2));
  EXPECT_EQ(r.runs, 6);
  EXPECT_EQ(r.failed, 0);
  // Byte for byte: every field of every record (drawn onsets in full, compound elements, the
  // unit's commissioning), and the decision statistics `tune` re-scores.
  EXPECT_EQ(Slurp(dir.path() / "r2" / "results.jsonl"), Slurp(dir.path() / "run" / "results.jsonl"));
  EXPECT_EQ(Slurp(dir.path() / "r2" / "decisions.jsonl"), Slurp(dir.path() / "run" / "decisions.jsonl"));
  EXPECT_EQ(Slurp(dir.path() / "r2" / "campaign.json"), Slurp(dir.path() / "run" / "campaign.json"));
  int detected = 0;
  for (const json& line : ReadLines(dir.path() / "r2" / "results.jsonl")) detected += line["detected"].get<bool>();
  EXPECT_GE(detected, 2);  // not two empty diagnoses
  // Any thread count: the same bytes.
  ReplayDirectory(Replay(x, dir.path() / "r1", 1));
  EXPECT_EQ(Slurp(dir.path() / "r1" / "results.jsonl"), Slurp(dir.path() / "r2" / "results.jsonl"));
  EXPECT_EQ(Slurp(dir.path() / "r1" / "alarms_per_hour.json"), Slurp(dir.path() / "r2" / "alarms_per_hour.json"));
  const json alarms = json::parse(Slurp(dir.path() / "r2" / "alarms_per_hour.json"));
  EXPECT_EQ(alarms["healthy_runs"], 3);
  EXPECT_EQ(alarms["unlabelled_runs"], 0);
  EXPECT_NEAR(alarms["hours"].get<double>(), 3 * 4.0 / 3600, 1e-12);  // 0 .. 4 s each
}

TEST(Replay, PoissonUpperBound) {
  EXPECT_NEAR(PoissonUpperBound(0, 0.95), 2.995732273553991, 1e-12);  // -ln(0.05)
  EXPECT_NEAR(PoissonUpperBound(1, 0.95), 4.743864518, 1e-8);
  EXPECT_NEAR(PoissonUpperBound(10, 0.95), 16.9622, 1e-4);  // Garwood's table
}

// A manifest of an import: a faulty run whose label is unknown (its "family" key gone), a row
// with nothing but run_id and signals, a "healthy" label: all scored for false alarms only, and
// the alarm onsets of the unlabelled faulty run counted per hour.
TEST(Replay, UnlabelledRunsCountForFalseAlarmsPerHour) {
  const Campaign c = CampaignFromJson(json::parse(R"({
    "name": "unlabelled", "seed": 11, "duration_s": 4,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.5, "onset_s": 1.0}],
    "healthy": 2
  })"),
                                      "c.json", ".");
  ScratchDir dir("replay_unlabelled");
  const std::string x = ExportTo(c, dir.path() / "x");
  std::vector<json> manifest = ReadLines(fs::path(x) / "manifest.jsonl");
  ASSERT_EQ(manifest.size(), 3u);
  // What the runs scored as labelled: the fault detected.
  ReplayDirectory(Replay(x, dir.path() / "labelled"));
  ASSERT_TRUE(ReadLines(dir.path() / "labelled" / "results.jsonl")[0]["detected"].get<bool>());
  manifest[0].erase("family");                                                      // no label at all
  manifest[1] = {{"run_id", manifest[1]["run_id"]}, {"signals", manifest[1]["signals"]}};  // an import's bare row
  manifest[2]["family"] = "healthy";
  std::string text;
  for (const json& m : manifest) text += m.dump() + "\n";
  std::ofstream(fs::path(x) / "manifest.jsonl") << text;
  const ReplayResult r = ReplayDirectory(Replay(x, dir.path() / "r"));
  const std::vector<json> results = ReadLines(dir.path() / "r" / "results.jsonl");
  EXPECT_EQ(results[0]["label"], "unlabelled");
  EXPECT_TRUE(results[0]["family"].is_null());
  EXPECT_TRUE(results[0]["detected"].get<bool>());  // an alarm on a run not known faulty: a false alarm
  EXPECT_EQ(results[1]["label"], "unlabelled");
  EXPECT_FALSE(results[2].contains("label"));  // "healthy" is a label
  EXPECT_EQ(r.alarms.unlabelled_runs, 2);
  EXPECT_EQ(r.alarms.healthy_runs, 1);
  EXPECT_GE(r.alarms.alarm_onsets, 1);
  const json alarms = json::parse(Slurp(dir.path() / "r" / "alarms_per_hour.json"));
  const double hours = 3 * 4.0 / 3600;
  EXPECT_NEAR(alarms["hours"].get<double>(), hours, 1e-12);
  EXPECT_DOUBLE_EQ(alarms["per_hour"].get<double>(), static_cast<double>(r.alarms.alarm_onsets) / alarms["hours"].get<double>());
  EXPECT_DOUBLE_EQ(alarms["per_hour_upper_95"].get<double>(),
                   PoissonUpperBound(r.alarms.alarm_onsets, 0.95) / alarms["hours"].get<double>());
  // The records read back as records (summary, report, diff): the label kept.
  RunRecord back = RunRecordFromJson(results[0]);
  EXPECT_TRUE(back.unlabelled);
  EXPECT_EQ(ToJson(back), results[0]);
}

TEST(Replay, CommissionsFromANamedHealthyRun) {
  const Campaign c = CampaignFromJson(json::parse(R"({
    "name": "commission", "seed": 3, "duration_s": 4,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.7, "onset_s": 1.0}],
    "healthy": 3
  })"),
                                      "c.json", ".");
  ScratchDir dir("replay_commission");
  const std::string x = ExportTo(c, dir.path() / "x");
  ReplayDirectory(Replay(x, dir.path() / "datasheet"));
  ReplayOptions o = Replay(x, dir.path() / "c2", 2);
  o.commission_run = "exp1/healthy/0";
  const ReplayResult r = ReplayDirectory(o);
  // The monitor learnt the unit: its statistics are not the datasheet monitor's.
  EXPECT_NE(Slurp(dir.path() / "c2" / "decisions.jsonl"), Slurp(dir.path() / "datasheet" / "decisions.jsonl"));
  EXPECT_EQ(r.alarms.excluded_run, "exp1/healthy/0");
  EXPECT_EQ(r.alarms.healthy_runs, 2);  // the run it learnt on is not counted
  o.output_dir = (dir.path() / "c1").string();
  o.threads = 1;
  ReplayDirectory(o);
  EXPECT_EQ(Slurp(dir.path() / "c1" / "results.jsonl"), Slurp(dir.path() / "c2" / "results.jsonl"));
  EXPECT_EQ(Slurp(dir.path() / "c1" / "decisions.jsonl"), Slurp(dir.path() / "c2" / "decisions.jsonl"));

  o.commission_run = "exp1/helthy/0";
  InputError e = ErrorOf([&] { ReplayDirectory(o); });
  EXPECT_EQ(e.source(), "--commission");
  EXPECT_THAT(e.message(), HasSubstr("unknown run \"exp1/helthy/0\""));
  EXPECT_EQ(e.hint(), "did you mean \"exp1/healthy/0\"?");
  o.commission_run = ReadLines(fs::path(x) / "manifest.jsonl")[0]["run_id"];
  e = ErrorOf([&] { ReplayDirectory(o); });
  EXPECT_THAT(e.message(), HasSubstr("is labelled faulty (kt_degradation on joint 3)"));
}

TEST(Replay, BadInputsNameTheirPath) {
  const Campaign c = CampaignFromJson(json::parse(R"({
    "name": "bad", "seed": 3, "duration_s": 2,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [], "healthy": 1
  })"),
                                      "c.json", ".");
  ScratchDir dir("replay_bad");
  const std::string x = ExportTo(c, dir.path() / "x");
  ReplayOptions o = Replay(x, dir.path() / "r");
  // --monitor: errors name the file and the pointer within it.
  o.monitor_file = dir.Write("m.json", R"({"type": "power_efficency"})");
  InputError e = ErrorOf([&] { ReplayDirectory(o); });
  EXPECT_EQ(e.source(), o.monitor_file);
  EXPECT_EQ(e.pointer(), "/type");
  o.monitor_file = dir.Write("m2.json", R"({"type": "power_efficiency", "significance": "low"})");
  e = ErrorOf([&] { ReplayDirectory(o); });
  EXPECT_EQ(e.source(), o.monitor_file);
  EXPECT_EQ(e.pointer(), "/significance");
  o.monitor_file = dir.Write("m3.json", "[1, 2]");
  e = ErrorOf([&] { ReplayDirectory(o); });
  EXPECT_EQ(e.source(), o.monitor_file);
  EXPECT_THAT(e.message(), HasSubstr("expected a JSON object as a campaign's \"monitor\" key, got [1,2]"));
  // A good one is recorded as the campaign's monitor.
  o.monitor_file = dir.Write("m4.json", R"({"type": "power_efficiency", "significance": 4})");
  const ReplayResult r = ReplayDirectory(o);
  EXPECT_EQ(ReadCampaignFileJson(dir.path() / "r")["campaign"]["monitor"]["significance"], 4);
  EXPECT_EQ(r.campaign.monitor.type, "power_efficiency");
  o.monitor_file.clear();

  // No such directory; no manifest.
  o.dir = (dir.path() / "nope").string();
  e = ErrorOf([&] { ReplayDirectory(o); });
  EXPECT_EQ(e.source(), o.dir);
  EXPECT_THAT(e.message(), HasSubstr("no such directory"));
  o.dir = x;
  fs::rename(fs::path(x) / "manifest.jsonl", fs::path(x) / "m.jsonl");
  e = ErrorOf([&] { ReplayDirectory(o); });
  EXPECT_EQ(e.source(), (fs::path(x) / "manifest.jsonl").string());
  fs::rename(fs::path(x) / "m.jsonl", fs::path(x) / "manifest.jsonl");
  // A signals file cut short (its compressed stream ends early): zlib's reason, not a run with
  // its end missing.
  const fs::path signals = fs::path(x) / "runs" / "000000.csv.gz";
  {
    std::ifstream in(signals, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(signals, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
  }
  e = ErrorOf([&] { ReplayDirectory(o); });
  EXPECT_EQ(e.source(), signals.string());
  EXPECT_THAT(e.message(), HasSubstr("cannot read: unexpected end of file (cut short or corrupt)"));
  // A damaged signals file: its line and column.
  std::ofstream(signals) << SignalsCsvHeader(3) << "0,1,2\n";
  e = ErrorOf([&] { ReplayDirectory(o); });
  EXPECT_EQ(e.source(), signals.string());
  EXPECT_THAT(e.message(), HasSubstr("line 2: 3 cells, expected 28"));
  std::ofstream(signals) << "t,q\n";
  EXPECT_THAT(ErrorOf([&] { ReplayDirectory(o); }).message(), HasSubstr("line 1: column 1 is \"t\", expected \"t_s\""));
}

}  // namespace
}  // namespace armfault
