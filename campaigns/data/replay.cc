// Recorded directories read (replay.h): a run's signals CSV, the manifest, the recorded robot,
// OUT/replay.json; and ReplayDirectory, which replays every run of the manifest through a monitor.
#include "campaigns/data/replay.h"
#include "campaigns/data/gzip_reason.h"

#include <zlib.h>

#include <charconv>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

#include "campaigns/data/export.h"
#include "campaigns/running/monitor_clock.h"
#include "campaigns/running/run_dir.h"
#include "campaigns/running/ordered_pipeline.h"
#include "campaigns/running/run_pipeline.h"
#include "core/base/distributions.h"
#include "core/base/json_input.h"
#include "core/base/output_file.h"
#include "core/base/suggest.h"
#include "faults/fault.h"

namespace armfault {

namespace fs = std::filesystem;

namespace {

// The fields of a JointSignals in the column order of SignalColumnNames().
constexpr int kFields = 9;
void SetField(JointSignals* s, int k, double x) {
  double* fields[kFields] = {&s->q_ref_rad,    &s->qd_ref_rad_s,    &s->q_meas_rad,    &s->qd_est_rad_s, &s->tau_sensor_Nm,
                             &s->i_cmd_A,      &s->i_supply_meas_A, &s->v_bus_meas_V,  &s->winding_temp_C};
  *fields[k] = x;
}

// Reads a gzip (or plain) text file line by line, in blocks.
class GzipLines {
 public:
  explicit GzipLines(const std::string& path) : path_(path) {
    file_ = gzopen(path.c_str(), "rb");
    if (!file_) throw InputError(path, "", "cannot read the file");
    gzbuffer(file_, 1 << 17);
  }
  ~GzipLines() {
    if (file_) gzclose(file_);
  }
  GzipLines(const GzipLines&) = delete;
  GzipLines& operator=(const GzipLines&) = delete;
  // The next line without its end ("\n" or "\r\n"); false at the end of the file.
  bool Next(std::string* line) {
    line->clear();
    for (;;) {
      if (pos_ == size_) {
        const int n = gzread(file_, buffer_, sizeof buffer_);
        if (n < 0) {
          int code = 0;
          throw InputError(path_, "", std::string("cannot read: ") + GzipReason(file_, path_, &code));
        }
        if (n == 0) {
          // A stream cut short gives its data and then 0, with Z_BUF_ERROR: its end is missing.
          int code = Z_OK;
          const std::string why = GzipReason(file_, path_, &code);
          if (code != Z_OK) throw InputError(path_, "", "cannot read: " + why);
          if (!line->empty()) return true;  // a last line without its newline
          return false;
        }
        pos_ = 0;
        size_ = static_cast<size_t>(n);
      }
      const char* start = buffer_ + pos_;
      const void* nl = std::memchr(start, '\n', size_ - pos_);
      if (nl) {
        const size_t len = static_cast<const char*>(nl) - start;
        line->append(start, len);
        pos_ += len + 1;
        if (!line->empty() && line->back() == '\r') line->pop_back();
        return true;
      }
      line->append(start, size_ - pos_);
      pos_ = size_;
    }
  }

