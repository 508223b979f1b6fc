// One run, in three stages, the same for every command:
//   PrepareCase  a campaign's case: its robot (its unit's, with the run's variation), its faults
//                as one set (a single fault is a set of one, a compound entry a set of several),
//                their conditional onsets resolved, the run spec, the monitor model of its unit,
//                and the record's identity and truth;
//   Execute      the plant with the monitor in the loop, scoring's tap beside it and the faults'
//                effect meters, returning the finished monitor with its output;
//   ScoreRun     the record's diagnosis, from the monitor's verdicts alone.
// RunCase is the three for one case. `trace`, `trace --run`, the report, thesis and the Python
// package use these stages and read the monitor's output from them; none runs a second monitor.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "campaigns/spec/campaign.h"
#include "campaigns/running/monitor_clock.h"
#include "campaigns/scoring/run_record.h"
#include "core/monitors/monitor.h"
#include "core/monitors/registry.h"
#include "core/plant/simulation.h"
#include "faults/fault.h"

namespace armfault {

// The monitor a unit's runs use: the campaign's (the datasheet, widened where tolerances are
// stated) or, with commissioning, that model fitted on the unit's commissioning run.
struct UnitMonitor {
  std::shared_ptr<const MonitorModel> model;
  std::string failure;  // non-empty: the unit's commissioning run failed, and why
};

// The commissioning motion of a robot: every joint on a sine pair of its own frequency, both
// ways through a good part of its range, for 16 s (docs/campaign-format.md, "Commissioning").
nlohmann::json CommissioningMotion(const RobotConfig& robot);
// Commissions the unit of `spec` (its robot, healthy, at the campaign's middle ambient, with a
// seed of the unit's own) and fits the monitor on what it recorded.
UnitMonitor CommissionUnit(const Campaign& campaign, const CaseSpec& spec);

// Per-unit monitors, each computed once, by the first run of that unit that needs it, from any
// thread. Runs that are their own unit are not cached.
class UnitMonitors {
 public:
  explicit UnitMonitors(const Campaign& campaign);
  UnitMonitor For(const CaseSpec& spec);

 private:
  const Campaign& campaign_;
  std::unique_ptr<std::once_flag[]> once_;
  std::vector<UnitMonitor> units_;
};

// A run's failure reason when its unit's commissioning run failed with `failure`.
std::string CommissioningFailureReason(const CaseSpec& spec, const std::string& failure);

// A case ready to run. `record` holds the case's identity and truth (family, joint, onset,
// magnitude; for a compound run its elements); its diagnosis is empty.
struct PreparedRun {
  RunRecord record;
  std::shared_ptr<const ArmModel> model;
  RunSpec spec;                                      // with the faults' schedule
  std::vector<std::shared_ptr<const Fault>> faults;  // the set, in the entry's order; empty: healthy
  std::shared_ptr<const MonitorModel> monitor;       // the unit's (commissioned where asked)
};
// Throws for a case that cannot be set up (RunCase makes that a failed record). A unit whose
// commissioning run failed gives a prepared run whose record is failed, with the reason, and no
// model. `units` (may be null) shares the commissioned monitors between the runs of one unit.
PreparedRun PrepareCase(const Campaign& campaign, const CaseSpec& spec, UnitMonitors* units);

// A run simulated with its monitor in the loop.
struct ExecutedRun {
  RunResult result;
  std::unique_ptr<HealthMonitor> monitor;  // finished (unless monitor_failure): output() is what scoring reads
  std::unique_ptr<DecisionTap> tap;        // null when the monitor publishes no statistics
  std::vector<FaultEffect> effects;        // one per fault of the set
  double first_tick_s = -1;                // the first controller tick at or after the onset
  nlohmann::json cost;                     // MonitorClock::ToJson; null after a monitor failure
  std::string monitor_failure;             // non-empty: the monitor threw MonitorFailure (why)
  std::map<int, double> sensor_saturated_s;  // RunRecord::sensor_saturated_s
};
// Simulates `spec` (its hardware schedule holds `faults`) with a new monitor of `monitor` fed the
// joints' signals at every tick, scoring's tap (knowing `onset_s`) after each call, the faults'
// effect meters, then `also`. Monitor failures are data (monitor_failure); a diverging plant is
// result.ok = false. Throws only what Simulate throws for a spec that does not fit the model.
// `keep_windows` false: the monitor keeps no efficiency windows (HealthMonitor::KeepWindows),
// what a campaign's run does so that its memory stays flat in the run's length.
// `statistics` (may be null): shown every published statistic at every tick
// (DecisionTap::ShowStatistics); a monitor that publishes none declares none to it.
ExecutedRun Execute(const ArmModel& model, const RunSpec& spec, const std::vector<std::shared_ptr<const Fault>>& faults,
                    const MonitorModel& monitor, double onset_s, const TickObserver& also = nullptr,
                    bool keep_windows = true, StatisticsObserver* statistics = nullptr);

// Sets a record's diagnosis (detection, latency, isolation, size) from its score.
void ApplyScore(const RunScore& score, RunRecord* record);
// A compound run's per-element isolation (RunRecord::compound): each element's "isolated"
// and "detection_time_s" from the first alarm verdict naming its family on its joint at or
// after its onset_s. Nothing for another run.
void ScoreCompoundElements(const MonitorOutput& output, RunRecord* r);
// The record of a prepared and executed run: effects, decision statistics, the monitor held to
// the contract, the score from its verdicts and why a wrong one is wrong.
RunRecord ScoreRun(const PreparedRun& prepared, const ExecutedRun& executed);

// One case, fully: PrepareCase, Execute, ScoreRun. Never throws for a failing run: the record
// says "failed" with the reason. `also` sees every tick after the monitor; `output` (may be
// null) receives the monitor's output, windows included; without it the monitor keeps none.
// `statistics` (may be null): as for Execute (`trace --run --statistics`).
RunRecord RunCase(const Campaign& campaign, const CaseSpec& spec, const TickObserver& also = nullptr,
                  UnitMonitors* units = nullptr, MonitorOutput* output = nullptr,
                  StatisticsObserver* statistics = nullptr);

// One case without a monitor: PrepareCase (no commissioning) and the plant with its
// sensor-saturation and effect meters, `also` seeing every tick. The record holds the case's
// identity, its truth and what the plant did (status, effect, excitation, sensor saturation);
// no diagnosis (nothing was watching), no cost. What `armfault export` writes, whose manifest
// holds nothing of a monitor: running one there would only cost time. Never throws, as RunCase.
RunRecord RunCasePlant(const Campaign& campaign, const CaseSpec& spec, const TickObserver& also = nullptr);

}  // namespace armfault
