#include "campaigns/data/export.h"

#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "core/base/csv.h"
#include "core/base/output_file.h"
#include "core/base/rng.h"
#include "core/base/suggest.h"
#include "core/monitors/monitor.h"
#include "core/plant/simulation.h"
#include "campaigns/data/channels.h"
#include "campaigns/scoring/provenance.h"
#include "campaigns/running/ordered_pipeline.h"
#include "campaigns/running/run_pipeline.h"
#include "faults/fault.h"

namespace armfault {

namespace {
// A compound run's elements without the monitor's outcome ("isolated", "detection_time_s"):
// the manifest holds the truth only.
void StripCompoundOutcome(nlohmann::json* m) {
  if (const auto it = m->find("compound"); it != m->end() && it->is_array()) {
    for (nlohmann::json& e : *it) {
      e.erase("isolated");
      e.erase("detection_time_s");
    }
  }
}
}  // namespace

namespace {

namespace fs = std::filesystem;

// The keys of a run record that are the monitor's, not the truth: left out of the manifest.
const char* const kMonitorKeys[] = {"detected",       "detection_time_s",   "latency_s",  "isolated_family",
                                    "isolated_joint", "magnitude_name",     "magnitude_estimate",
                                    "confidence",     "alarm_before_onset", "miss_reason", "decision"};

std::string CaseFileName(long case_index) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "runs/%06ld.csv.gz", case_index);
  return buf;
}

// Streams one run's signals into a gzip file through a temporary name (renamed when complete;
// removed when not), never through a link, every write checked: the first failure throws with
// the system's reason.
class SignalsWriter {
 public:
  SignalsWriter(const fs::path& path, int joints, int gzip_level) : path_(path), tmp_(path.string() + ".tmp") {
    const int fd = OpenDescriptorForWriting(tmp_);
    file_ = gzdopen(fd, ("wb" + std::to_string(gzip_level)).c_str());
    if (!file_) {
      ::close(fd);
      Abandon();
      throw InputError(tmp_.string(), "", "cannot write: out of memory for the gzip stream");
    }
    Append(SignalsCsvHeader(joints));
  }
  ~SignalsWriter() {
    if (file_) {
      gzclose(file_);
      Abandon();  // not finished (an error): no half file left behind
    }
  }
  void Write(const Tick& tick) {
    std::string& row = row_;
    row.clear();
    AppendCsvExact(&row, tick.t_s);
    for (const JointTick& jt : *tick.joints) {
      const JointSignals& s = jt.signals;
      for (double x : {s.q_ref_rad, s.qd_ref_rad_s, s.q_meas_rad, s.qd_est_rad_s, s.tau_sensor_Nm, s.i_cmd_A,
                       s.i_supply_meas_A, s.v_bus_meas_V, s.winding_temp_C}) {
        row += ',';
        AppendCsvExact(&row, x);
      }
    }
    row += '\n';
    Append(row);
    ++ticks_;
  }
  long ticks() const { return ticks_; }
  void Close() {
    gzFile file = file_;
    file_ = nullptr;
    errno = 0;
    if (gzclose(file) != Z_OK) {
      const int error = errno ? errno : EIO;
      Abandon();
      throw InputError(tmp_.string(), "", std::string("cannot write: ") + std::strerror(error));
    }
    RenameChecked(tmp_, path_);
  }

 private:
  void Append(const std::string& text) {
    errno = 0;
    if (gzwrite(file_, text.data(), static_cast<unsigned>(text.size())) == static_cast<int>(text.size())) return;
    int code = 0;
    const char* why = gzerror(file_, &code);
    throw InputError(tmp_.string(), "",
                     std::string("cannot write: ") + (code == Z_ERRNO ? std::strerror(errno ? errno : EIO) : why));
  }
  void Abandon() {
    std::error_code ec;
    fs::remove(tmp_, ec);
  }
  fs::path path_, tmp_;
  gzFile file_ = nullptr;
  std::string row_;
  long ticks_ = 0;
};

std::string Num(const nlohmann::json& v) {
  if (!v.is_number()) return "";
  std::string out;
  AppendCsvExact(&out, v.get<double>());
  return out;
}

}  // namespace

std::string ManifestCsvHeader() {
  return "case,run_id,split,signals,ticks,trajectory,group,family,joint,onset_s,magnitude_key,magnitude,profile,seed,"
         "repetition,unit,ambient_C,status,reason,took_effect,excited,not_excited_reason\n";
}