 private:
  std::string path_;
  gzFile file_ = nullptr;
  char buffer_[1 << 16];
  size_t pos_ = 0, size_ = 0;
};

std::string Line(long n) { return "line " + std::to_string(n) + ": "; }

}  // namespace

long ReadSignalsCsv(const std::string& path, int joints,
                    const std::function<void(double t_s, const std::vector<JointSignals>& joints)>& each) {
  GzipLines in(path);
  std::string line;
  if (!in.Next(&line)) throw InputError(path, "", "empty: expected the header " + SignalsCsvHeader(joints));
  std::string expected = SignalsCsvHeader(joints);
  if (!expected.empty() && expected.back() == '\n') expected.pop_back();
  if (line != expected) {
    // The first column that differs.
    size_t a = 0, b = 0, column = 1;
    while (true) {
      const size_t ea = std::min(line.find(',', a), line.size()), eb = std::min(expected.find(',', b), expected.size());
      const std::string got = a <= line.size() ? line.substr(a, ea - a) : "";
      const std::string want = b <= expected.size() ? expected.substr(b, eb - b) : "";
      if (got != want || ea >= line.size() || eb >= expected.size()) {
        throw InputError(path, "",
                         Line(1) + "column " + std::to_string(column) + " is \"" + got + "\", expected \"" + want +
                             "\" (the header of a run of " + std::to_string(joints) + " joints: " + expected + ")");
      }
      a = ea + 1;
      b = eb + 1;
      ++column;
    }
  }
  const size_t cells = 1 + static_cast<size_t>(kFields * joints);
  std::vector<JointSignals> signals(static_cast<size_t>(joints));
  std::vector<double> v(cells);
  long n = 1, ticks = 0;
  double last_t = -std::numeric_limits<double>::infinity();
  while (in.Next(&line)) {
    ++n;
    if (line.empty()) continue;
    size_t k = 0;
    const char* p = line.data();
    const char* end = p + line.size();
    while (true) {
      const char* comma = static_cast<const char*>(std::memchr(p, ',', static_cast<size_t>(end - p)));
      const char* cell_end = comma ? comma : end;
      if (k >= cells) {
        throw InputError(path, "", Line(n) + "more than the header's " + std::to_string(cells) + " cells");
      }
      if (p == cell_end) {
        v[k] = std::numeric_limits<double>::quiet_NaN();
      } else {
        const auto [next, ec] = std::from_chars(p, cell_end, v[k]);
        if (ec != std::errc() || next != cell_end) {
          throw InputError(path, "", Line(n) + "column " + std::to_string(k + 1) + ": \"" + std::string(p, cell_end) +
                                         "\" is not a number");
        }
      }
      ++k;
      if (!comma) break;
      p = comma + 1;
    }
    if (k != cells) {
      throw InputError(path, "", Line(n) + std::to_string(k) + " cells, expected " + std::to_string(cells));
    }
    if (!(v[0] > last_t) || !std::isfinite(v[0])) {
      throw InputError(path, "", Line(n) + "t_s " + FormatNumber(v[0]) + " does not follow " + FormatNumber(last_t) +
                                     " (time must increase)");
    }
    last_t = v[0];
    for (int j = 0; j < joints; ++j) {
      for (int f = 0; f < kFields; ++f) SetField(&signals[static_cast<size_t>(j)], f, v[1 + static_cast<size_t>(kFields * j + f)]);
    }
    each(v[0], signals);
    ++ticks;
  }
  return ticks;
}

void ReadSignalsAtControlRate(const std::string& path, int joints, double control_dt_s,
                              std::vector<std::vector<JointSignals>>* ticks, std::vector<double>* t_s) {
  ticks->clear();
  t_s->clear();
  ReadSignalsCsv(path, joints, [&](double t, const std::vector<JointSignals>& row) {
    if (!t_s->empty() && std::fabs(t - t_s->back() - control_dt_s) > 1e-6) {
      throw InputError(path, "", "ticks " + FormatNumber(t_s->back()) + " s and " + FormatNumber(t) +
                                     " s are not one control period (" + FormatNumber(control_dt_s) +
                                     " s) apart: the log is read at the robot's control rate");
    }
    t_s->push_back(t);
    ticks->push_back(row);
  });
}

std::vector<nlohmann::json> ManifestLines(const std::string& dir) {
  const fs::path path = fs::path(dir) / "manifest.jsonl";
  if (!fs::exists(path)) {
    throw InputError(dir, "", "no manifest.jsonl here (expected the output of armfault export or import)");
  }
  std::vector<nlohmann::json> lines;
  ReadJsonLines(path.string(), {}, [&](nlohmann::json&& line, long) {
    if (!line.is_object() || !line.contains("run_id") || !line["run_id"].is_string()) {
      throw std::runtime_error("expected an object with a string \"run_id\"");
    }
    lines.push_back(std::move(line));
  });
  return lines;
}

nlohmann::json ManifestLine(const std::string& dir, const std::string& run, const std::string& option) {
  std::vector<std::string> ids;
  for (nlohmann::json& line : ManifestLines(dir)) {
    if (line["run_id"] == run) return std::move(line);
    ids.push_back(line["run_id"].get<std::string>());
  }
  const std::string near = NearestId(run, ids);
  throw InputError(option, "", "no run \"" + run + "\" in " + (fs::path(dir) / "manifest.jsonl").string(),
                   near.empty() ? "" : "did you mean \"" + near + "\"?");
}

RobotConfig RecordedRobot(const std::string& dir, const std::string& hint) {
  const fs::path campaign = fs::path(dir) / "campaign.json";
  if (!fs::exists(campaign)) throw InputError(dir, "", "no campaign.json here" + (hint.empty() ? "" : ": " + hint));
  const nlohmann::json file = ParseJsonText(ReadTextFile(campaign.string()), campaign.string());
  // As `run`, `export` and `import` write it: {"campaign": {..., "robot": ...}, ...}.
  if (!file.is_object() || !file.contains("campaign") || !file["campaign"].is_object() || !file["campaign"].contains("robot")) {
    throw InputError(campaign.string(), "/campaign/robot", "missing" + (hint.empty() ? "" : ": " + hint));
  }
  try {
    return RobotFromJson(file["campaign"]["robot"], "/campaign/robot", dir);
  } catch (const InputError& e) {
    throw e.WithSource(campaign.string());
  }
}

std::optional<ReplaySource> ReadReplaySource(const std::string& out_dir) {
  const fs::path path = fs::path(out_dir) / kReplayFile;
  if (!fs::exists(path)) return std::nullopt;
  const nlohmann::json j = ReadJsonFile(path.string());
  ReplaySource src;
  src.file = path.string();
  auto text = [&](const char* key) {
    const auto it = j.is_object() ? j.find(key) : j.end();
    if (!j.is_object() || it == j.end() || !it->is_string()) {
      throw InputError(src.file, std::string("/") + key,
                       "expected a string (the replayed directory), got " +
                           (j.is_object() && it != j.end() ? Describe(*it) : std::string("nothing")));
    }
    return it->get<std::string>();
  };
  const std::string given = text("source"), absolute = text("source_absolute");
  if (const auto it = j.find("import"); it == j.end() || !it->is_boolean()) {
    throw InputError(src.file, "/import", "expected true or false, got " + (it == j.end() ? std::string("nothing") : Describe(*it)));
  } else {
    src.import = it->get<bool>();
  }
  // The absolute path first: `source` is relative to where replay ran.
  if (fs::is_directory(absolute)) src.dir = absolute;
  else if (fs::is_directory(given)) src.dir = given;
  else {
    throw InputError(src.file, "/source_absolute",
                     "\"" + absolute + "\" (\"" + given + "\" as given) is no directory: the recorded data " +
                         out_dir + " replayed moved; replay it again into " + out_dir);
  }
  return src;
}

std::optional<RecordedRuns> ReplayedImportRuns(const std::string& out_dir) {
  const std::optional<ReplaySource> src = ReadReplaySource(out_dir);
  if (!src || !src->import) return std::nullopt;
  RecordedRuns runs;
  runs.manifest_path = (fs::path(src->dir) / "manifest.jsonl").string();
  long index = 0;
  for (const nlohmann::json& line : ManifestLines(src->dir)) {
    // As replay reads a line: "case" when it is an integer, else the line's index.
    const auto c = line.find("case");
    const long case_index = c != line.end() && c->is_number_integer() ? c->get<long>() : index;
    runs.run_ids[case_index] = line["run_id"].get<std::string>();
    ++index;
  }
  return runs;
}

nlohmann::json AlarmRate::ToJson() const {
  const bool any = hours > 0;
  nlohmann::json j = {{"healthy_runs", healthy_runs},
                      {"unlabelled_runs", unlabelled_runs},
                      {"hours", hours},
                      {"alarm_onsets", alarm_onsets},
                      {"per_hour", any ? nlohmann::json(static_cast<double>(alarm_onsets) / hours) : nlohmann::json(nullptr)},
                      {"per_hour_upper_95", any ? nlohmann::json(PoissonUpperBound(alarm_onsets, 0.95) / hours)
                                                : nlohmann::json(nullptr)},
                      {"counted",
                       "alarm onsets (a joint's verdict turning to alarm) on healthy and unlabelled runs, over their "
                       "hours from first to last tick; upper bound one-sided 95 % (Poisson, chi-squared)"}};
  if (!excluded_run.empty()) j["excluded_run"] = excluded_run;
  return j;
}

namespace {

// One run of the manifest.
struct ManifestRun {
  RunRecord truth;
  std::string signals;  // relative to DIR
  long ticks = -1;      // what the manifest says, -1 when it does not
  long line = 0;
  bool faulty() const { return !truth.family.empty(); }
};

// A manifest line's label, read leniently (an import may hold only run_id and signals): fills
// the keys a record needs with what an unknown run has, then reads it as `score` does.
ManifestRun ManifestRunFromJson(nlohmann::json j, long line, long index) {
  if (!j.is_object()) throw std::runtime_error("expected a JSON object");
  ManifestRun m;
  m.line = line;
  const auto sig = j.find("signals");
  if (sig == j.end() || !sig->is_string() || sig->get<std::string>().empty()) {
    throw std::runtime_error("missing \"signals\": the run's signals file (runs/NAME.csv.gz)");
  }
  m.signals = sig->get<std::string>();
  if (const auto t = j.find("ticks"); t != j.end() && t->is_number_integer()) m.ticks = t->get<long>();
  bool unlabelled = !j.contains("family");
  if (const auto label = j.find("label"); label != j.end() && !label->is_null()) {
    const std::string l = label->is_string() ? label->get<std::string>() : "";
    if (l == "unknown" || l == "unlabelled") unlabelled = true;
    else if (l == "healthy") j["family"] = nullptr;
    else if (l != "fault") throw std::runtime_error("\"label\" " + label->dump() + ": expected \"healthy\", \"unknown\" or \"fault\" (docs/import.md)");
    j.erase("label");
  }
  if (j.contains("family") && j["family"] == "healthy") j["family"] = nullptr;
  if (unlabelled) {
    if (j.contains("family") && j["family"].is_string() && !j["family"].get<std::string>().empty()) {
      throw std::runtime_error("labelled unknown, yet its \"family\" is " + j["family"].dump());
    }
    j["family"] = nullptr;
  }
  const nlohmann::json defaults = {{"case", index},    {"trajectory", ""},    {"fault", nullptr},   {"joint", nullptr},
                                   {"onset_s", nullptr}, {"magnitude_key", nullptr}, {"magnitude", nullptr},
                                   {"group", unlabelled ? "unlabelled" : "healthy"},
                                   {"seed", 0},        {"repetition", 0},     {"variation", nullptr}, {"status", "ok"},
                                   {"reason", nullptr}, {"effect", nullptr}};
  if (!j["family"].is_null()) {
    for (const char* key : {"joint", "onset_s"}) {
      if (!j.contains(key)) throw std::runtime_error("a faulty run needs \"" + std::string(key) + "\"");
    }
  }
  for (const auto& [key, value] : defaults.items()) {
    if (!j.contains(key)) j[key] = value;
  }
  m.truth = TruthOf(j);
  m.truth.unlabelled = unlabelled;
  return m;
}

// The onset the live run scored against: the manifest rounds onset_s to the microsecond; a
// fault whose onset is a number of its own (not a condition's) gives it in full in "fault".
void RestoreOnset(RunRecord* r) {
  if (r->family.empty() || !r->fault.is_object()) return;
  std::optional<double> exact;
  auto take = [&](const nlohmann::json& f) {
    if (f.is_object() && f.contains("onset_s") && f["onset_s"].is_number()) {
      const double o = f["onset_s"].get<double>();
      if (!exact || o < *exact) exact = o;
    }
  };
  if (r->is_compound() && r->fault.contains("compound") && r->fault["compound"].is_array()) {
    for (const nlohmann::json& e : r->fault["compound"]) take(e);
  } else {
    take(r->fault);
  }
  if (exact && RoundToMicroseconds(*exact) == RoundToMicroseconds(r->onset_s)) r->onset_s = *exact;
}

// Per-joint alarm onsets in a run's verdicts.
long AlarmOnsets(const MonitorOutput& output) {
  std::map<int, bool> alarmed;
  long n = 0;
  for (const Verdict& v : output.verdicts) {
    bool& was = alarmed[v.joint];
    if (v.alarm && !was) ++n;
    was = v.alarm;
  }
  return n;
}

// One replayed run: its record, its output lines and what it adds to the alarms per hour.
struct Replayed {
  RunRecord record;
  std::string result_line, decision_line, cost_line;
  long alarm_onsets = 0;
  double seconds = 0;
};

// DIR as replay reads it: its paths, the campaign the runs were recorded with (its monitor
// built) and its shard.
struct RecordedDirectory {
  fs::path dir, manifest_path, campaign_path;
  Campaign campaign;
  ShardSpec shard;
};

// Checks that `given` is an export's or an import's directory and reads its campaign.json.
RecordedDirectory ReadRecordedDirectory(const std::string& given) {
  RecordedDirectory d;
  d.dir = fs::path(given);
  const fs::path& dir = d.dir;
  if (!fs::is_directory(dir)) {
    throw InputError(given, "", fs::exists(dir) ? "not a directory" : "no such directory (expected the output of armfault export or import)");
  }
  d.manifest_path = dir / "manifest.jsonl";
  if (!fs::exists(d.manifest_path)) {
    throw InputError(d.manifest_path.string(), "",
                     "missing: replay reads an export's or an import's manifest.jsonl and runs/*.csv.gz"
                     " (a run directory has no signals: armfault export CAMPAIGN writes them)");
  }
  d.campaign_path = dir / run_dir::kCampaign;
  if (!fs::exists(d.campaign_path)) {
    throw InputError(d.campaign_path.string(), "", "missing: the campaign (robot, monitor, floors) the runs were recorded with");
  }
  const nlohmann::json campaign_file = ReadCampaignFileJson(dir);
  Campaign& campaign = d.campaign;
  // The spec alone (trajectories unread: nothing is simulated but a unit's commissioning motion,
  // and a trajectory's CSV file stays where the campaign was) and its monitor, built as
  // CampaignFromJson builds it.
  static_cast<CampaignSpec&>(campaign) = CampaignSpecFromJson(campaign_file["campaign"], d.campaign_path.string(), dir.string());
  try {
    campaign.monitor_model = MakeMonitorModel(campaign.monitor, MonitorContextOf(campaign), "/monitor");
  } catch (const InputError& e) {
    throw e.WithSource(d.campaign_path.string());
  }
  // campaign.json's campaign as DIR holds it (re-parsing it resolves a campaign without a
  // "monitor" key, written {}, to the full settings: another hash), its monitor replaced by
  // --monitor's when given.
  campaign.resolved = campaign_file["campaign"];
  if (campaign_file.contains("shard") && campaign_file["shard"].is_object()) {
    d.shard.index = campaign_file["shard"].value("index", 0);
    d.shard.count = campaign_file["shard"].value("count", 1);
  }
  return d;
}

// --monitor M.json in place of the campaign's monitor: errors name M.json and the pointer
// within it.
void UseMonitorFile(const std::string& monitor_file, Campaign* campaign) {
  const nlohmann::json value = ReadJsonFile(monitor_file);
  if (!value.is_object()) {
    throw InputError(monitor_file, "", "expected a JSON object as a campaign's \"monitor\" key, got " + Describe(value));
  }
  InputContext context;
  context.source = monitor_file;
  context.base_dir = fs::path(monitor_file).parent_path().string();
  if (context.base_dir.empty()) context.base_dir = ".";
  MonitorSpec spec;
  try {
    spec = MonitorSpecFromJson(value, "", context);
    MonitorContext mc = MonitorContextOf(*campaign);
    mc.input = context;
    campaign->monitor_model = MakeMonitorModel(spec, mc, "");
  } catch (const InputError& e) {
    throw e.WithSource(monitor_file);
  }
  campaign->monitor = spec;
  campaign->resolved["monitor"] = spec.ToJson();
}

// The manifest's runs in order, and each run_id's index among them (a run_id twice is an error).
struct ManifestRuns {
  std::vector<ManifestRun> runs;
  std::map<std::string, size_t> by_id;
};

ManifestRuns ReadManifestRuns(const fs::path& manifest_path) {
  ManifestRuns manifest;
  std::vector<ManifestRun>& runs = manifest.runs;
  ReadJsonLines(manifest_path.string(), {"cannot read the file", true}, [&](nlohmann::json&& line, long number) {
    runs.push_back(ManifestRunFromJson(std::move(line), number, static_cast<long>(runs.size())));
    if (!manifest.by_id.emplace(runs.back().truth.run_id, runs.size() - 1).second) {
      throw std::runtime_error("run_id \"" + runs.back().truth.run_id + "\" appears twice");
    }
  });
  return manifest;
}

// What replaying a run needs, the same for every run.
struct ReplayContext {
  const Campaign& campaign;
  const fs::path& dir;
  const fs::path& manifest_path;
  std::shared_ptr<const ArmModel> arm;
  int joints = 0;
  double tick_s = 0;
  long last_tick = 0;  // the campaign's last control tick
  std::shared_ptr<const MonitorModel> commissioned;  // --commission's; null: the campaign's or the unit's
  UnitMonitors* units = nullptr;
  std::string SignalsPath(const ManifestRun& m) const { return (dir / m.signals).string(); }
};

// The monitor model commissioned on the signals of --commission's run (`run`), a healthy run of
// the manifest; the campaign's model when the commissioning returns none.
std::shared_ptr<const MonitorModel> CommissionOnRun(const ReplayContext& c, const ManifestRuns& manifest, const std::string& run) {
  const auto it = manifest.by_id.find(run);
  if (it == manifest.by_id.end()) {
    std::vector<std::string> ids;
    for (const ManifestRun& m : manifest.runs) ids.push_back(m.truth.run_id);
    const std::string near = NearestId(run, ids);
    throw InputError("--commission", "", "unknown run \"" + run + "\" (not in " + c.manifest_path.string() + ")",
                     near.empty() ? "" : "did you mean \"" + near + "\"?");
  }
  const ManifestRun& m = manifest.runs[it->second];
  if (m.faulty()) {
    throw InputError("--commission", "", "run \"" + run + "\" is labelled faulty (" + m.truth.family +
                                             " on joint " + std::to_string(m.truth.joint) +
                                             "): commissioning needs a healthy log of the unit");
  }
  const std::unique_ptr<CommissioningSink> sink = c.campaign.monitor_model->BeginCommissioning(c.tick_s);
  if (!sink) {
    throw InputError("--commission", "", "monitor " + c.campaign.monitor_model->type() +
                                             " learns nothing from commissioning (docs/monitor-api.md, \"Commissioning\")");
  }
  std::shared_ptr<const MonitorModel> commissioned;
  double end_s = 0;
  try {
    ReadSignalsCsv(c.SignalsPath(m), c.joints, [&](double t_s, const std::vector<JointSignals>& s) {
      sink->Tick(t_s, s);
      end_s = t_s;
    });
    commissioned = sink->End(end_s);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError("--commission", "", "commissioning on run \"" + run + "\" failed: " + e.what());
  }
  if (!commissioned) commissioned = c.campaign.monitor_model;
  return commissioned;
}

// The run `m` ready to replay in `p`: its record (the onset as the live run scored it) and its
// monitor model (--commission's, the campaign's, or its unit's as the campaign commissioned
// it). False when its unit's commissioning failed: p->record then says why.
bool PrepareReplayedRun(const ReplayContext& c, const ManifestRun& m, PreparedRun* p) {
  p->record = m.truth;
  p->model = c.arm;
  RunRecord& r = p->record;
  if (!r.family.empty() && r.conditional_onset && !r.injected()) {
    r.onset_s = static_cast<double>(c.last_tick + 1) * c.tick_s;  // as PrepareFaults scores a fault that never acted
  }
  RestoreOnset(&r);
  if (c.commissioned) {
    p->monitor = c.commissioned;
  } else if (!c.campaign.commissioning) {
    p->monitor = c.campaign.monitor_model;
  } else {
    if (r.case_index < 0 || r.case_index >= CaseCount(c.campaign)) {
      throw InputError(c.manifest_path.string(), "", Line(m.line) + "case " + std::to_string(r.case_index) +
                                                         " is not a case of the campaign, whose units are commissioned: "
                                                         "give --commission RUN");
    }
    const CaseSpec cs = CaseAt(c.campaign, r.case_index);
    const UnitMonitor unit = c.units->For(cs);
    if (!unit.model) {
      r.ok = false;
      r.failure_reason = CommissioningFailureReason(cs, unit.failure);
      return false;
    }
    p->monitor = unit.model;
  }
  return true;
}

// Replays run `m`: its signals fed to a fresh monitor tick by tick, as the plant's loop feeds
// it, with scoring's decision tap beside it, and the record scored by ScoreRun.
Replayed ReplayRun(const ReplayContext& c, const ManifestRun& m) {
  Replayed out;
  PreparedRun p;
  const RunRecord& r = p.record;
  if (!PrepareReplayedRun(c, m, &p)) {
    out.record = r;
    return out;
  }
  ExecutedRun x;
  x.result.ok = r.ok;
  x.result.failure_reason = r.failure_reason;
  x.sensor_saturated_s = r.sensor_saturated_s;
  x.monitor = p.monitor->NewMonitor();
  x.monitor->KeepWindows(false);
  x.tap = x.monitor->NewDecisionTap(r.onset_s);
  MonitorClock clock;
  double first_s = 0, end_s = 0;
  long ticks = 0;
  try {
    ticks = ReadSignalsCsv(c.SignalsPath(m), c.joints, [&](double t_s, const std::vector<JointSignals>& s) {
      if (ticks++ == 0) first_s = t_s;
      clock.Start();
      x.monitor->Observe(t_s, s);
      clock.StopTick();
      if (x.tap) x.tap->AfterObserve(t_s);
      if (x.first_tick_s < 0 && t_s >= r.onset_s) x.first_tick_s = t_s;
      end_s = t_s;
    });
    if (m.ticks >= 0 && ticks != m.ticks) {
      throw InputError(c.SignalsPath(m), "", "holds " + std::to_string(ticks) + " ticks; " + c.manifest_path.string() + " " +
                                                 Line(m.line) + "says " + std::to_string(m.ticks));
    }
    if (ticks == 0 && r.ok) {
      throw InputError(c.SignalsPath(m), "", "holds no tick of a run whose status is ok");
    }
    if (ticks == 0) {  // a run that could not be set up: nothing was recorded, nothing to score
      out.record = r;
      return out;
    }
    x.result.end_time_s = end_s;
    clock.Start();
    x.monitor->Finish(end_s);
    clock.StopFinish();
    x.cost = clock.ToJson();
  } catch (const MonitorFailure& e) {
    x.monitor_failure = e.what();
  }
  out.seconds = end_s - first_s;
  if (x.monitor_failure.empty()) out.alarm_onsets = AlarmOnsets(x.monitor->output());
  out.record = ScoreRun(p, x);
  return out;
}

// A replayed run counted into `result`: the runs, the failed ones, and the alarms per hour of
// the healthy and unlabelled runs other than --commission's (`commission_run`).
void CountReplayed(const Replayed& item, const std::string& commission_run, ReplayResult* result) {
  const RunRecord& r = item.record;
  if (!r.ok) ++result->failed;
  ++result->runs;
  if (r.family.empty() && r.ok && r.run_id != commission_run) {
    (r.unlabelled ? result->alarms.unlabelled_runs : result->alarms.healthy_runs)++;
    result->alarms.alarm_onsets += item.alarm_onsets;
    result->alarms.hours += item.seconds / 3600.0;
  }
}

}  // namespace

ReplayResult ReplayDirectory(const ReplayOptions& o) {
  RecordedDirectory d = ReadRecordedDirectory(o.dir);
  if (!o.monitor_file.empty()) UseMonitorFile(o.monitor_file, &d.campaign);
  const ManifestRuns manifest = ReadManifestRuns(d.manifest_path);
  const std::vector<ManifestRun>& runs = manifest.runs;
  const auto arm = std::make_shared<const ArmModel>(d.campaign.robot);
  ReplayContext c{d.campaign, d.dir, d.manifest_path, arm, arm->joint_count(), arm->control_dt_s(), 0, nullptr, nullptr};
  c.last_tick = std::lround(d.campaign.duration_s / c.tick_s);

  // The monitor model of every run: --commission's, or per unit as the campaign commissioned.
  ReplayResult result;
  if (!o.commission_run.empty()) {
    c.commissioned = CommissionOnRun(c, manifest, o.commission_run);
    result.alarms.excluded_run = o.commission_run;
  }
  UnitMonitors units(d.campaign);
  c.units = &units;

  fs::create_directories(o.output_dir);
  AtomicOutputFile results(fs::path(o.output_dir) / run_dir::kResults);
  AtomicOutputFile decisions(fs::path(o.output_dir) / run_dir::kDecisions);
  AtomicOutputFile costs(fs::path(o.output_dir) / run_dir::kMonitorCost);
  const long total = static_cast<long>(runs.size());
  if (o.progress) o.progress(0, total);
  long done = 0;
  size_t cursor = 0;
  RunOrderedPipeline(
      o.threads, [&]() -> std::optional<size_t> { return cursor < runs.size() ? std::optional<size_t>(cursor++) : std::nullopt; },
      [&](size_t k) {
        Replayed out = ReplayRun(c, runs[k]);
        out.result_line = ToJson(out.record).dump() + "\n";
        out.decision_line = DecisionLineJson(out.record).dump() + "\n";
        out.cost_line = MonitorCostLine(out.record);
        return out;
      },
      [&](const Replayed& item) {
        decisions.Write(item.decision_line);
        costs.Write(item.cost_line);
        results.Write(item.result_line);
        CountReplayed(item, o.commission_run, &result);
        ++done;
        if (o.progress) o.progress(done, total);
      });

  result.campaign = d.campaign;
  WriteAtomically(fs::path(o.output_dir) / run_dir::kCampaign, CampaignFileJson(d.campaign, d.shard).dump(2) + "\n");
  decisions.Commit();
  costs.Commit();
  results.Commit();
  WriteAtomically(fs::path(o.output_dir) / run_dir::kAlarmsPerHour, result.alarms.ToJson().dump(2) + "\n");
  // Where the signals came from: an import's stand-in campaign.json does not name its runs.
  const nlohmann::json source = {{"source", o.dir},
                                 {"source_absolute", fs::absolute(d.dir).lexically_normal().string()},
                                 {"import", fs::exists(d.dir / "import.json")}};
  WriteAtomically(fs::path(o.output_dir) / kReplayFile, source.dump(2) + "\n");
  return result;
}

}  // namespace armfault
