// Scoring of a campaign from its run records (results.jsonl): summary.json, floor verdicts
// and a JUnit report of the floors for CI.
//
// Definitions (all rates are fractions in [0, 1]):
//   - A record with ok == false counts only as a failed run: it is listed in "failed_runs"
//     and excluded from every rate, group, family and the confusion matrix.
//   - An ok faulty record that was not excited (its fault took no effect, or its joint stayed
//     still although the family shows only in motion) is listed in "not_excited_runs" and
//     counted in its scopes' "not_excited", outside every rate, unless the campaign sets
//     "include_not_excited": then it is scored like any other run.
//   - Faulty run: ok record with a non-empty `family`. Healthy run: ok record with family "".
//   - detection rate = detected faulty runs / faulty runs (`detected` already means "alarm at
//     or after the onset").
//   - false-alarm rate = healthy runs with `detected` / healthy runs.
//   - alarm_before_onset_rate = faulty runs with `alarm_before_onset` / faulty runs (reported
//     beside the false-alarm rate, not part of the overall floor).
//   - isolation accuracy = detected faulty runs with isolated_family == family and
//     isolated_joint == joint / detected faulty runs.
//   - latency (s): over detected faulty runs that carry latency_s; median (mean of the two
//     middle values for even n) and 95th percentile by nearest rank (sorted value at index
//     ceil(0.95 n) - 1); "misses" = undetected faulty runs.
//   - magnitude error: |estimate - magnitude| / |magnitude| over detected, correctly isolated
//     faulty runs that have a magnitude_estimate, a magnitude_key, magnitude_name ==
//     magnitude_key and magnitude != 0; count, mean and max.
//   - confusion: rows = true class (family, or "healthy"), columns = predicted class
//     (isolated_family if detected, "unknown" if detected without a family, else "healthy").
//     One label list for rows and columns: every family seen as true or predicted class,
//     sorted, then "healthy" and "unknown" (always present).
//   - per joint: per_joint holds, for each joint that had faulty runs (compound runs left out)
//     or a false alarm, its faulty runs' metrics (every family) and false_alarm = healthy runs
//     whose alarm named this joint / healthy runs; per_family_joint each (family, joint)'s.
//   - confusion_by_joint: as confusion, a class being (family, joint): rows the true (family,
//     joint) ({"healthy", null} for a healthy run), columns the named (isolated_family or
//     "unknown", isolated_joint) if detected, else {"healthy", null}; a fault named on the
//     wrong joint is off the diagonal here though not in "confusion".
//   Every rate is reported as {"rate", "low", "high", "successes", "trials"} with the 95 %
//   Wilson score interval.
//
// summary.json:
//   {"armfault_version", "campaign": <resolved campaign, as given>,
//    "campaign_hash": CampaignHash(campaign) (campaigns/scoring/provenance.h; null without a campaign),
//    "runs": {"total", "ok", "failed", "faulty", "healthy"},   (faulty/healthy: ok runs)
//    "overall": {"runs", "faulty_runs", "healthy_runs", "detection", "isolation",
//                "false_alarm", "alarm_before_onset_rate",
//                "latency": {"count", "median_s", "p95_s", "misses"},
//                "magnitude_error": {"count", "mean", "max"}},   (null statistics when count 0)
//    "per_family": {"<family>": {"runs", "faulty_runs", "detection", ... as overall without
//                                "healthy_runs" and "false_alarm"}},
//    "groups": [{"group", "family", "joint", "magnitude_key", "magnitude", "runs",
//                "faulty_runs", "detection", ...; "healthy_runs" and "false_alarm" only for a
//                group holding healthy runs}],   (sorted by group; null family etc. if healthy)
//    "confusion": {"labels": [...], "counts": [[row per true label]]},
//    "confusion_by_joint": {"labels": [{"family", "joint"}...], "counts": [[...]]},
//    "per_joint": [{"joint", "runs" (faulty), "faulty_runs", "not_excited", "detection",
//                   "isolation", "alarm_before_onset_rate", "latency", "magnitude_error",
//                   "healthy_runs", "false_alarm"}],   (sorted by joint)
//    "per_family_joint": [{"family", "joint", as per_family}],   (sorted by family, joint)
//    "floors": [{"name", "kind", "bound", "measured" (null if nothing to measure), "met",
//                "message"}],
//    "floors_met": all floors met (true if there are none),
//    "failed_runs": {"count", "truncated", "runs": [{"run_id", "reason"}]},
//                   (the 100 smallest run_ids, sorted, so the list is independent of order)
//    "not_excited_runs": {"count", "included", "truncated", "runs": [{"run_id", "reason"}]},
//    "not_injected_runs": {"count", "truncated", "runs": [{"run_id", "reason"}]},  (only with
//   conditional onsets: runs whose condition never fired, outside every rate; also "runs.not_injected")
//                   (likewise; faulty runs whose fault could not act on anything a monitor
//                    sees: left out of every rate unless "included")
//    "healthy_operation": HealthyOperation::ToJson (below; `run`, `merge`, `export`: not
//                         `replay`, whose "alarms_per_hour" counts the hours it replayed)}
//   Every scope also reports "not_excited": its faulty runs that could not act.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "campaigns/spec/campaign_spec.h"  // Floors
#include "campaigns/scoring/run_record.h"

