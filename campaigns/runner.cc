#include "campaigns/runner.h"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/power_monitor.h"
#include "core/run_config.h"
#include "faults/fault.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;

RobotConfig VariedRobot(const Campaign& c, const CaseSpec& cs) {
  RobotConfig r = c.robot;
  r.payload_kg += cs.extra_payload_kg;
  for (size_t j = 0; j < r.modules.size(); ++j) {
    if (cs.torque_noise_Nm >= 0) r.modules[j].torque_sensor.noise_Nm = cs.torque_noise_Nm;
    const double f = j < cs.friction_factors.size() ? cs.friction_factors[j] : 1.0;
    r.modules[j].friction.viscous_Nm_s_per_rad *= f;
    r.modules[j].friction.coulomb_Nm *= f;
    r.modules[j].friction.static_Nm *= f;
  }
  return r;
}

}  // namespace

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

RunRecord RunCase(const Campaign& campaign, const CaseSpec& cs, const TickObserver& also) {
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
    const RobotConfig robot = VariedRobot(campaign, cs);
    const ArmModel model(robot);
    std::vector<std::shared_ptr<const Fault>> faults;
    if (!cs.fault.is_null()) {
      faults.push_back(MakeFault(cs.fault, "/fault", robot));
      const Fault& f = *faults[0];
      r.family = f.family();
      r.joint = f.joint_index() + 1;
      r.onset_s = f.timing().onset_s;
      r.magnitude_key = FaultMagnitudeKey(r.family);
      if (!r.magnitude_key.empty() && cs.fault.contains(r.magnitude_key) && cs.fault[r.magnitude_key].is_number()) {
        r.magnitude = cs.fault[r.magnitude_key].get<double>();
      } else {
        r.magnitude_key.clear();
      }
    }
    RunSpec spec;
    spec.duration_s = campaign.duration_s;
    spec.seed = cs.seed;
    spec.joints.resize(robot.modules.size());
    for (const auto& [joint, trajectory] : campaign.trajectories[cs.trajectory].parsed) {
      spec.joints[joint - 1].trajectory = trajectory;
    }
    if (!faults.empty()) spec.hardware = std::make_shared<FaultSchedule>(faults);
    // The monitor knows the nominal robot (payload and friction as designed), not this run's.
    PowerEfficiencyMonitor monitor(campaign.monitor_model);
    EffectRecorder effects(model, faults);
    DecisionRecorder decisions(monitor.joint_count(), r.onset_s);
    const RunResult result = Simulate(model, spec, ObserveWith(&monitor, [&](const Tick& tick) {
                                        for (int j = 0; j < monitor.joint_count(); ++j) {
                                          decisions.Record(tick.t_s, j, monitor.readings(j), monitor.structural_family(j));
                                        }
                                        effects.Observe(tick);
                                        if (also) also(tick);
                                      }));
    monitor.Finish(result.end_time_s);
    r.ok = result.ok;
    r.failure_reason = result.failure_reason;
    if (!faults.empty()) r.effect = effects.Results()[0].ToJson();
    r.decision = ToJson(decisions.stats());
    // The decision rule `armfault tune` re-scores: alarms before the onset are false alarms;
    // detection is the first alarm from the onset on.
    const DecisionOutcome d =
        Decide(decisions.stats(), campaign.monitor_model.thresholds, campaign.monitor_model.config.significance);
    r.alarm_before_onset = d.alarm_before_onset;
    r.detected = d.detected;
    if (d.detected) {
      r.detection_time_s = d.detection_time_s;
      if (!r.family.empty()) r.latency_s = d.detection_time_s - r.onset_s;
      r.isolated_family = d.family;
      r.isolated_joint = d.joint;
      // The size: the joint's latest verdict of that family (refined while the alarm stands).
      for (const Verdict& v : monitor.output().verdicts) {
        if (v.joint != d.joint || v.family != d.family || !v.alarm) continue;
        r.magnitude_name = v.magnitude_name;
        if (!v.magnitude_name.empty()) r.magnitude_estimate = v.magnitude;
        r.confidence = v.confidence;
      }
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
  const nlohmann::json campaign_file = CampaignFileJson(campaign, o.shard);

  std::vector<CaseSpec> all = ExpandCases(campaign);
  std::vector<const CaseSpec*> mine;
  for (const CaseSpec& c : all) {
    if (o.shard.Contains(c.index)) mine.push_back(&c);
  }
  RunnerResult out;
  out.total = static_cast<long>(mine.size());

  size_t next = 0;
  if (o.resume && fs::exists(results_path)) {
    if (!fs::exists(campaign_path) || ReadJsonFile(campaign_path.string()) != campaign_file) {
      throw InputError(campaign_path.string(), "",
                       "--resume: this directory holds another campaign or shard; run it without --resume, or "
                       "choose another output directory");
    }
    // Keep the complete prefix of lines that are exactly the expected cases, in order.
    std::ifstream in(results_path, std::ios::binary);
    std::string line;
    std::streamoff good_end = 0;
    while (next < mine.size() && std::getline(in, line)) {
      if (in.eof()) break;  // no newline: a line cut by a crash
      try {
        const RunRecord r = RunRecordFromJson(nlohmann::json::parse(line));
        if (r.case_index != mine[next]->index || r.run_id != mine[next]->run_id) break;
        if (!r.ok) ++out.failed;
      } catch (const std::exception&) {
        break;
      }
      ++next;
      good_end = in.tellg();
    }
    in.close();
    fs::resize_file(results_path, static_cast<uintmax_t>(good_end));
  } else {
    WriteAtomically(campaign_path, campaign_file.dump(2) + "\n");
    std::ofstream(results_path, std::ios::binary | std::ios::trunc);
  }
  out.resumed = static_cast<long>(next);

  std::FILE* results = std::fopen(results_path.string().c_str(), "ab");
  if (!results) throw InputError(results_path.string(), "", "cannot open for appending");
  long done = out.resumed;
  if (o.progress) o.progress(done, out.total);

  const int threads = o.threads > 0 ? o.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  arena.execute([&] {
    size_t cursor = next;
    tbb::parallel_pipeline(
        static_cast<size_t>(4 * threads),
        tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order,
                                       [&](tbb::flow_control& fc) -> size_t {
                                         if (cursor >= mine.size()) {
                                           fc.stop();
                                           return 0;
                                         }
                                         return cursor++;
                                       }) &
            tbb::make_filter<size_t, std::pair<std::string, bool>>(
                tbb::filter_mode::parallel,
                [&](size_t k) {
                  const RunRecord r = RunCase(campaign, *mine[k]);
                  return std::make_pair(ToJson(r).dump() + "\n", r.ok);
                }) &
            tbb::make_filter<std::pair<std::string, bool>, void>(
                tbb::filter_mode::serial_in_order, [&](const std::pair<std::string, bool>& item) {
              const std::string& line = item.first;
              // One write per line, flushed at once: a kill leaves at most one partial line.
              std::fwrite(line.data(), 1, line.size(), results);
              std::fflush(results);
              if (!item.second) ++out.failed;
              ++out.ran;
              ++done;
              if (o.progress) o.progress(done, out.total);
            }));
  });
  if (std::fclose(results) != 0) throw InputError(results_path.string(), "", "error while writing");
  return out;
}

}  // namespace armfault
