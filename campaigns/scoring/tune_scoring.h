// The scoring engine of `armfault tune` (internal to campaigns/tuning/tuning.cc): every run as a
// table of its first alarms under every threshold setting (RunTable, built from its stored
// statistics), and the scores of every setting, the operating point and the report's ROC,
// latency and detection-probability sections from those tables (ScoreRuns). The same for
// the power monitor's detectors and for published statistics.
#pragma once

#include <nlohmann/json.hpp>

#include <limits>
#include <string>
#include <vector>

#include "core/monitors/detector_statistics.h"
#include "core/monitors/threshold_statistics.h"
#include "campaigns/scoring/tune_options.h"

namespace armfault {
namespace tune {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Outcome of one detector (over all joints) or of the tick-level events, for one threshold.
struct Hit {
  double t = kInf;
  int joint = 0;
  int family = -1;  // index into the family table
  bool pre = false;  // alarm before the onset
};

struct FamilyTable {
  std::vector<std::string> names;
  int Id(const std::string& name) {
    for (size_t i = 0; i < names.size(); ++i) {
      if (names[i] == name) return static_cast<int>(i);
    }
    names.push_back(name);
    return static_cast<int>(names.size()) - 1;
  }
};

// What tune sweeps: one axis per threshold (a power-monitor detector's worn limit, or a published
// statistic's threshold), and the significance the power monitor's detectors share.
struct TuneAxis {
  std::string name;     // "kt_factor.worn", or the statistic's name
  std::string family;   // the family its alarms name
  double default_value = 0;
  std::vector<double> values;
  std::vector<double> thresholds;  // the threshold each value sets (tie margins compare these)
};
struct TuneSpace {
  std::vector<TuneAxis> axes;
  std::vector<double> significance;  // empty: none (published statistics)
  double default_significance = 0;
  bool joint_first = false;  // ties at one instant: the lower joint first, else the axis order
  size_t SignificanceCount() const { return std::max<size_t>(1, significance.size()); }
};
// One index per axis, then the significance's (0 when there is none).
using Setting = std::vector<int>;

struct RunTable {
  bool select = true;  // in the half the operating point is chosen on (even seed)
  int family = -1;  // true family id, -1 healthy
  int joint = 0;
  std::string magnitude_key;
  double magnitude = 0;
  std::string category;  // magnitude of a family without a numeric one (the stuck lead...)
  double onset_s = 0;
  double observed_s = 0;  // monitored seconds (the sequential decision's runs: a healthy run's exposure)
  Hit event;
  std::vector<std::vector<std::vector<Hit>>> hits;  // [axis][significance][value]
};

// The first alarm of each run's detector `d` at (threshold, significance) from its power-monitor
// statistics, and of its tick-level events; families are numbered in `families` as they come.
Hit DetectorHit(const DecisionStats& s, Detector d, double threshold, double significance, FamilyTable* families);
Hit EventHit(const DecisionStats& s, FamilyTable* families);
// A run's hits under every setting of a published-statistics space.
void StatisticHits(const ThresholdStats& stats, const TuneSpace& space, FamilyTable* families, RunTable* r);

// The first alarm of a run under the setting k: the same order as Decide() (power monitor) or
// DecideThresholds() (published statistics).
Hit Combine(const RunTable& r, const Setting& k, const TuneSpace& space);

struct Scored {
  nlohmann::json report;
  Setting op;
  long settings = 0;
};

// Scores every setting of `space` on the runs, picks the operating point by the rule and writes
// the report (docs/tuning.md): the same for the power monitor's detectors and for published
// statistics. `failed`: the runs that failed (counted in the report); `extra_warnings` lead
// its "warnings".
Scored ScoreRuns(const TuneSpace& space, const std::vector<RunTable>& runs, const FamilyTable& families, long failed,
                 const std::string& campaign_name, const std::string& campaign_hash, const TuneOptions& options,
                 const std::vector<std::string>& extra_warnings);

}  // namespace tune
}  // namespace armfault
