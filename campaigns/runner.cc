#include "campaigns/runner.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>

#include "campaigns/early_stop.h"
#include "campaigns/monitor_cost.h"
#include "core/monitors/power_monitor.h"
#include "core/monitors/registry.h"
#include "core/base/rng.h"
#include "core/run_config.h"
#include "faults/fault.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;

// Commissioning: 16 s, enough for several reversals of the slowest joint.
constexpr double kCommissioningDuration_s = 16.0;

// The complete lines at the start of `path` (at most `limit`) that `accept` takes, as the byte
// offset after each. Stops at the first line it refuses and at a last line without a newline
// (cut by a kill). A missing file has none.
std::vector<std::streamoff> AcceptedLineEnds(const fs::path& path, size_t limit,
                                             const std::function<bool(size_t k, const std::string& line)>& accept) {
  std::vector<std::streamoff> ends;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (ends.size() < limit && std::getline(in, line)) {
    if (in.eof()) break;  // no newline: a line cut by a crash
    if (!accept(ends.size(), line)) break;
    ends.push_back(in.tellg());
  }
  return ends;
}

// Cuts `path` (created if missing) after its first `lines` lines, whose ends are `ends`.
void KeepLines(const fs::path& path, const std::vector<std::streamoff>& ends, size_t lines) {
  if (!fs::exists(path)) std::ofstream(path, std::ios::binary);
  fs::resize_file(path, lines == 0 ? 0 : static_cast<uintmax_t>(ends[lines - 1]));
}

// One run's two lines, written together by the pipeline's serial stage.
struct RunLines {
  std::string decision;  // decisions.jsonl
  std::string result;    // results.jsonl
  bool ok = true;
  std::string cost;      // monitor_cost.jsonl
  RunRecord record;      // --early-stop: what the floors are judged on
};

// The complete lines of a file (a line cut by a crash is left out).
std::vector<std::string> CompleteLines(const fs::path& path) {
  std::vector<std::string> lines;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line) && !in.eof()) lines.push_back(line);
  return lines;
}

// --early-stop writes its runs in the order they ran; at the end the files (results.jsonl last,
// their lines in step) are rewritten in case order, as every other reader expects (a temporary
// file renamed over each).
void SortByCaseIndex(const std::vector<fs::path>& paths) {
  const std::vector<std::string> results = CompleteLines(paths.back());
  std::vector<std::pair<long, size_t>> order;
  for (size_t k = 0; k < results.size(); ++k) {
    order.emplace_back(RunRecordFromJson(nlohmann::json::parse(results[k])).case_index, k);
  }
  std::sort(order.begin(), order.end());
  for (const fs::path& path : paths) {
    const std::vector<std::string> lines = CompleteLines(path);
    std::string text;
    for (const auto& [index, k] : order) {
      if (k < lines.size()) text += lines[k] + "\n";
    }
    WriteAtomically(path, text);
  }
}

// The first `lines` complete lines of `path` (created if missing).
void KeepFirstLines(const fs::path& path, size_t lines) {
  std::vector<std::string> kept = CompleteLines(path);
  kept.resize(std::min(kept.size(), lines));
  std::string text;
  for (const std::string& line : kept) text += line + "\n";
  WriteAtomically(path, text);
}

std::string CostLine(const RunRecord& r) {
  nlohmann::json j = {{"case", r.case_index}, {"run_id", r.run_id}};
  if (r.cost.is_object()) {
    j.update(r.cost);
  } else {
    j["ticks"] = 0;
  }
  return j.dump() + "\n";
}

}  // namespace

nlohmann::json CommissioningMotion(const RobotConfig& robot) {
  nlohmann::json joints = nlohmann::json::object();
  for (size_t j = 0; j < robot.modules.size(); ++j) {
    const ModuleParams& m = robot.modules[j];
    // A sine pair peaks at 1.3 A: keep it within 70 % of the half range, 30 deg at most, about
    // the middle of the range; each joint at its own frequency so their accelerations differ.
    const double half = 0.5 * (m.max_angle_deg - m.min_angle_deg);
    const double amplitude = std::min(30.0, 0.7 * half / 1.3);
    joints[std::to_string(j + 1)] = {{"type", "sine_pair"},
                                     {"amplitude_deg", amplitude},
                                     {"omega_rad_s", 0.9 + 0.35 * static_cast<double>(j)},
                                     {"offset_deg", 0.5 * (m.max_angle_deg + m.min_angle_deg)}};
  }
  return joints;
}