namespace armfault {

struct FloorVerdict {
  std::string name;  // "detection_rate", "per_family/torque_sensor_stuck/detection_rate"
  std::string kind;  // "min" or "max"
  double bound = 0;
  std::optional<double> measured;  // nullopt: nothing to measure (no such runs); then not met
  bool met = false;
  std::string message;  // "detection_rate 0.850 < 0.900 (34 of 40 runs)"
  long successes = 0, trials = 0;  // what `measured` is the ratio of
};

namespace internal {

// Counts of one scope of runs (a group/family cell, a family, the whole campaign).
struct SummaryTally {
  long faulty = 0, detected = 0, isolated = 0, before_onset = 0;
  long healthy = 0, healthy_alarms = 0;
  long not_excited = 0;  // faulty runs whose fault could not act, left out of the counts above
  std::vector<double> latencies_s;       // detected faulty runs, in arrival order
  std::vector<double> magnitude_errors;  // relative, in arrival order
  // Descriptors of a group cell: the smallest (joint, magnitude_key, magnitude) seen, so
  // that they do not depend on the order of the records.
  bool has_descriptor = false;
  int joint = 0;
  std::string magnitude_key;
  double magnitude = 0;
};

// Adds `from`'s counts and values to `into` (descriptors untouched), as Build() pools cells.
void MergeTally(const SummaryTally& from, SummaryTally* into);

}  // namespace internal

// Accumulates run records one by one. Memory grows with the number of (group, family) pairs
// plus one latency and at most one magnitude error per detected run and at most 100 failed
// run ids, not with the number of records. The result does not depend on the order of Add().
class SummaryBuilder {
 public:
  // include_not_excited: score runs whose fault could not act like any other (the campaign's
  // "include_not_excited"); by default they are counted and listed apart, outside every rate.
  explicit SummaryBuilder(bool include_not_excited = false) : include_not_excited_(include_not_excited) {}
  void Add(const RunRecord& r);

  // The summary.json content (see above). `campaign` is the resolved campaign JSON, embedded
  // as is; `version` becomes "armfault_version".
  nlohmann::json Build(const Floors& floors, const nlohmann::json& campaign, const std::string& version) const;
  // One verdict per set floor: overall detection_rate, false_alarm_rate, isolation_accuracy,
  // then each per_family entry (sorted by family) in the same metric order.
  std::vector<FloorVerdict> Verdicts(const Floors& floors) const;

  long runs() const { return ok_runs_ + failed_runs_; }  // every record added
  // ok healthy runs, and those of them that alarmed (the false-alarm rate's trials and successes)
  long healthy_runs() const;
  long healthy_alarms() const;
  long not_excited_runs() const { return not_excited_runs_; }
  // ok faulty runs whose conditional onset never fired (RunRecord::injected), outside every rate
  long not_injected_runs() const { return not_injected_runs_; }
  bool includes_not_excited() const { return include_not_excited_; }  // ok faulty runs that could not act
  long failed_runs() const { return failed_runs_; }
  // The failed run of the lowest case number (whatever the order of Add()): what the console
  // and junit.xml name, so that a failure is seen with its reason, not only counted.
  struct FirstFailure {
    long case_index = -1;  // -1: no run failed
    std::string run_id, reason;
  };
  const FirstFailure& first_failure() const { return first_failure_; }
  // "run RUN_ID: REASON" of the first failure ("" when no run failed).
  std::string FirstFailureText() const;
  // Joints whose torque went beyond their sensor's range in some runs (RunRecord::
  // sensor_saturated_s): how many runs and the longest time in one, by joint number.
  struct SaturationTally {
    long runs = 0;
    double longest_s = 0;
  };
  const std::map<int, SaturationTally>& sensor_saturation() const { return saturation_; }
  // The tally of every (group, family) cell, sorted: for tools that compare or re-pool
  // campaigns (armfault diff) with exactly the definitions above.
  const std::map<std::pair<std::string, std::string>, internal::SummaryTally>& cells() const { return cells_; }
  // The scored faulty runs of each (family, joint), compound runs left out (no single joint);
  // not_excited counts its runs left out.
  const std::map<std::pair<std::string, int>, internal::SummaryTally>& family_joint_cells() const {
    return by_family_joint_;
  }
  // Per joint: its faulty runs (every family), and as healthy / healthy_alarms the campaign's
  // healthy runs and those whose false alarm named this joint. Joints with neither are absent.
  std::map<int, internal::SummaryTally> JointTallies() const;

