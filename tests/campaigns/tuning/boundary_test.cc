// The boundary search (campaigns/tuning/boundary.h, `armfault boundary`): bad "search" input, the
// batch planner on a synthetic cell, and a small real search that is the same for any thread
// count, resumes to the same bytes and whose runs re-run exactly from campaign.json.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "campaigns/tuning/boundary.h"
#include "campaigns/spec/campaign.h"
#include "campaigns/running/runner.h"
#include "core/base/json_input.h"
#include "core/base/rng.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;
using testing_support::ErrorOf;
using testing_support::Lines;
using testing_support::ReadAll;

// A short search: K_T on the moving top joint, 3 s runs, batches of 4, at most 12 runs.
nlohmann::json SmallSearch() {
  return nlohmann::json::parse(R"({
    "name": "small-search", "seed": 5, "duration_s": 3,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [0.8, 0.99], "onset_s": {"uniform": [0.8, 1.2]}}],
    "variation": {"torque_noise_Nm": {"uniform": [0.02, 0.06]}, "payload_kg": {"uniform": [0, 0.5]}},
    "search": {"batch": 4, "max_runs": 12}
  })");
}

std::vector<std::string> ErrorLines(const nlohmann::json& campaign) {
  return ErrorReportLines(ErrorOf([&] { CampaignFromJson(campaign, "c.json", "."); }));
}

bool HasLine(const std::vector<std::string>& lines, const std::string& start) {
  for (const std::string& l : lines) {
    if (l.rfind(start, 0) == 0) return true;
  }
  return false;
}

std::string Joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const std::string& l : lines) s += l + "\n";
  return s;
}

TEST(BoundarySearch, OneSidedZIsTheNormalQuantile) {
  // mpmath at 40 digits: sqrt(2) erfinv(2 c - 1) of the double c; within a few ulps.
  EXPECT_NEAR(OneSidedZ(0.95), 1.644853626951472284276316, 2e-15);
  EXPECT_NEAR(OneSidedZ(0.9), 1.281551565544600593487448, 2e-15);
  EXPECT_NEAR(OneSidedZ(0.999), 3.090232306167813277758202, 4e-15);
  EXPECT_EQ(OneSidedZ(0.5), 0.0);
}

TEST(BoundarySearch, BadInputNamesFilePointerAndValue) {
  {  // a family without a magnitude
    nlohmann::json c = SmallSearch();
    c["faults"][0] = {{"family", "torque_sensor_stuck"}, {"joint", 3}, {"lead", "open"}, {"onset_s", 1}};
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /faults/0/family: \"torque_sensor_stuck\" has no magnitude to search")) << Joined(lines);
  }
  {  // an inverted range
    nlohmann::json c = SmallSearch();
    c["search"]["range"] = {0.95, 0.8};
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /search/range/0: inverted search range: low 0.95 is greater than high 0.8")) << Joined(lines);
  }
  {  // an empty range
    nlohmann::json c = SmallSearch();
    c["search"]["range"] = {0.9, 0.9};
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /search/range: empty search range [0.9, 0.9]")) << Joined(lines);
  }
  {  // an entry with one magnitude and no range: nothing to search
    nlohmann::json c = SmallSearch();
    c["faults"][0]["kt_factor"] = 0.9;
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /faults/0/kt_factor: empty search range: \"kt_factor\" is the one value 0.9")) << Joined(lines);
  }
  {  // the healthy value in the range
    nlohmann::json c = SmallSearch();
    c["search"]["range"] = {0.8, 1.0};
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /search/range/1: kt_degradation: kt_factor 1 is no fault")) << Joined(lines);
  }
  {  // the healthy value at the end of the entry's own list: the element named
    nlohmann::json c = SmallSearch();
    c["faults"][0]["kt_factor"] = {0.8, 0.9, 1.0};
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /faults/0/kt_factor/2: kt_degradation: kt_factor 1 is no fault")) << Joined(lines);
  }
  {  // a magnitude the family refuses
    nlohmann::json c = SmallSearch();
    c["search"]["range"] = {-0.5, 0.9};
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /search/range/0: kt_degradation: -0.5 must be greater than 0")) << Joined(lines);
  }
  {  // a joint the robot lacks
    nlohmann::json c = SmallSearch();
    c["faults"][0]["joint"] = 7;
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /faults/0/joint: kt_degradation: joint 7 does not exist")) << Joined(lines);
  }
  {  // an unknown key, and a batch below 2
    nlohmann::json c = SmallSearch();
    c["search"]["targte"] = 0.9;
    c["search"]["batch"] = 1;
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /search/targte: unknown key \"targte\"")) << Joined(lines);
    EXPECT_TRUE(HasLine(lines, "c.json: /search/batch: 1 is outside [2, 1000]")) << Joined(lines);
  }
  {  // another swept key in a searched entry
    nlohmann::json c = SmallSearch();
    c["faults"][0]["onset_s"] = {1.0, 2.0};
    const auto lines = ErrorLines(c);
    EXPECT_TRUE(HasLine(lines, "c.json: /faults/0/onset_s: a searched entry takes one value")) << Joined(lines);
  }
}