std::string ManifestCsvRow(const nlohmann::json& m) {
  auto text = [&](const char* key) { return m[key].is_string() ? CsvText(m[key].get<std::string>()) : std::string(); };
  auto integer = [&](const char* key) { return m[key].is_number() ? m[key].dump() : std::string(); };
  auto boolean = [](const nlohmann::json& v) { return v.is_boolean() ? std::string(v.get<bool>() ? "true" : "false") : ""; };
  const nlohmann::json& variation = m["variation"];
  const nlohmann::json& effect = m["effect"];
  std::string row = m["case"].dump();
  for (const std::string& cell :
       {text("run_id"), text("split"), text("signals"), integer("ticks"), text("trajectory"), text("group"),
        text("family"), integer("joint"), Num(m["onset_s"]), text("magnitude_key"), Num(m["magnitude"]),
        text("profile"), integer("seed"), integer("repetition"),
        variation.is_object() && variation.contains("unit") ? variation["unit"].dump() : std::string(),
        variation.is_object() && variation.contains("ambient_C") ? Num(variation["ambient_C"]) : std::string(),
        text("status"), text("reason"), effect.is_object() ? boolean(effect["took_effect"]) : std::string(),
        boolean(m["excited"]), text("not_excited_reason")}) {
    row += "," + cell;
  }
  return row + "\n";
}

const std::vector<std::string>& SignalColumnNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const Channel& c : MonitorSignalChannels(1)) {
      if (c.joint == 1) out.push_back(c.quantity);
    }
    return out;
  }();
  return names;
}

std::string SignalsCsvHeader(int joints) { return ChannelsCsvHeader(MonitorSignalChannels(joints)); }

void CheckGzipLevel(int level) {
  if (level < 1 || level > 9) {
    throw InputError("--gzip-level", "", "expected 1 (fastest) to 9 (smallest), got " + std::to_string(level));
  }
}

SplitSpec ParseSplit(const std::string& text) {
  SplitSpec s;
  if (text.empty()) return s;
  double parts[3];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf/%lf/%lf%c", &parts[0], &parts[1], &parts[2], &tail) != 3 ||
      std::any_of(parts, parts + 3, [](double p) { return !(p >= 0 && p <= 1); }) ||
      std::fabs(parts[0] + parts[1] + parts[2] - 1) > 1e-9) {
    throw InputError("--split", "", "expected TRAIN/VALIDATION/TEST fractions summing to 1 (e.g. 0.6/0.2/0.2), got \"" +
                                        text + "\"");
  }
  s.enabled = true;
  s.train = parts[0];
  s.validation = parts[1];
  s.test = parts[2];
  return s;
}

std::string SplitOf(const SplitSpec& split, unsigned long long seed) {
  if (!split.enabled) return "";
  // A uniform draw in [0, 1) from the seed alone (53 bits of a mixed seed).
  const double u = static_cast<double>(MixSeed(seed, 0x73706c6974ULL) >> 11) * 0x1.0p-53;
  if (u < split.train) return "train";
  if (u < split.train + split.validation) return "validation";
  return "test";
}