  // The runs of one group on one trajectory (a JUnit test case), with the first run (lowest
  // case number) that went wrong: a faulty run missed or misisolated, a healthy run that
  // alarmed.
  struct TrajectoryCell {
    internal::SummaryTally tally;
    std::string not_excited_reason;  // of the first run left out as not excited
    long first_wrong_case = -1;
    std::string first_wrong_run_id;
  };
  // Key: (family, or "" for healthy runs; trajectory; group).
  using TrajectoryKey = std::tuple<std::string, std::string, std::string>;
  const std::map<TrajectoryKey, TrajectoryCell>& trajectory_cells() const { return by_trajectory_; }

  // Compound runs (docs/campaign-format.md, "Compound faults"), scored runs only; the section
  // "compound" of summary.json is written when any ok compound run was added.
  struct CompoundTally {
    long runs = 0, detected = 0, named = 0;  // named: the first alarm named one of its faults
    std::map<std::pair<size_t, std::string>, std::pair<long, long>> elements;  // (position, family) -> (isolated, runs)
  };
 private:
  std::map<int, SaturationTally> saturation_;
  std::map<std::pair<std::string, std::string>, internal::SummaryTally> cells_;  // (group, family)
  std::map<std::string, std::map<std::string, long>> confusion_;  // true -> predicted -> count
  // (family, joint) -> (named family, named joint) -> count; ("healthy", 0) for healthy / no alarm
  std::map<std::pair<std::string, int>, std::map<std::pair<std::string, int>, long>> joint_confusion_;
  std::map<std::pair<std::string, int>, internal::SummaryTally> by_family_joint_;
  std::map<int, long> healthy_alarms_by_joint_;  // healthy runs that alarmed, by the joint named (0: none)
  std::pair<nlohmann::json, nlohmann::json> PerJointJson() const;  // per_joint, per_family_joint
  nlohmann::json JointConfusionJson() const;
  std::map<TrajectoryKey, TrajectoryCell> by_trajectory_;
  std::multiset<std::pair<std::string, std::string>> failed_listed_;  // (run_id, reason)
  std::multiset<std::pair<std::string, std::string>> not_excited_listed_;  // (run_id, reason)
  bool include_not_excited_ = false;
  long not_excited_runs_ = 0;
  std::multiset<std::pair<std::string, std::string>> not_injected_listed_;  // (run_id, reason)
  long not_injected_runs_ = 0;
  long conditional_onset_runs_ = 0;  // ok runs whose fault has a conditional onset
  long ok_runs_ = 0;
  long failed_runs_ = 0;
  FirstFailure first_failure_;
  long compound_seen_ = 0;
  CompoundTally compound_;
  std::map<std::string, CompoundTally> compound_by_name_;
};

// JUnit XML with one testcase per floor verdict (classname "floors"), a <failure> for each
// floor not met; a single passing "no floors" testcase if there are none.
std::string JUnitXml(const std::string& campaign_name, const std::vector<FloorVerdict>& verdicts);

// The same floors suite, then one test suite per fault family (and "healthy") with one test
// case per group and trajectory, named "<trajectory>: <group>", holding its counts. The floors
// that apply to the family (its per_family floors, else the overall ones) are checked on the
// case's own runs; each one missed is a <failure> with the numbers and the command that
// replays the case's first wrong run: `armfault trace <campaign_json> --run <run_id>`, with
// `campaign_json` relative to the output directory (so a merged directory's file is the same).
// Then a suite "per joint": one case per joint ("joint 3") and per family x joint
// ("kt_degradation: joint 3") holding its counts, latency median and (per joint) the false
// alarms that named it; no floor is checked there.
std::string JUnitXml(const std::string& campaign_name, const SummaryBuilder& builder, const Floors& floors,
                     const std::string& campaign_json);

// The healthy runs' false alarms per hour of operation: each healthy run scored lasts the
// campaign's duration_s, and a false-alarmed one counts once (a monitor's first alarm ends
// its verdict). per_hour_upper_95: the one-sided 95 % upper bound on the rate the hours
// support (Poisson, chi-squared; 0 alarms in 20 h: 0.150 per hour).
struct HealthyOperation {
  long runs = 0;
  long false_alarms = 0;
  double hours = 0;
  double set_for_per_hour = 0;  // the rate the monitor states it was set for (0: none stated)
  // {"healthy_runs", "false_alarms", "hours", "per_hour", "per_hour_upper_95" (both null
  // without hours), "counted"}
  nlohmann::json ToJson() const;
  // "healthy operation: 120 runs, 20.0 h, 0 false alarms: 0 per hour (95 % upper bound 0.150)"
  std::string Line() const;
};
// `set_for_per_hour` > 0: written beside the measured rate ("set_for_per_hour"; the line's
// ", set for N per hour").
HealthyOperation HealthyOperationOf(const SummaryBuilder& builder, double duration_s, double set_for_per_hour = 0);

// 95 % Wilson score interval (z = 1.959963984540054) of successes / trials.
struct RateInterval {
  double rate = 0, low = 0, high = 1;
};
// trials == 0 gives rate 0, low 0, high 1. Throws std::invalid_argument unless
// 0 <= successes <= trials.
RateInterval Wilson(long successes, long trials);

}  // namespace armfault