TEST(BoundarySearch, DefaultsAndRunsMakeTheCases) {
  nlohmann::json c = SmallSearch();
  const Campaign grid = CampaignFromJson(c, "c.json", ".");
  EXPECT_EQ(CaseCount(grid), 2);  // without runs, `run` runs the grid
  EXPECT_DOUBLE_EQ(grid.search.target, 0.9);
  EXPECT_DOUBLE_EQ(grid.search.confidence, 0.95);
  EXPECT_DOUBLE_EQ(grid.search.entries[0].low, 0.8);
  EXPECT_DOUBLE_EQ(grid.search.entries[0].high, 0.99);
  c["search"]["runs"] = nlohmann::json::parse(R"([{"trajectory": "exp1", "entry": 0, "joint": 3, "magnitude": 0.9},
                                                   {"trajectory": "exp1", "entry": 0, "joint": 3, "magnitude": 0.9}])");
  const Campaign runs = CampaignFromJson(c, "c.json", ".");
  ASSERT_EQ(CaseCount(runs), 2);
  const CaseSpec a = CaseAt(runs, 0), b = CaseAt(runs, 1);
  EXPECT_EQ(a.run_id, "exp1/kt_degradation#0/kt_factor=0.9/j3/s0");
  EXPECT_EQ(b.run_id, "exp1/kt_degradation#0/kt_factor=0.9/j3/s1");
  EXPECT_NE(a.seed, b.seed);
  EXPECT_EQ(a.fault["kt_factor"], 0.9);
  EXPECT_EQ(a.group, "kt_degradation kt_factor=0.9 joint=3");
}

// A K_T factor range searched to 0.02 on a 1e-4 lattice.
SearchEntryRange KtRange(double low, double high) {
  SearchEntryRange range;
  range.key = "kt_factor";
  range.low = low;
  range.high = high;
  range.tolerance = 0.02;
  range.lattice = 1e-4;
  return range;
}

// A synthetic cell: detection probability logistic in log severity with a known a90. The
// search must end near it within its budget.
TEST(BoundarySearch, PlannerConvergesOnASyntheticCell) {
  SearchSpec spec;
  spec.present = true;
  spec.batch = 8;
  spec.max_runs = 200;
  const SearchEntryRange range = KtRange(0.80, 0.995);
  // PoD(s) = 1 / (1 + exp(-(a + b ln s))) with a90 at severity 0.08 (kt 0.92).
  const double b = 6, a = std::log(9.0) - b * std::log(0.08);
  Rng rng(42);
  CellData data;
  CellStep step;
  for (int batch = 0; batch < 100; ++batch) {
    step = PlanCell(spec, range, data);
    if (step.magnitudes.empty()) break;
    EXPECT_LE(static_cast<int>(step.magnitudes.size()), spec.batch);
    for (double m : step.magnitudes) {
      EXPECT_GE(m, range.low);
      EXPECT_LE(m, range.high);
      const double p = 1 / (1 + std::exp(-(a + b * std::log(1 - m))));
      data.magnitudes.push_back(m);
      data.detected.push_back(rng.Uniform() < p);
      ++data.runs;
    }
  }
  EXPECT_TRUE(step.status == "converged" || step.status == "budget") << step.status;
  EXPECT_LE(data.runs, spec.max_runs);
  const CellEstimate est = EstimateCell(spec, range, data);
  ASSERT_TRUE(est.a90_95.has_value());
  ASSERT_TRUE(est.a90.has_value());
  EXPECT_NEAR(*est.a90, 0.92, 0.02);
  EXPECT_LE(*est.a90_95, *est.a90);  // more severe (a smaller K_T factor) than the point estimate
  EXPECT_NEAR(*est.a90_95, 0.92, 0.04);
}