ExportResult ExportCampaign(const Campaign& campaign, const ExportOptions& o) {
  CheckGzipLevel(o.gzip_level);
  const fs::path dir(o.output_dir);
  fs::create_directories(dir / "runs");
  const long mine = o.shard.Size(CaseCount(campaign));  // cases by index: nothing held per case
  const int joints = static_cast<int>(campaign.robot.modules.size());
  AtomicOutputFile manifest(dir / "manifest.jsonl");
  AtomicOutputFile manifest_csv(dir / "manifest.csv");
  manifest_csv.Write(ManifestCsvHeader());
  ExportResult out;
  long done = 0;
  if (o.progress) o.progress(0, mine);

  long cursor = 0;
  RunOrderedPipeline(
      o.threads, [&]() -> std::optional<long> { return cursor < mine ? std::optional<long>(cursor++) : std::nullopt; },
      [&](long k) {
        const CaseSpec cs = CaseAt(campaign, o.shard.CaseIndex(k));
        const std::string file = CaseFileName(cs.index);
        SignalsWriter writer(dir / file, joints, o.gzip_level);
        double end_s = 0;
        // No monitor runs: the manifest holds nothing of one (RunCasePlant).
        const RunRecord r = RunCasePlant(campaign, cs, [&](const Tick& tick) {
          writer.Write(tick);
          end_s = tick.t_s;
        });
        writer.Close();
        nlohmann::json m = ToJson(r);
        for (const char* key : kMonitorKeys) m.erase(key);
        StripCompoundOutcome(&m);
        m["split"] = o.split.enabled ? nlohmann::json(SplitOf(o.split, r.seed)) : nlohmann::json(nullptr);
        m["signals"] = file;
        m["ticks"] = writer.ticks();
        m["end_s"] = RoundToMicroseconds(end_s);
        m["profile"] = r.fault.is_object() ? nlohmann::json(r.fault.value("profile", "abrupt")) : nlohmann::json(nullptr);
        return m;
      },
      [&](const nlohmann::json& m) {
        manifest.Write(m.dump() + "\n");
        manifest_csv.Write(ManifestCsvRow(m));
        if (m["status"] != "ok") ++out.failed;
        ++out.runs;
        ++done;
        if (o.progress) o.progress(done, mine);
      });
  WriteAtomically(dir / run_dir::kCampaign, CampaignFileJson(campaign, o.shard).dump(2) + "\n");
  WriteAtomically(dir / "channels.json", ChannelsJson(MonitorSignalChannels(joints), "runs/*.csv.gz"));
  manifest.Commit();
  manifest_csv.Commit();
  return out;
}

RunRecord TruthOf(nlohmann::json line) {
  if (!line.is_object()) throw std::runtime_error("expected a JSON object");
  // An import's label (docs/import.md): "unknown" is a run scored for false alarms only;
  // "healthy" and "fault" say what its family already does.
  bool unlabelled = false;
  if (const auto it = line.find("label"); it != line.end()) {
    unlabelled = *it == "unknown" || *it == "unlabelled";
    line.erase(it);
  }
  for (const char* key : kMonitorKeys) {
    if (!line.contains(key)) line[key] = nullptr;
  }
  line["detected"] = false;
  line["confidence"] = 0;
  line["alarm_before_onset"] = false;
  RunRecord r = RunRecordFromJson(line);
  r.detection_time_s.reset();
  r.latency_s.reset();
  r.isolated_family.clear();
  r.isolated_joint = 0;
  r.magnitude_name.clear();
  r.magnitude_estimate.reset();
  r.miss_reason.clear();
  r.decision = nullptr;
  r.unlabelled = unlabelled;
  return r;
}

namespace {

Verdict VerdictFromJson(const nlohmann::json& j, std::string* run_id) {
  if (!j.is_object()) throw std::runtime_error("expected a JSON object, got " + Describe(j));
  ObjectReader reader(j, "");
  reader.AllowOnly({"run_id", "t_s", "joint", "family", "alarm", "magnitude", "state", "magnitude_name", "confidence"});
  *run_id = reader.RequireString("run_id");
  Verdict v;
  v.t_s = reader.RequireNumber("t_s");
  v.joint = reader.RequireInt("joint");
  const nlohmann::json* alarm = reader.Find("alarm");
  if (!alarm || !alarm->is_boolean()) {
    throw InputError("", "/alarm", "expected true or false, got " + (alarm ? Describe(*alarm) : std::string("nothing")));
  }
  v.alarm = alarm->get<bool>();
  v.state = v.alarm ? HealthState::kWorn : HealthState::kHealthy;
  if (const nlohmann::json* state = reader.Find("state")) {
    const std::string s = state->is_string() ? state->get<std::string>() : "";
    if (s == "healthy") v.state = HealthState::kHealthy;
    else if (s == "worn") v.state = HealthState::kWorn;
    else if (s == "defective") v.state = HealthState::kDefective;
    else throw InputError("", "/state", "expected \"healthy\", \"worn\" or \"defective\", got " + Describe(*state));
    if ((v.state != HealthState::kHealthy) != v.alarm) throw InputError("", "/state", "disagrees with \"alarm\"");
  }
  if (const nlohmann::json* family = reader.Find("family"); family && !family->is_null()) {
    if (!family->is_string()) throw InputError("", "/family", "expected a fault family name, got " + Describe(*family));
    v.family = family->get<std::string>();
  }
  if (const nlohmann::json* m = reader.Find("magnitude"); m && !m->is_null()) {
    if (!m->is_number()) throw InputError("", "/magnitude", "expected a number or null, got " + Describe(*m));
    v.magnitude = m->get<double>();
  }
  if (const nlohmann::json* name = reader.Find("magnitude_name"); name && !name->is_null()) {
    if (!name->is_string()) throw InputError("", "/magnitude_name", "expected a name, got " + Describe(*name));
    v.magnitude_name = name->get<std::string>();
  }
  v.confidence = v.alarm ? 1.0 : 0.0;
  if (const nlohmann::json* c = reader.Find("confidence"); c && !c->is_null()) {
    if (!c->is_number()) throw InputError("", "/confidence", "expected a number in [0, 1], got " + Describe(*c));
    v.confidence = c->get<double>();
  }
  return v;
}

}  // namespace