UnitMonitor CommissionUnit(const Campaign& campaign, const CaseSpec& spec) {
  UnitMonitor out;
  try {
    const RobotConfig robot = UnitRobot(campaign, spec);
    const ArmModel model(robot);
    InputContext context;
    context.source = "<commissioning>";
    RunSpec run;
    run.duration_s = kCommissioningDuration_s;
    // A fleet's unit has a seed of its own; a run that is its own unit derives one from its seed.
    run.seed = spec.unit >= 0 ? MixSeed(campaign.seed, 0x636f6d6dULL + static_cast<uint64_t>(spec.unit))
                              : MixSeed(spec.seed, 0x636f6d6dULL);
    const StatedTolerances stated = StatedOf(campaign);
    run.ambient_C = 0.5 * (stated.ambient_min_C + stated.ambient_max_C);
    run.joints.resize(robot.modules.size());
    for (const auto& [joint, trajectory] :
         JointTrajectoriesFromJson(CommissioningMotion(robot), "/commissioning", robot, run.duration_s, context)) {
      run.joints[joint - 1].trajectory = trajectory;
    }
    CommissioningData data;
    data.control_dt_s = model.control_dt_s();
    const RunResult result = Simulate(model, run, [&](const Tick& tick) {
      data.t_s.push_back(tick.t_s);
      std::vector<JointSignals> s;
      s.reserve(tick.joints->size());
      for (const JointTick& jt : *tick.joints) s.push_back(jt.signals);
      data.signals.push_back(std::move(s));
    });
    data.ok = result.ok;
    data.failure_reason = result.failure_reason;
    if (!result.ok) {
      out.failure = result.failure_reason;
      return out;
    }
    out.model = campaign.monitor_model->Commissioned(data);
    if (!out.model) out.model = campaign.monitor_model;  // a monitor that learns nothing from it
  } catch (const std::exception& e) {
    out.failure = e.what();
  }
  return out;
}

UnitMonitors::UnitMonitors(const Campaign& campaign)
    : campaign_(campaign),
      once_(new std::once_flag[static_cast<size_t>(std::max(0, campaign.variation.units))]),
      units_(static_cast<size_t>(std::max(0, campaign.variation.units))) {}

UnitMonitor UnitMonitors::For(const CaseSpec& spec) {
  if (!campaign_.commissioning) return {campaign_.monitor_model, ""};
  if (spec.unit < 0 || static_cast<size_t>(spec.unit) >= units_.size()) return CommissionUnit(campaign_, spec);
  const size_t u = static_cast<size_t>(spec.unit);
  std::call_once(once_[u], [&] { units_[u] = CommissionUnit(campaign_, spec); });
  return units_[u];
}

OutputLock::OutputLock(const fs::path& dir, const std::string& command) {
  fs::create_directories(dir);
  const fs::path path = dir / ".armfault.lock";
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(path.string(), "", "cannot open the directory's lock file");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    std::string holder(512, '\0');
    const ssize_t n = ::pread(fd_, holder.data(), holder.size(), 0);
    holder.resize(n > 0 ? static_cast<size_t>(n) : 0);
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\0')) holder.pop_back();
    ::close(fd_);
    fd_ = -1;
    throw InputError(dir.string(), "",
                     "another armfault is writing here (" + (holder.empty() ? std::string("holder unknown") : holder) +
                         "); wait for it to finish, or choose another output directory");
  }
  char host[256] = "?";
  gethostname(host, sizeof host - 1);
  const std::time_t now = std::time(nullptr);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  const std::string text = "pid " + std::to_string(getpid()) + " on " + host + " since " + when + ": " + command + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, text.data(), text.size(), 0) < 0) {
    // The lock holds; only the holder's description could not be written.
  }
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock
}

void WriteAtomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    f.flush();
    if (!f) throw InputError(tmp.string(), "", "cannot write the file");
  }
  fs::rename(tmp, path);
}

