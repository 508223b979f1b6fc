// The run directory (campaigns/running/run_dir.h): the one reader of run records, the table of outputs
// written from results.jsonl, --summary-only's rows.
#include "campaigns/running/run_dir.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/base/json_input.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using testing_support::ErrorOf;
using testing_support::ReadAll;
using testing_support::ScratchDir;

RunRecord Record(long index, bool detected) {
  RunRecord r;
  r.case_index = index;
  r.run_id = "exp1/kt#0/j3/r" + std::to_string(index);
  r.trajectory = "exp1";
  r.family = "kt_degradation";
  r.joint = 3;
  r.onset_s = 1;
  r.detected = detected;
  return r;
}

std::string Lines(const std::vector<RunRecord>& records) {
  std::string text;
  for (const RunRecord& r : records) text += ToJson(r).dump() + "\n";
  return text;
}

CampaignSpec SmallCampaign() {
  return CampaignSpecFromJson(nlohmann::json::parse(R"({"name": "small", "duration_s": 2,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.6, "onset_s": 1}],
    "floors": {"detection_rate": 0.5}})"),
                          "c.json", ".");
}

TEST(RunDir, ReadRunRecordsNamesTheFileAndLine) {
  ScratchDir dir("run_dir");
  const std::string path = dir.Write("results.jsonl", Lines({Record(0, true)}) + "{\"case\": 1, not json\n");
  std::vector<long> seen;
  const InputError e = ErrorOf([&] { ReadRunRecords(path, {}, [&](RunRecord&& r, long) { seen.push_back(r.case_index); }); });
  EXPECT_THAT(std::string(e.what()), HasSubstr(path + ": line 2: "));
  EXPECT_EQ(seen, std::vector<long>({0}));
}

TEST(RunDir, ReadRunRecordsIgnoresUnknownKeysAndSaysWhatTheCallerRefuses) {
  ScratchDir dir("run_dir");
  nlohmann::json extra = ToJson(Record(0, true));
  extra["decision"] = {{"anything", 1}};  // a newer key
  const std::string path = dir.Write("results.jsonl", extra.dump() + "\n" + Lines({Record(1, false)}));
  long n = 0;
  ReadRunRecords(path, {}, [&](RunRecord&&, long line) { EXPECT_EQ(line, ++n); });
  EXPECT_EQ(n, 2);
  const InputError e = ErrorOf([&] {
    ReadRunRecords(path, {}, [&](RunRecord&& r, long) {
      if (!r.detected) throw std::runtime_error("not detected");
    });
  });
  EXPECT_THAT(std::string(e.what()), HasSubstr(path + ": line 2: not detected"));
}

TEST(RunDir, AnErrorAboutAFileReadInStepKeepsItsOwnFile) {
  ScratchDir dir("run_dir");
  const std::string path = dir.Write("results.jsonl", Lines({Record(0, true), Record(1, true)}));
  const InputError other = ErrorOf([&] {
    ReadRunRecords(path, {}, [&](RunRecord&&, long line) {
      if (line == 2) throw InputError("decisions.jsonl", "", "line 2: cut");
    });
  });
  EXPECT_EQ(other.source(), "decisions.jsonl");
  EXPECT_THAT(std::string(other.what()), Not(HasSubstr("results.jsonl")));
  const InputError own = ErrorOf([&] {
    ReadRunRecords(path, {}, [&](RunRecord&&, long) { throw InputError("", "/x", "no source"); });
  });
  EXPECT_EQ(own.source(), path);
  EXPECT_THAT(std::string(own.what()), HasSubstr("line 1: "));
}

TEST(RunDir, ReadRunRecordsSaysTheCallersOpenErrorAndSkipsBlankLinesOnlyWhenAsked) {
  ScratchDir dir("run_dir");
  JsonLinesOptions options;
  options.open_error = "cannot read the file (run `armfault run` first)";
  const std::string missing = (dir.path() / "results.jsonl").string();
  EXPECT_THAT(std::string(ErrorOf([&] { ReadRunRecords(missing, options, [](RunRecord&&, long) {}); }).what()),
              HasSubstr(missing + ": (document root): cannot read the file (run `armfault run` first)"));
  const std::string path = dir.Write("results.jsonl", Lines({Record(0, true)}) + "  \n" + Lines({Record(1, true)}));
  EXPECT_THAT(std::string(ErrorOf([&] { ReadRunRecords(path, {}, [](RunRecord&&, long) {}); }).what()),
              HasSubstr(": line 2: "));
  options.skip_blank = true;
  std::vector<long> lines;
  ReadRunRecords(path, options, [&](RunRecord&&, long line) { lines.push_back(line); });
  EXPECT_EQ(lines, std::vector<long>({1, 3}));
}

