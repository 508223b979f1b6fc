// The cases of a campaign spec: the product trajectory x fault entry x its swept values x
// joint x repetition, then `healthy` fault-free runs per trajectory (or a boundary search's
// runs). Each case has a stable run_id and a seed derived from the campaign seed and that
// run_id, so a case runs the same on any machine, thread or shard; its variation (payload,
// noise, a unit's friction and tolerances, ambient) is drawn from that seed.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "core/monitors/registry.h"
#include "core/plant/robot/robot_config.h"
#include "campaigns/spec/campaign_spec.h"

namespace armfault {

// One run of a campaign, fully determined.
struct CaseSpec {
  long index = 0;
  std::string run_id;
  size_t trajectory = 0;       // index into Campaign::trajectories
  nlohmann::json fault;        // concrete fault JSON (uniform values drawn); null: healthy
  std::string group;           // family x parameters x joint ("" for healthy)
  unsigned long long seed = 0;
  int repetition = 0;
  // drawn variation
  double extra_payload_kg = 0;
  double torque_noise_Nm = -1;             // < 0: the robot's
  std::vector<double> friction_factors;    // per joint, true friction scale
  int unit = -1;                           // the robot unit (-1: this run is its own unit)
  double ambient_C = 20;
  bool warm_start = false;                 // the run's thermal nodes start warm (RunSpec::start)
  std::vector<std::vector<double>> tolerance_draws;  // [joint][ToleranceKeys() order]; empty: none
  std::vector<ConfounderDraw> confounder_draws;      // per joint (variation/confounders); empty: none
  nlohmann::json VariationJson() const;
};

// The robot of a case's unit: the campaign's robot with the unit's tolerances and friction
// (no run-to-run payload or noise).
RobotConfig UnitRobot(const CampaignSpec& campaign, const CaseSpec& spec);
// The case's robot: its unit's, with the run's payload and sensor noise.
RobotConfig CaseRobot(const CampaignSpec& campaign, const CaseSpec& spec);
// The stated tolerances the monitor may know (with the friction spread and ambient range).
StatedTolerances StatedOf(const CampaignSpec& campaign);
// All the monitor may know of the campaign (core/monitors/registry.h): the nominal robot, the
// stated tolerances, commissioning, and where its files resolve.
MonitorContext MonitorContextOf(const CampaignSpec& campaign);

// Case `index` (0 <= index < CaseCount) from the campaign and the index alone: its mixed-radix
// position in trajectory x (fault entry: values x joint x repetition, then healthy runs).
// Nothing is held per case, so counting, shard selection, resume and merge stay flat in
// memory whatever the campaign's size. Throws std::out_of_range outside [0, CaseCount).
CaseSpec CaseAt(const CampaignSpec& campaign, long index);
// All cases in order (CaseAt of every index): for small campaigns and tests.
std::vector<CaseSpec> ExpandCases(const CampaignSpec& campaign);

// The run_id of a search run: "<trajectory>/<family>#<entry>/<key>=<magnitude>/j<joint>/s<number>".
std::string SearchRunId(const CampaignSpec& campaign, const SearchRun& run);

}  // namespace armfault