nlohmann::json CampaignFileJson(const Campaign& campaign, const ShardSpec& shard) {
  return {{"armfault_version", ARMFAULT_VERSION},
          {"shard", {{"index", shard.index}, {"count", shard.count}}},
          {"cases", CaseCount(campaign)},
          {"campaign", campaign.resolved}};
}

std::string EarlyStopSummaryLine(const nlohmann::json& report) {
  const long runs = report.at("runs").get<long>(), cases = report.at("cases").get<long>();
  std::string line = report.at("decided").get<bool>()
                         ? "early stop: every floor decided after " + std::to_string(runs) + " of " + std::to_string(cases) +
                               " runs (" + std::to_string(cases - runs) + " not run, " +
                               std::to_string(static_cast<int>(std::lround(100.0 * static_cast<double>(cases - runs) /
                                                                          static_cast<double>(std::max(1L, cases))))) +
                               " %)"
                         : "early stop: not every floor could be decided; all " + std::to_string(runs) + " runs made";
  for (const nlohmann::json& f : report.at("floors")) {
    char p[32];
    std::snprintf(p, sizeof p, "%.4f", f.at("p_met").get<double>());
    line += "\n  " + f.at("name").get<std::string>() + ": " +
            (f.at("decided").get<bool>() ? std::string(f.at("met").get<bool>() ? "met" : "missed") + " after " +
                                               std::to_string(f.at("decided_after_runs").get<long>()) + " runs"
                                         : std::string("undecided")) +
            " (P(met by the whole campaign) = " + p + ", " + std::to_string(f.at("successes").get<long>()) + " of " +
            std::to_string(f.at("trials").get<long>()) + ")";
  }
  return line;
}

void ScoreCompoundElements(const MonitorOutput& output, RunRecord* r) {
  if (!r->is_compound()) return;
  for (nlohmann::json& e : r->compound) {
    if (!e.contains("onset_s") || !e["onset_s"].is_number()) {  // a conditional onset that never fired
      e["isolated"] = false;
      e["detection_time_s"] = nullptr;
      continue;
    }
    const double onset = e["onset_s"].get<double>();
    const std::string family = e.value("family", "");
    const int joint = e.value("joint", 0);
    std::optional<double> found;
    for (const Verdict& v : output.verdicts) {
      if (v.alarm && v.t_s >= onset && v.family == family && v.joint == joint) {
        found = v.t_s;
        break;
      }
    }
    e["isolated"] = found.has_value();
    e["detection_time_s"] = found ? nlohmann::json(RoundToMicroseconds(*found)) : nlohmann::json(nullptr);
  }
}

void ApplyScore(const RunScore& score, RunRecord* r) {
  r->alarm_before_onset = score.alarm_before_onset;
  r->detected = score.detected;
  if (!score.detected) return;
  r->detection_time_s = score.detection_time_s;
  if (!r->family.empty()) r->latency_s = score.detection_time_s - r->onset_s;
  r->isolated_family = score.family;
  r->isolated_joint = score.joint;
  r->magnitude_name = score.magnitude_name;
  r->magnitude_estimate = score.magnitude;
  r->confidence = score.confidence;
}

namespace {

// A case's run without its faults: duration, seed, ambient and the trajectory's joints.
RunSpec CaseRunSpec(const Campaign& campaign, const CaseSpec& cs, const ArmModel& model) {
  RunSpec spec;
  spec.duration_s = campaign.duration_s;
  spec.seed = cs.seed;
  spec.ambient_C = cs.ambient_C;
  spec.joints.resize(static_cast<size_t>(model.joint_count()));
  for (const auto& [joint, trajectory] : campaign.trajectories[cs.trajectory].parsed) {
    spec.joints[joint - 1].trajectory = trajectory;
  }
  return spec;
}

// A fault with a conditional onset: when its condition fires in this run (faults/fault.h,
// ResolveConditionalOnsets, on the run's own plant, seed and trajectories), and the record's
// fire time; a condition that never fires (or too late to act) makes the run not injected, and
// it is then scored against an onset after its last tick (so every alarm is before it).
void ResolveConditionalOnset(const Campaign& campaign, const CaseSpec& cs, const ArmModel& model, Fault* fault,
                             RunRecord* r) {
  ResolveConditionalOnsets(model, CaseRunSpec(campaign, cs, model), {fault});
  r->conditional_onset = true;
  if (!std::isnan(fault->timing().fired_s)) r->onset_fired_s = fault->timing().fired_s;
  const long last_tick = std::lround(campaign.duration_s / model.control_dt_s());
  r->not_injected_reason = NotInjectedReason(*fault, static_cast<double>(last_tick) * model.control_dt_s());
  if (!r->injected()) r->onset_s = static_cast<double>(last_tick + 1) * model.control_dt_s();
}

}  // namespace