TEST(RunDir, CompleteRunRecordsStopsAtALineCutByAKill) {
  ScratchDir dir("run_dir");
  const std::string whole = Lines({Record(0, true), Record(1, true)});
  const std::string path = dir.Write("results.jsonl", whole + ToJson(Record(2, true)).dump().substr(0, 30));
  EXPECT_EQ(CompleteRunRecords(path).size(), 2u);
  EXPECT_TRUE(CompleteRunRecords(dir.path() / "absent.jsonl").empty());
}

TEST(RunDir, EveryRecordOutputIsAFileOfTheDirectory) {
  for (const RecordOutputRow& row : RecordOutputs()) {
    bool listed = false;
    for (const RunDirFile& f : RunDirFiles()) listed = listed || std::string(f.name) == row.file;
    EXPECT_TRUE(listed) << row.file;
  }
}

TEST(RunDir, WriteRecordOutputsWritesEveryRowAndSummaryOnlyTheKeptOnes) {
  const CampaignSpec campaign = SmallCampaign();
  ScratchDir dir("run_dir");
  dir.Write("results.jsonl", Lines({Record(0, true), Record(1, false)}));
  const RecordOutputsResult full = WriteRecordOutputs(dir.path(), campaign, false);
  EXPECT_EQ(full.summary.runs(), 2);
  ASSERT_EQ(full.verdicts.size(), 1u);
  EXPECT_TRUE(full.verdicts[0].met);  // 1 of 2 >= 0.5
  const std::string csv = ReadAll(dir.path() / "results.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);  // header + 2 rows
  EXPECT_THAT(ReadAll(dir.path() / "summary.json"), HasSubstr("\"detection_rate\""));
  EXPECT_THAT(ReadAll(dir.path() / "junit.xml"), HasSubstr("<testsuite"));

  ScratchDir small("run_dir_small");
  small.Write("results.jsonl", Lines({Record(0, true), Record(1, false)}));
  small.Write("results.csv", "stale\n");
  small.Write("decisions.jsonl", "{}\n");
  WriteRecordOutputs(small.path(), campaign, true);
  RemoveNotKeptBySummaryOnly(small.path());
  EXPECT_FALSE(fs::exists(small.path() / "results.csv"));
  EXPECT_FALSE(fs::exists(small.path() / "decisions.jsonl"));
  EXPECT_EQ(ReadAll(small.path() / "summary.json"), ReadAll(dir.path() / "summary.json"));
  EXPECT_EQ(ReadAll(small.path() / "junit.xml"), ReadAll(dir.path() / "junit.xml"));
}

TEST(RunDir, WriteRecordOutputsRefusesACaseTwiceNamingTheLine) {
  ScratchDir dir("run_dir");
  dir.Write("results.jsonl", Lines({Record(0, true), Record(1, true), Record(1, true)}));
  const InputError e = ErrorOf([&] { WriteRecordOutputs(dir.path(), SmallCampaign(), false); });
  EXPECT_THAT(std::string(e.what()), HasSubstr("results.jsonl: line 3: case 1 (run \"exp1/kt#0/j3/r1\") comes after case 1"));
  EXPECT_FALSE(fs::exists(dir.path() / "summary.json"));
}

TEST(RunDir, AnEarlyStoppedRunsDecisionsGoIntoTheSummary) {
  ScratchDir dir("run_dir");
  dir.Write("results.jsonl", Lines({Record(0, true)}));
  dir.Write("early_stop.json", R"({"floors": [{"name": "detection_rate", "decided": true, "met": false}]})");
  const RecordOutputsResult r = WriteRecordOutputs(dir.path(), SmallCampaign(), false);
  EXPECT_EQ(r.early_stop_decided.at("detection_rate"), false);
  EXPECT_THAT(ReadAll(dir.path() / "summary.json"), HasSubstr("\"early_stop\""));
}

TEST(RunDir, WriteAtomicallyNeverWritesThroughALinkAndLeavesNoHalfFile) {
  ScratchDir dir("run_dir");
  const std::string target = dir.Write("precious.txt", "precious\n");
  fs::create_symlink(target, dir.path() / "summary.json.tmp");
  EXPECT_THAT(ErrorOf([&] { WriteAtomically(dir.path() / "summary.json", "{}\n"); }).message(),
              HasSubstr("is a symbolic link"));
  EXPECT_EQ(ReadAll(target), "precious\n");
  // A link at the name itself is replaced, not written through.
  fs::remove(dir.path() / "summary.json.tmp");
  fs::create_symlink(target, dir.path() / "summary.json");
  WriteAtomically(dir.path() / "summary.json", "{}\n");
  EXPECT_FALSE(fs::is_symlink(dir.path() / "summary.json"));
  EXPECT_EQ(ReadAll(target), "precious\n");
  EXPECT_EQ(ReadAll(dir.path() / "summary.json"), "{}\n");
}

}  // namespace
}  // namespace armfault
