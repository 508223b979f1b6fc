// ImportLogs (import.h): the output directory's checks, the logs read into runs
// (import_log.cc), the labels checked against the runs, and the manifest, the stand-in
// campaign, channels.json and import.json written into a temporary directory renamed at the end.
#include "campaigns/data/import.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

#include "campaigns/spec/campaign_spec.h"
#include "campaigns/data/channels.h"
#include "campaigns/data/export.h"
#include "campaigns/data/import_internal.h"
#include "campaigns/running/run_dir.h"
#include "core/base/json_input.h"
#include "core/base/output_file.h"
#include "core/base/suggest.h"
#include "core/plant/simulation.h"
#include "faults/fault.h"

namespace armfault {

namespace fs = std::filesystem;

using import_detail::RunOut;

namespace {

// The manifest line of an imported run: the export's keys (campaigns/data/export.cc), with the
// label as its fault, plus "label" and "source".
nlohmann::json ManifestLine(const RunOut& r, long index, const ImportLabel* label) {
  nlohmann::json m;
  m["case"] = index;
  m["run_id"] = r.run_id;
  m["split"] = nullptr;
  m["signals"] = r.signals;
  m["ticks"] = r.ticks;
  m["end_s"] = r.end_s;
  m["trajectory"] = "import";
  m["seed"] = 0;
  m["repetition"] = 0;
  m["variation"] = nullptr;
  m["effect"] = nullptr;
  m["excited"] = nullptr;
  m["not_excited_reason"] = nullptr;
  m["status"] = "ok";
  m["reason"] = nullptr;
  m["fault"] = nullptr;
  m["family"] = nullptr;
  m["joint"] = nullptr;
  m["onset_s"] = nullptr;
  m["magnitude_key"] = nullptr;
  m["magnitude"] = nullptr;
  m["profile"] = nullptr;
  m["group"] = "";
  m["label"] = "unknown";
  if (label && label->kind == ImportLabel::Kind::kHealthy) m["label"] = "healthy";
  if (label && label->kind == ImportLabel::Kind::kFault) {
    const std::string key = FaultMagnitudeKey(label->family);
    nlohmann::json fault = {{"family", label->family}, {"joint", label->joint}, {"onset_s", label->onset_s}};
    std::string group = label->family;
    if (label->magnitude && !key.empty()) {
      fault[key] = *label->magnitude;
      group += " " + key + "=" + FormatNumber(*label->magnitude);
    }
    group += " joint=" + std::to_string(label->joint);
    m["label"] = "fault";
    m["fault"] = fault;
    m["family"] = label->family;
    m["joint"] = label->joint;
    m["onset_s"] = label->onset_s;
    m["magnitude_key"] = key.empty() ? nlohmann::json(nullptr) : nlohmann::json(key);
    m["magnitude"] = label->magnitude ? nlohmann::json(*label->magnitude) : nlohmann::json(nullptr);
    m["profile"] = "abrupt";
    m["group"] = group;
  }
  nlohmann::json source = {{"file", r.file}, {"lines", {r.first_line, r.last_line}}, {"rows", r.rows}};
  if (!r.value.empty()) source["run_value"] = r.value;
  m["source"] = source;
  return m;
}

// Removes the temporary directory unless released (an error: nothing is left behind).
struct TempDir {
  fs::path path;
  bool keep = false;
  ~TempDir() {
    if (keep) return;
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

}  // namespace

ImportResult ImportLogs(const std::vector<std::string>& logs, const ImportMap& map, const ImportOptions& o) {
  if (logs.empty()) throw InputError("LOG", "", "give at least one log file");
  fs::path dir = fs::path(o.output_dir).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();  // "out/" is "out"
  if (dir.empty() || dir == "." || dir == "..") throw InputError("-o", "", "expected a new directory's name, got \"" + o.output_dir + "\"");
  std::error_code ec;
  if (fs::exists(fs::symlink_status(dir, ec)) && !(fs::is_directory(fs::symlink_status(dir, ec)) && fs::is_empty(dir, ec))) {
    throw InputError(dir.string(), "", "already exists and is not an empty directory: choose another output directory");
  }
  const ArmModel arm(map.robot);
  const double dt_s = arm.control_dt_s();
  const int joints = arm.joint_count();

  fs::path parent = dir.parent_path();
  if (parent.empty()) parent = ".";
  fs::create_directories(parent);
  TempDir tmp{parent / (dir.filename().string() + ".import-tmp." + std::to_string(::getpid()))};
  fs::remove_all(tmp.path, ec);
  fs::create_directories(tmp.path / "runs");

  ImportResult result;
  std::vector<RunOut> runs;
  std::set<std::string> run_ids;
  nlohmann::json log_list = nlohmann::json::array();
  for (const std::string& log : logs) {
    const size_t before = runs.size();
    const long rows = import_detail::ReadLogIntoRuns(map, log, tmp.path, dt_s, joints, &runs, &run_ids);
    result.rows += rows;
    nlohmann::json ids = nlohmann::json::array();
    for (size_t i = before; i < runs.size(); ++i) ids.push_back(runs[i].run_id);
    log_list.push_back({{"file", log}, {"rows", rows}, {"runs", ids}});
    if (o.progress) o.progress(result.rows);
  }

  // The labels against the runs found.
  ErrorList errors;
  std::vector<std::string> ids;
  for (const RunOut& r : runs) ids.push_back(r.run_id);
  std::map<std::string, const RunOut*> by_id;
  for (const RunOut& r : runs) by_id[r.run_id] = &r;
  for (const auto& [id, label] : map.labels) {
    const auto it = by_id.find(id);
    if (it == by_id.end()) {
      const std::string near = NearestId(id, ids);
      errors.Add(InputError(map.source, label.pointer, "no run \"" + id + "\" in the logs",
                            near.empty() ? "" : "did you mean \"" + near + "\"?"));
    } else if (label.kind == ImportLabel::Kind::kFault && label.onset_s > it->second->end_s) {
      errors.Add(InputError(map.source, label.pointer + "/onset_s",
                            FormatNumber(label.onset_s) + " is after the run's end (" + FormatNumber(it->second->end_s) + " s)"));
    }
  }
  errors.ThrowIfAny();

  AtomicOutputFile manifest(tmp.path / "manifest.jsonl");
  AtomicOutputFile manifest_csv(tmp.path / "manifest.csv");
  manifest_csv.Write(ManifestCsvHeader());
  for (size_t i = 0; i < runs.size(); ++i) {
    const auto it = map.labels.find(runs[i].run_id);
    const nlohmann::json m = ManifestLine(runs[i], static_cast<long>(i), it == map.labels.end() ? nullptr : &it->second);
    manifest.Write(m.dump() + "\n");
    manifest_csv.Write(ManifestCsvRow(m));
    result.ticks += runs[i].ticks;
    result.max_end_s = std::max(result.max_end_s, runs[i].end_s);
  }
  manifest.Commit();
  manifest_csv.Commit();
  result.runs = static_cast<long>(runs.size());

  // The stand-in campaign: the robot, the longest run, the floors; its cases are not the runs
  // (the manifest is the truth), only as many.
  const nlohmann::json campaign_json = {
      {"name", map.name},
      {"robot", RobotToJson(map.robot)},
      {"duration_s", std::max(result.max_end_s, dt_s)},
      {"trajectories", {{{"name", "import"}, {"joints", nlohmann::json::object()}}}},
      {"healthy", result.runs},
      {"monitor", nlohmann::json::object()},
      {"floors", map.floors}};
  // Only the floors come from the map unchecked: an error in them names the map and /floors/...
  const CampaignSpec campaign = CampaignSpecFromJson(campaign_json, map.source, map.base_dir);
  WriteAtomically(tmp.path / run_dir::kCampaign, CampaignFileJson(campaign, ShardSpec{}).dump(2) + "\n");
  WriteAtomically(tmp.path / "channels.json", ChannelsJson(MonitorSignalChannels(joints), "runs/*.csv.gz"));
  nlohmann::json import_record = {{"map", map.source}, {"logs", log_list}, {"control_period_s", dt_s},
                                  {"max_gap_s", map.max_gap_periods * dt_s}};
  WriteAtomically(tmp.path / "import.json", import_record.dump(2) + "\n");

  if (fs::exists(dir, ec)) fs::remove(dir, ec);  // empty (checked above)
  RenameChecked(tmp.path, dir);
  tmp.keep = true;
  return result;
}

}  // namespace armfault