TEST(BoundarySearch, AllMissedOrAllDetectedTriesTheEndsThenStops) {
  SearchSpec spec;
  spec.batch = 4;
  const SearchEntryRange range = KtRange(0.8, 0.99);
  CellData none;
  const CellStep first = PlanCell(spec, range, none);
  ASSERT_EQ(first.magnitudes.size(), 4u);
  EXPECT_DOUBLE_EQ(first.magnitudes.front(), 0.99);  // least severe first
  EXPECT_DOUBLE_EQ(first.magnitudes.back(), 0.8);
  for (bool hit : {false, true}) {
    CellData d;
    for (double m : first.magnitudes) d.magnitudes.push_back(m), d.detected.push_back(hit), ++d.runs;
    const CellStep second = PlanCell(spec, range, d);
    ASSERT_EQ(second.magnitudes.size(), 4u);
    for (double m : second.magnitudes) EXPECT_DOUBLE_EQ(m, hit ? 0.99 : 0.8);
    for (double m : second.magnitudes) d.magnitudes.push_back(m), d.detected.push_back(hit), ++d.runs;
    const CellStep third = PlanCell(spec, range, d);
    EXPECT_TRUE(third.magnitudes.empty());
    EXPECT_EQ(third.status, hit ? "below_range" : "above_range");
  }
}

TEST(BoundarySearch, CompleteSeparationBisectsTheGap) {
  SearchSpec spec;
  spec.batch = 4;
  const SearchEntryRange range = KtRange(0.8, 0.99);
  CellData d;
  for (auto [m, hit] : {std::pair{0.99, false}, {0.96, false}, {0.95, false}, {0.93, true}, {0.9, true}, {0.8, true}}) {
    d.magnitudes.push_back(m), d.detected.push_back(hit), ++d.runs;
  }
  const CellStep step = PlanCell(spec, range, d);
  ASSERT_EQ(step.magnitudes.size(), 4u);
  for (double m : step.magnitudes) {
    EXPECT_GT(m, 0.93);
    EXPECT_LT(m, 0.95);
  }
  // The same outcomes plan the same batch: choices depend on the results only.
  EXPECT_EQ(PlanCell(spec, range, d).magnitudes, step.magnitudes);
}

class BoundaryRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("boundary_" + std::to_string(getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    campaign_ = new Campaign(CampaignFromJson(SmallSearch(), "small.json", "."));
    BoundaryOptions o;
    o.output_dir = (*dir_ / "j1").string();
    o.threads = 1;
    result_ = new BoundaryResult(RunBoundary(*campaign_, o));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete campaign_;
    delete result_;
  }
  static fs::path* dir_;
  static Campaign* campaign_;
  static BoundaryResult* result_;
};
fs::path* BoundaryRun::dir_ = nullptr;
Campaign* BoundaryRun::campaign_ = nullptr;
BoundaryResult* BoundaryRun::result_ = nullptr;