RunRecord RunCase(const Campaign& campaign, const CaseSpec& cs, const TickObserver& also, UnitMonitors* units) {
  RunRecord r;
  r.case_index = cs.index;
  r.run_id = cs.run_id;
  r.trajectory = campaign.trajectories[cs.trajectory].name;
  r.fault = cs.fault;
  r.group = cs.group;
  r.seed = cs.seed;
  r.repetition = cs.repetition;
  r.variation = cs.VariationJson();
  try {
    std::optional<UnitMonitors> own;
    if (!units) units = &own.emplace(campaign);
    const UnitMonitor unit = units->For(cs);
    if (!unit.model) {
      r.ok = false;
      r.failure_reason = "the commissioning run of " +
                         (cs.unit >= 0 ? "unit " + std::to_string(cs.unit) : std::string("this run's unit")) +
                         " failed: " + unit.failure;
      return r;
    }
    const MonitorModel& monitor_model = *unit.model;
    const RobotConfig robot = CaseRobot(campaign, cs);
    const ArmModel model(robot);
    std::vector<std::shared_ptr<const Fault>> faults;
    const bool compound = cs.fault.is_object() && cs.fault.contains("compound");
    if (compound) {
      // Every element on the schedule: they act together. The record's onset is the earliest.
      r.family = "compound";
      r.joint = 0;
      r.compound = nlohmann::json::array();
      const nlohmann::json& elements = cs.fault.at("compound");
      std::vector<std::unique_ptr<Fault>> made;
      std::vector<Fault*> conditional;
      for (size_t i = 0; i < elements.size(); ++i) {
        made.push_back(MakeFault(elements[i], "/fault/compound/" + std::to_string(i), robot));
        if (made.back()->timing().condition) conditional.push_back(made.back().get());
      }
      // Conditional onsets: resolved on the run's own plant with every element acting.
      const long last_tick = std::lround(campaign.duration_s / model.control_dt_s());
      const double end_s = static_cast<double>(last_tick) * model.control_dt_s();
      if (!conditional.empty()) {
        ResolveConditionalOnsets(model, CaseRunSpec(campaign, cs, model), conditional);
        r.conditional_onset = true;
      }
      bool any_injected = false;
      std::string not_injected;
      for (size_t i = 0; i < made.size(); ++i) {
        const Fault& f = *made[i];
        const std::string why = NotInjectedReason(f, end_s);
        nlohmann::json e = {{"family", f.family()},
                            {"joint", f.joint_index() + 1},
                            {"onset_s", why.empty() ? nlohmann::json(RoundToMicroseconds(f.timing().onset_s))
                                                    : nlohmann::json(nullptr)}};
        const std::string key = FaultMagnitudeKey(f.family());
        const bool sized = !key.empty() && elements[i].contains(key) && elements[i][key].is_number();
        e["magnitude_key"] = sized ? nlohmann::json(key) : nlohmann::json(nullptr);
        e["magnitude"] = sized ? elements[i][key] : nlohmann::json(nullptr);
        if (f.timing().condition) {
          const double fired = f.timing().fired_s;
          e["onset_fired_s"] = std::isnan(fired) ? nlohmann::json(nullptr) : nlohmann::json(RoundToMicroseconds(fired));
          e["not_injected_reason"] = why.empty() ? nlohmann::json(nullptr) : nlohmann::json(why);
          if (!std::isnan(fired) && (!r.onset_fired_s || fired < *r.onset_fired_s)) r.onset_fired_s = fired;
        }
        if (why.empty()) {
          r.onset_s = any_injected ? std::min(r.onset_s, f.timing().onset_s) : f.timing().onset_s;
          any_injected = true;
        } else {
          not_injected += (not_injected.empty() ? "" : "; ") + std::string("element ") + std::to_string(i) + ": " + why;
        }
        r.compound.push_back(std::move(e));
      }
      // Not injected only when no element acted; then scored against an onset after the last tick.
      if (!any_injected) {
        r.not_injected_reason = not_injected;
        r.onset_s = static_cast<double>(last_tick + 1) * model.control_dt_s();
      }
      for (std::unique_ptr<Fault>& f : made) faults.push_back(std::move(f));
    } else if (!cs.fault.is_null()) {
      std::unique_ptr<Fault> made = MakeFault(cs.fault, "/fault", robot);
      if (made->timing().condition) ResolveConditionalOnset(campaign, cs, model, made.get(), &r);
      faults.push_back(std::move(made));
      const Fault& f = *faults[0];
      r.family = f.family();
      r.joint = f.joint_index() + 1;
      if (r.injected()) r.onset_s = f.timing().onset_s;
      r.magnitude_key = FaultMagnitudeKey(r.family);
      if (!r.magnitude_key.empty() && cs.fault.contains(r.magnitude_key) && cs.fault[r.magnitude_key].is_number()) {
        r.magnitude = cs.fault[r.magnitude_key].get<double>();
      } else {
        r.magnitude_key.clear();
      }
    }
    RunSpec spec = CaseRunSpec(campaign, cs, model);
    if (!faults.empty()) spec.hardware = std::make_shared<FaultSchedule>(faults);
    // The monitor knows the nominal robot (payload and friction as designed) and what it learnt
    // on this unit while commissioning, not this run's truth. The tap beside it (scoring's)
    // knows the onset.
    const std::unique_ptr<HealthMonitor> monitor = monitor_model.NewMonitor();
    const std::unique_ptr<DecisionTap> tap = monitor->NewDecisionTap(r.onset_s);
    EffectRecorder effects(model, faults);
    double first_tick_s = -1;  // the first tick at or after the onset
    RunResult result;
    // The monitor's own calls are timed (monitor_cost.jsonl); the tap is scoring's, not its.
    MonitorClock clock;
    std::vector<JointSignals> signals;
    try {
      result = Simulate(model, spec, [&](const Tick& tick) {
        signals.resize(tick.joints->size());
        for (size_t j = 0; j < signals.size(); ++j) signals[j] = (*tick.joints)[j].signals;
        clock.Start();
        monitor->Observe(tick.t_s, signals);
        clock.StopTick();
        if (tap) tap->AfterObserve(tick.t_s);
        if (first_tick_s < 0 && tick.t_s >= r.onset_s) first_tick_s = tick.t_s;
        effects.Observe(tick);
        if (also) also(tick);
      });
      clock.Start();
      monitor->Finish(result.end_time_s);
      clock.StopFinish();
      r.cost = clock.ToJson();
    } catch (const MonitorFailure& e) {
      r.ok = false;
      r.failure_reason = "monitor " + monitor_model.type() + " failed: " + e.what();
      return r;
    }
    r.ok = result.ok;
    r.failure_reason = result.failure_reason;
    if (compound) {
      // Each element's own effect; the run is not excited only if no element could act.
      const std::vector<FaultEffect> results = effects.Results();
      std::string reasons;
      bool any_excited = false;
      r.effect = nlohmann::json::array();
      for (size_t i = 0; i < faults.size(); ++i) {
        const bool injected = r.compound[i]["onset_s"].is_number();  // a condition that never fired: never acted
        const std::string reason = injected ? NotExcitedReason(*faults[i], results[i]) : "";
        r.effect.push_back(results[i].ToJson());
        r.compound[i]["effect"] = results[i].ToJson();
        r.compound[i]["excited"] = injected && reason.empty();
        if (!injected) continue;
        any_excited = any_excited || reason.empty();
        reasons += (reasons.empty() ? "" : "; ") + std::string("element ") + std::to_string(i) + ": " + reason;
      }
      r.not_excited_reason = any_excited || !r.injected() ? "" : reasons;
    } else if (!faults.empty()) {
      const FaultEffect effect = effects.Results()[0];
      r.effect = effect.ToJson();
      r.not_excited_reason = r.injected() ? NotExcitedReason(*faults[0], effect) : "";
    }
    if (tap) r.decision = tap->Statistics();
    // A monitor that breaks the contract (a joint that does not exist, a NaN, time running
    // backwards) fails the run: its verdicts cannot be scored.
    const std::string breach = CheckOutput(monitor->output(), static_cast<int>(robot.modules.size()),
                                           result.end_time_s, FaultFamilyNames());
    if (!breach.empty()) {
      r.ok = false;
      r.failure_reason = "monitor " + monitor_model.type() + " emitted a bad verdict: " + breach;
      return r;
    }
    // Scored from the verdicts alone, as for any monitor (core/monitors/monitor.h).
    const RunScore score = ScoreVerdicts(monitor->output(), r.onset_s, first_tick_s);
    ApplyScore(score, &r);
    if (compound) {
      ScoreCompoundElements(monitor->output(), &r);
      if (result.ok && r.injected() && (!r.detected || !IsolatedRight(r))) {
        // Explained against the earliest element (the one the first alarm should have named).
        size_t first = 0;  // (a condition that never fired has onset_s +infinity)
        for (size_t i = 1; i < faults.size(); ++i) {
          if (faults[i]->timing().onset_s < faults[first]->timing().onset_s) first = i;
        }
        const std::string family = faults[first]->family();
        const int joint = faults[first]->joint_index() + 1;
        r.miss_reason = tap ? tap->Explain(score, family, joint) : ExplainFromVerdicts(score, family, joint);
      }
    } else if (result.ok && r.injected()) {
      r.miss_reason = tap ? tap->Explain(score, r.family, r.joint) : ExplainFromVerdicts(score, r.family, r.joint);
    }
  } catch (const std::exception& e) {
    r.ok = false;
    r.failure_reason = std::string("run could not be set up: ") + e.what();
  }
  return r;
}

