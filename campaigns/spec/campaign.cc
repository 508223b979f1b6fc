#include "campaigns/spec/campaign.h"

#include <filesystem>
#include <set>

#include "faults/fault.h"

namespace armfault {

namespace {

// An onset at or after the end of the run (a value of a list or grid, the upper end of a
// uniform range, a compound element's): that fault would never act, an error naming its pointer
// (a uniform range may end at the end of the run: its draws fall below it).
void CheckOnsetsWithinRun(const CampaignSpec& c, const std::string& source) {
  ErrorList errors;
  auto late = [&](const std::string& pointer, const std::string& what) {
    errors.Add(InputError(source, pointer, what + " is at or after the end of the run (duration_s " + FormatNumber(c.duration_s) +
                                               "): the fault would never act"));
  };
  for (const FaultEntry& e : c.faults) {
    for (const auto& [key, sweep] : e.keys) {
      if (key != "onset_s") continue;
      if (sweep.uniform) {
        // Draws fall below the upper end: a range ending at the run's end is allowed.
        if (sweep.high > c.duration_s) late(sweep.pointer, "onset_s up to " + FormatNumber(sweep.high) + " s");
        continue;
      }
      for (const nlohmann::json& v : sweep.values) {
        if (v.is_number() && v.get<double>() >= c.duration_s) {
          late(sweep.pointer, "onset_s " + FormatNumber(v.get<double>()) + " s");
          break;
        }
      }
    }
    for (size_t i = 0; i < e.elements.size(); ++i) {
      const nlohmann::json& el = e.elements[i];
      if (el.contains("onset_s") && el["onset_s"].is_number() && el["onset_s"].get<double>() >= c.duration_s) {
        late(PointerJoin(PointerJoin(PointerJoin(e.pointer, "compound"), i), "onset_s"),
             "onset_s " + FormatNumber(el["onset_s"].get<double>()) + " s");
      }
    }
  }
  errors.ThrowIfAny();
}

}  // namespace

Campaign CampaignFromJson(const nlohmann::json& value, const std::string& source, const std::string& base_dir,
                          MonitorLoading loading) {
  Campaign c;
  static_cast<CampaignSpec&>(c) = CampaignSpecFromJson(value, source, base_dir, &c.loaded_trajectories);
  CheckOnsetsWithinRun(c, source);
  if (loading == MonitorLoading::kSkipUserCode && MonitorRunsUserCode(c.monitor.type)) return c;
  try {
    c.monitor_model = MakeMonitorModel(c.monitor, MonitorContextOf(c), "/monitor");
  } catch (const InputError& e) {
    throw e.WithSource(source);
  }
  return c;
}

Campaign ReadCampaignFile(const std::string& path, MonitorLoading loading) {
  std::string base = std::filesystem::path(path).parent_path().string();
  if (base.empty()) base = ".";
  return CampaignFromJson(ReadJsonFile(path), path, base, loading);
}


std::vector<std::string> CampaignWarnings(const Campaign& c) {
  std::vector<std::string> out;
  // Commissioning that the monitor does not learn from costs a run per unit and changes nothing.
  if (c.commissioning && c.monitor_model && !c.monitor_model->LearnsFromCommissioning()) {
    const std::string source = c.monitor_model->source();
    out.push_back("/commissioning: monitor " + c.monitor_model->type() + (source.empty() ? "" : " (" + source + ")") +
                  " learns nothing from commissioning (docs/monitor-api.md, \"Commissioning\"): its runs are as "
                  "without it, and each unit's commissioning run only costs time");
  }
  for (size_t ti = 0; ti < c.trajectories.size(); ++ti) {
    const CampaignTrajectory& t = c.trajectories[ti];
    const auto& loaded = c.loaded_trajectories[ti];
    // Joints a trajectory does not name hold their start; named ones may still not move.
    std::set<int> still;
    for (int j = 1; j <= static_cast<int>(c.robot.modules.size()); ++j) {
      const auto it = loaded.find(j);
      if (it == loaded.end()) {
        still.insert(j);
        continue;
      }
      const MotionEnvelope range = SampleMotion(*it->second, c.duration_s);
      if (range.max_rad - range.min_rad < kMinTravelToExcite_rad) still.insert(j);
    }
    auto warn = [&](const std::string& pointer, const std::string& family, int j) {
      if (still.count(j) == 0) return;
      out.push_back(pointer + " (" + family + ") targets joint " + std::to_string(j) + ", which trajectory \"" +
                    t.name + "\" leaves still: " +
                    (FaultNeedsMotion(family) ? "its runs there will be not excited (" + family +
                                                    " shows only in motion) and left out of the rates"
                                              : "the fault can act at rest, but no motion of its joint helps see it"));
    };
    for (const FaultEntry& e : c.faults) {
      for (int j : e.joints) warn(e.pointer, e.family, j);
      // A compound entry: each element (its run is not excited only if no element can act).
      for (size_t i = 0; i < e.elements.size(); ++i) {
        const nlohmann::json& el = e.elements[i];
        if (el.contains("joint") && el["joint"].is_number_integer() && el.contains("family") && el["family"].is_string()) {
          warn(PointerJoin(PointerJoin(e.pointer, "compound"), i), el["family"].get<std::string>(), el["joint"].get<int>());
        }
      }
    }
  }
  return out;
}

}  // namespace armfault