namespace {

// Where a line that is not JSON holds NaN or Infinity outside a string (Python's json.dumps
// writes float("nan") so), the key it is the value of ("" when not after a key) and the token;
// nullopt when it holds none.
struct NonJsonNumber {
  std::string key, token;
};
std::optional<NonJsonNumber> FindNonJsonNumber(const std::string& line) {
  bool in_string = false, escaped = false;
  std::string text, last_string, key;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false, last_string = text;
      else text += c;
      continue;
    }
    if (c == '"') {
      in_string = true;
      text.clear();
    } else if (c == ':') {
      key = last_string;
    } else if (c == ',' || c == '{') {
      key.clear();
    } else {
      for (const char* token : {"NaN", "-Infinity", "Infinity"}) {
        if (line.compare(i, std::strlen(token), token) == 0) return NonJsonNumber{key, token};
      }
    }
  }
  return std::nullopt;
}

}  // namespace

void ReadVerdicts(std::istream& in, const std::string& path, const VerdictLimits& limits,
                  const std::function<std::string(const std::string& run_id, std::string* hint)>& run_known,
                  const std::function<void(const std::string& run_id, const Verdict& verdict)>& each) {
  // Every bad line is found; the first kMaxReportedErrors are kept whole, the rest counted.
  ErrorList errors;
  size_t unlisted = 0;
  std::string line;
  long n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const bool keep = errors.size() < kMaxReportedErrors;
    auto bad = [&](const std::string& message, const std::string& hint = "") {
      if (keep) errors.Add(InputError(path, "", "line " + std::to_string(n) + ": " + message, hint));
      else ++unlisted;
    };
    std::string run_id;
    Verdict v;
    try {
      nlohmann::json parsed;
      try {
        parsed = ParseJsonText(line, "");
      } catch (const InputError&) {
        // Python's json.dumps writes NaN (and Infinity) by default: say what to write instead.
        if (const std::optional<NonJsonNumber> nan = FindNonJsonNumber(line)) {
          const std::string where = nan->key.empty() ? "" : "/" + nan->key + ": ";
          throw InputError("", "",
                           where + nan->token + " is not JSON; write null" +
                               (nan->token == "NaN" ? "" : " or a finite number") +
                               " (Python's json.dumps writes float(\"nan\") as NaN: give None, or check with "
                               "allow_nan=False)");
        }
        throw;
      }
      v = VerdictFromJson(parsed, &run_id);
    } catch (const InputError& e) {
      bad((e.pointer().empty() ? "" : e.pointer() + ": ") + e.message());
      continue;
    } catch (const std::exception& e) {
      bad(e.what());
      continue;
    }
    std::string hint;
    if (const std::string why = run_known(run_id, keep ? &hint : nullptr); !why.empty()) {
      bad(why, hint);
      continue;
    }
    if (const std::string why = CheckVerdict(v, limits.joints, limits.duration_s, limits.families); !why.empty()) {
      bad(why);
      continue;
    }
    each(run_id, v);
  }
  if (!errors.empty()) throw InputError(errors.errors(), unlisted);
}

CampaignSpec ScoredCampaign(const CampaignSpec& campaign, const std::string& verdicts_path) {
  CampaignSpec scored = campaign;
  scored.monitor.type = "verdicts";
  scored.monitor.settings = {{"file", verdicts_path}, {"sha256", Sha256FileHex(verdicts_path)}};
  scored.resolved["monitor"] = scored.monitor.ToJson();
  return scored;
}