TEST_F(BoundaryRun, WritesOrdinaryRecordsAndTheBoundary) {
  const nlohmann::json& r = result_->report;
  ASSERT_EQ(r["cells"].size(), 1u);
  const nlohmann::json& cell = r["cells"][0];
  EXPECT_EQ(cell["family"], "kt_degradation");
  EXPECT_EQ(cell["joint"], 3);
  EXPECT_LE(cell["runs"].get<long>(), 12);
  EXPECT_EQ(result_->runs, cell["runs"].get<long>());
  EXPECT_FALSE(cell["status"].get<std::string>().empty());
  EXPECT_EQ(nlohmann::json::parse(ReadAll(*dir_ / "j1" / "boundary.json")), r);
  // campaign.json lists exactly the runs in results.jsonl, in case order.
  const nlohmann::json file = nlohmann::json::parse(ReadAll(*dir_ / "j1" / "campaign.json"));
  const std::vector<std::string> lines = Lines(ReadAll(*dir_ / "j1" / "results.jsonl"));
  EXPECT_EQ(file["campaign"]["search"]["runs"].size(), lines.size());
  EXPECT_EQ(file["cases"].get<size_t>(), lines.size());
  EXPECT_EQ(Lines(ReadAll(*dir_ / "j1" / "decisions.jsonl")).size(), lines.size());
}

TEST_F(BoundaryRun, SameBytesForAnyThreadCount) {
  BoundaryOptions o;
  o.output_dir = (*dir_ / "j2").string();
  o.threads = 2;
  RunBoundary(*campaign_, o);
  for (const char* name : {"campaign.json", "results.jsonl", "decisions.jsonl", "boundary.json"}) {
    EXPECT_EQ(ReadAll(*dir_ / "j2" / name), ReadAll(*dir_ / "j1" / name)) << name;
  }
}

TEST_F(BoundaryRun, ResumedAfterAStopOrAKillEndsWithTheSameBytes) {
  const fs::path out = *dir_ / "resumed";
  BoundaryOptions o;
  o.output_dir = out.string();
  o.threads = 2;
  o.max_batches = 1;
  const BoundaryResult stopped = RunBoundary(*campaign_, o);
  EXPECT_TRUE(stopped.stopped);
  EXPECT_EQ(stopped.batches, 1);
  // A kill in the middle of the next batch: its first run written, the second cut.
  o.max_batches = 2;
  o.resume = true;
  RunBoundary(*campaign_, o);
  std::string results = ReadAll(out / "results.jsonl");
  const std::vector<std::string> lines = Lines(results);
  ASSERT_GE(lines.size(), 6u);
  std::string kept;
  for (size_t k = 0; k < 5; ++k) kept += lines[k] + "\n";
  kept += lines[5].substr(0, lines[5].size() / 2);
  std::ofstream(out / "results.jsonl", std::ios::binary | std::ios::trunc) << kept;
  o.max_batches = 0;
  const BoundaryResult resumed = RunBoundary(*campaign_, o);
  EXPECT_GE(resumed.resumed, 5);
  for (const char* name : {"campaign.json", "results.jsonl", "decisions.jsonl", "boundary.json"}) {
    EXPECT_EQ(ReadAll(out / name), ReadAll(*dir_ / "j1" / name)) << name;
  }
}

TEST_F(BoundaryRun, EveryRunReRunsFromTheOutputsCampaignJson) {
  // What `armfault trace DIR/campaign.json --run RUN_ID` does: the case from campaign.json, RunCase.
  const nlohmann::json file = nlohmann::json::parse(ReadAll(*dir_ / "j1" / "campaign.json"));
  const Campaign c = CampaignFromJson(file["campaign"], (*dir_ / "j1" / "campaign.json").string(), (*dir_ / "j1").string());
  const std::vector<std::string> lines = Lines(ReadAll(*dir_ / "j1" / "results.jsonl"));
  ASSERT_EQ(CaseCount(c), static_cast<long>(lines.size()));
  for (long k : {0L, static_cast<long>(lines.size()) - 1}) {
    EXPECT_EQ(ToJson(RunCase(c, CaseAt(c, k))).dump(), lines[static_cast<size_t>(k)]) << k;
  }
}

TEST_F(BoundaryRun, ResumeRefusesAnotherCampaign) {
  nlohmann::json other = SmallSearch();
  other["seed"] = 6;
  const Campaign c = CampaignFromJson(other, "other.json", ".");
  BoundaryOptions o;
  o.output_dir = (*dir_ / "j1").string();
  o.resume = true;
  const InputError e = ErrorOf([&] { RunBoundary(c, o); });
  EXPECT_NE(std::string(e.what()).find("--resume: this directory holds another campaign"), std::string::npos) << e.what();
}

}  // namespace
}  // namespace armfault