RunnerResult RunCampaign(const Campaign& campaign, const RunnerOptions& o) {
  const fs::path dir(o.output_dir);
  fs::create_directories(dir);
  const fs::path campaign_path = dir / "campaign.json";
  const fs::path results_path = dir / "results.jsonl";
  const fs::path decisions_path = dir / "decisions.jsonl";
  const fs::path cost_path = dir / "monitor_cost.jsonl";
  nlohmann::json campaign_file = CampaignFileJson(campaign, o.shard);
  // --early-stop: the runs go in an even sweep of the case space and stop when every floor is
  // decided (campaigns/early_stop.h); early_stop.json marks a finished one.
  const fs::path early_path = dir / "early_stop.json";
  std::unique_ptr<EarlyStop> early;
  std::optional<EarlyStopOrder> order;
  std::mutex early_mutex;  // the input stage asks what the output stage decides
  if (o.early_stop) {
    if (o.shard.count > 1) {
      throw InputError("--early-stop", "",
                       "decides the campaign's floors on all of its runs in one directory, so it cannot run as a shard "
                       "(drop --shard, or run the shards without --early-stop)");
    }
    early = std::make_unique<EarlyStop>(campaign, *o.early_stop);
    order.emplace(CaseCount(campaign), campaign.seed);
    campaign_file["early_stop"] = o.early_stop->ToJson();
  }
  auto case_at_position = [&](size_t k) {
    return order ? order->CaseIndex(static_cast<long>(k)) : o.shard.CaseIndex(static_cast<long>(k));
  };
  // A compound case's family is "compound": a faulty case for the overall floors, in no
  // per_family scope (EarlyStop::Scope::Holds).
  auto family_of = [](const CaseSpec& spec) { return spec.fault.is_null() ? std::string() : spec.fault.value("family", ""); };

  // The shard's cases by index (CaseAt): nothing is held per case, so memory stays flat in
  // the campaign's size and the first run starts at once.
  const size_t mine = static_cast<size_t>(o.shard.Size(CaseCount(campaign)));
  auto is_case = [&](size_t k, long case_index, const std::string& run_id) {
    const long index = case_at_position(k);
    return case_index == index && run_id == CaseAt(campaign, index).run_id;
  };
  RunnerResult out;
  out.total = static_cast<long>(mine);

  size_t next = 0;
  if (o.resume && fs::exists(results_path)) {
    if (!fs::exists(campaign_path) || ReadJsonFile(campaign_path.string()) != campaign_file) {
      throw InputError(campaign_path.string(), "",
                       "--resume: this directory holds another campaign or shard (or was run with other --early-stop "
                       "settings); run it without --resume, or choose another output directory");
    }
  }
  if (early && o.resume && fs::exists(results_path) && fs::exists(early_path)) {
    // Finished: its files are in case order already, and nothing is left to run.
    for (const std::string& line : CompleteLines(results_path)) {
      ++out.resumed;
      out.failed += RunRecordFromJson(nlohmann::json::parse(line)).ok ? 0 : 1;
    }
    out.early_stop = ReadJsonFile(early_path.string());
    return out;
  }
  if (early && o.resume && fs::exists(results_path)) {
    // Replay the decisions over the runs kept so far, in the order they ran: each needed case
    // in turn must be the next line of both files; keep that prefix.
    const std::vector<std::string> results_lines = CompleteLines(results_path), decision_lines = CompleteLines(decisions_path);
    const size_t lines = std::min(results_lines.size(), decision_lines.size());
    size_t kept = 0;
    for (; next < mine && kept < lines && !early->AllDecided(); ++next) {
      const CaseSpec spec = CaseAt(campaign, case_at_position(next));
      if (!early->Needed(family_of(spec))) continue;
      RunRecord r;
      try {
        r = RunRecordFromJson(nlohmann::json::parse(results_lines[kept]));
        const DecisionLine d = DecisionLineFromJson(nlohmann::json::parse(decision_lines[kept]));
        if (r.case_index != spec.index || r.run_id != spec.run_id || d.case_index != spec.index) break;
      } catch (const std::exception&) {
        break;
      }
      early->Add(r);
      out.failed += r.ok ? 0 : 1;
      ++kept;
    }
    std::string results_text, decisions_text;
    for (size_t k = 0; k < kept; ++k) {
      results_text += results_lines[k] + "\n";
      decisions_text += decision_lines[k] + "\n";
    }
    WriteAtomically(decisions_path, decisions_text);
    KeepFirstLines(cost_path, kept);
    WriteAtomically(results_path, results_text);
    out.resumed = static_cast<long>(kept);
  } else if (o.resume && fs::exists(results_path)) {
    // Keep the complete prefix of lines that are exactly the expected cases, in order, in both
    // files. decisions.jsonl is written first, so after a kill it is at most one line ahead; a
    // missing one (removed, or an older armfault's directory) keeps nothing.
    std::vector<bool> ok;
    const std::vector<std::streamoff> result_ends =
        AcceptedLineEnds(results_path, mine, [&](size_t k, const std::string& line) {
          try {
            const RunRecord r = RunRecordFromJson(nlohmann::json::parse(line));
            if (!is_case(k, r.case_index, r.run_id)) return false;
            ok.push_back(r.ok);
            return true;
          } catch (const std::exception&) {
            return false;
          }
        });
    const std::vector<std::streamoff> decision_ends =
        AcceptedLineEnds(decisions_path, result_ends.size(), [&](size_t k, const std::string& line) {
          try {
            const DecisionLine d = DecisionLineFromJson(nlohmann::json::parse(line));
            return is_case(k, d.case_index, d.run_id);
          } catch (const std::exception&) {
            return false;
          }
        });
    next = decision_ends.size();
    for (size_t k = 0; k < next; ++k) out.failed += ok[k] ? 0 : 1;
    KeepLines(results_path, result_ends, next);
    KeepLines(decisions_path, decision_ends, next);
    KeepFirstLines(cost_path, next);  // written before each results line: at least `next`
    out.resumed = static_cast<long>(next);
  } else {
    std::error_code ec;
    fs::remove(early_path, ec);  // of an earlier run into this directory
    WriteAtomically(campaign_path, campaign_file.dump(2) + "\n");
    std::ofstream(results_path, std::ios::binary | std::ios::trunc);
    std::ofstream(decisions_path, std::ios::binary | std::ios::trunc);
    std::ofstream(cost_path, std::ios::binary | std::ios::trunc);
  }

  std::FILE* results = std::fopen(results_path.string().c_str(), "ab");
  if (!results) throw InputError(results_path.string(), "", "cannot open for appending");
  std::FILE* decisions = std::fopen(decisions_path.string().c_str(), "ab");
  if (!decisions) {
    std::fclose(results);
    throw InputError(decisions_path.string(), "", "cannot open for appending");
  }
  std::FILE* costs = std::fopen(cost_path.string().c_str(), "ab");
  if (!costs) {
    std::fclose(results);
    std::fclose(decisions);
    throw InputError(cost_path.string(), "", "cannot open for appending");
  }
  long done = out.resumed;
  if (o.progress) o.progress(done, out.total);

  UnitMonitors units(campaign);
  const int threads = o.threads > 0 ? o.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  arena.execute([&] {
    size_t cursor = next;
    tbb::parallel_pipeline(
        static_cast<size_t>(4 * threads),
        tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order,
                                       [&](tbb::flow_control& fc) -> size_t {
                                         if (cursor >= mine) {
                                           fc.stop();
                                           return 0;
                                         }
                                         if (o.stop && o.stop->load()) {
                                           out.interrupted = true;
                                           fc.stop();
                                           return 0;
                                         }
                                         if (early) {
                                           // Skip the cases no undecided floor needs (decisions are final,
                                           // so the output stage would drop them too).
                                           std::lock_guard<std::mutex> lock(early_mutex);
                                           while (cursor < mine && !early->AllDecided() &&
                                                  !early->Needed(family_of(CaseAt(campaign, case_at_position(cursor))))) {
                                             ++cursor;
                                           }
                                           if (cursor >= mine || early->AllDecided()) {
                                             fc.stop();
                                             return 0;
                                           }
                                         }
                                         return cursor++;
                                       }) &
            tbb::make_filter<size_t, RunLines>(tbb::filter_mode::parallel,
                                               [&](size_t k) {
                                                 RunRecord r = RunCase(campaign, CaseAt(campaign, case_at_position(k)),
                                                                       nullptr, &units);
                                                 RunLines lines{DecisionLineJson(r).dump() + "\n", ToJson(r).dump() + "\n",
                                                                r.ok, CostLine(r), {}};
                                                 if (early) lines.record = std::move(r);
                                                 return lines;
                                               }) &
            tbb::make_filter<RunLines, void>(tbb::filter_mode::serial_in_order, [&](const RunLines& item) {
              std::unique_lock<std::mutex> lock(early_mutex, std::defer_lock);
              if (early) {
                // In the order of the runs: a run no undecided floor needs any more is dropped,
                // whichever thread finished it when, so the kept runs are the same for any -j.
                lock.lock();
                if (early->AllDecided() || !early->Needed(item.record.family)) return;
                early->Add(item.record);
              }
              // One write per line, flushed at once, the decision first: a kill leaves at most one
              // partial line in each file, and results.jsonl never ahead of decisions.jsonl.
              std::fwrite(item.decision.data(), 1, item.decision.size(), decisions);
              std::fflush(decisions);
              std::fwrite(item.cost.data(), 1, item.cost.size(), costs);
              std::fflush(costs);
              std::fwrite(item.result.data(), 1, item.result.size(), results);
              std::fflush(results);
              if (!item.ok) ++out.failed;
              ++out.ran;
              ++done;
              if (o.progress) o.progress(done, out.total);
            }));
  });
  const bool decisions_closed = std::fclose(decisions) == 0;
  const bool costs_closed = std::fclose(costs) == 0;
  if (std::fclose(results) != 0) throw InputError(results_path.string(), "", "error while writing");
  if (!decisions_closed) throw InputError(decisions_path.string(), "", "error while writing");
  if (!costs_closed) throw InputError(cost_path.string(), "", "error while writing");
  if (early && !out.interrupted) {
    SortByCaseIndex({decisions_path, cost_path, results_path});
    out.early_stop = early->ToJson(CaseCount(campaign));
    WriteAtomically(early_path, out.early_stop.dump(2) + "\n");
  }
  return out;
}

}  // namespace armfault