ScoreResult ScoreExternalVerdicts(const CampaignSpec& campaign, const std::string& dir_name, const std::string& verdicts_path,
                                  const std::string& output_dir) {
  const fs::path dir(dir_name);
  // The truth: an export's manifest, or the records of a run.
  fs::path truth_path = dir / "manifest.jsonl";
  if (!fs::exists(truth_path)) truth_path = dir / run_dir::kResults;
  if (!fs::exists(truth_path)) {
    throw InputError(dir.string(), "", "neither manifest.jsonl (armfault export) nor results.jsonl (armfault run) is here");
  }
  std::vector<RunRecord> runs;
  std::map<std::string, size_t> by_id;
  ReadJsonLines(truth_path.string(), {}, [&](nlohmann::json&& line, long) {
    runs.push_back(TruthOf(line));
    if (!by_id.emplace(runs.back().run_id, runs.size() - 1).second) {
      throw std::runtime_error("run_id \"" + runs.back().run_id + "\" appears twice");
    }
  });
  const ArmModel arm(campaign.robot);
  const double tick_s = arm.control_dt_s();
  const int joints = arm.joint_count();
  const std::vector<std::string> families = FaultFamilyNames();

  // The verdicts, per run, in time order (a tool may write runs interleaved).
  std::vector<MonitorOutput> outputs(runs.size());
  std::vector<std::string> run_ids;  // for "did you mean": made at the first unknown run_id
  ScoreResult result;
  {
    std::ifstream in(verdicts_path, std::ios::binary);
    if (!in) throw InputError(verdicts_path, "", "cannot read the file");
    ReadVerdicts(
        in, verdicts_path, {joints, campaign.duration_s, families},
        [&](const std::string& run_id, std::string* hint) {
          if (by_id.count(run_id)) return std::string();
          if (hint) {
            if (run_ids.empty()) {
              for (const RunRecord& r : runs) run_ids.push_back(r.run_id);
            }
            if (const std::string near = NearestId(run_id, run_ids); !near.empty()) {
              *hint = "did you mean \"" + near + "\"?";
            }
          }
          return "unknown run_id \"" + run_id + "\" (not a run of " + truth_path.string() + ")";
        },
        [&](const std::string& run_id, const Verdict& v) {
          outputs[by_id.at(run_id)].verdicts.push_back(v);
          ++result.verdicts;
        });
  }

  const fs::path out_dir(output_dir);
  fs::create_directories(out_dir);
  std::ostringstream lines;
  for (size_t k = 0; k < runs.size(); ++k) {
    RunRecord& r = runs[k];
    std::vector<Verdict>& verdicts = outputs[k].verdicts;
    std::stable_sort(verdicts.begin(), verdicts.end(), [](const Verdict& a, const Verdict& b) { return a.t_s < b.t_s; });
    if (verdicts.empty()) ++result.runs_without_verdicts;
    // The first controller tick at or after the onset (ticks at k * period, as Simulate has them).
    double first_tick_s = -1;
    if (r.ok) {
      long tick = static_cast<long>(std::ceil(r.onset_s / tick_s));
      while (tick > 0 && (tick - 1) * tick_s >= r.onset_s) --tick;
      while (tick * tick_s < r.onset_s) ++tick;
      first_tick_s = tick * tick_s;
    }
    if (r.ok && r.injected()) {  // a conditional onset that never fired has nothing to score
      const RunScore score = ScoreVerdicts(outputs[k], r.onset_s, first_tick_s);
      ApplyScore(score, &r);
      r.miss_reason = ExplainFromVerdicts(score, r.family, r.joint);
      if (r.is_compound()) {
        ScoreCompoundElements(outputs[k], &r);
        if (IsolatedRight(r)) r.miss_reason.clear();
      }
    }
    lines << ToJson(r).dump() << "\n";
    ++result.runs;
  }
  // The campaign as `run` writes it, then the records: the summary, JUnit and report read them.
  result.campaign = ScoredCampaign(campaign, verdicts_path);
  WriteAtomically(out_dir / run_dir::kCampaign, CampaignFileJson(result.campaign, ShardSpec{}).dump(2) + "\n");
  WriteAtomically(out_dir / run_dir::kResults, lines.str());
  return result;
}

}  // namespace armfault
