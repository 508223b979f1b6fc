// Decisions with a stated false-alarm rate ("decision": "sequential"; docs/monitor.md,
// "Sequential decision"): a one-sided CUSUM per joint and detector on the whitened innovation
// of the detector's residual model, its threshold set from a target number of false alarms per
// healthy hour of the arm.
//
// Residual model. At a look (every L_d seconds in which detector d has a statistic) the
// detector's signed deviation b (detector_statistics.h, in its units) is, on a healthy unit,
//     b = beta + e,  |beta| <= m,  e ~ N(0, se^2)
// se the estimate's own standard error, beta a bias the fit's covariance does not know (the
// reference's form is not the plant's: a warm-up, a lubricant it does not follow), bounded by
// the model error m, fitted on healthy runs (docs/assumptions.md). The innovation
// z = (b - m) / se then has a mean <= 0, and looks L_d apart, L_d = look_memories x the memory of
// the fit behind b, are nearly independent (correlation exp(-look_memories)).
//
// Test. S_0 = 0, S_n = max(0, S_{n-1} + z_n - k) (Page's CUSUM; k = allowance_sd, optimal for a
// shift of 2k standard deviations); alarm when S > h. The sensor drift is signed: two CUSUMs
// (z and -z), its statistic the larger. Siegmund's approximation of the in-control average run
// length in looks,
//     ARL0(h, k) = (exp(2 k b) - 2 k b - 1) / (2 k^2),  b = h + 1.166,
// sets h: the arm's target rate lambda [1/h] is split equally over its N CUSUMs (per joint: K_T,
// resistance, friction, and two for the drift where a torque sensor is read), so each must
// have ARL0 = (3600 / L_d) N / lambda looks. Innovations of mean <= 0 run at least that long, and
// a CUSUM that looks less than continuously alarms less: the measured rate is at most the
// target when the residual model holds (a bound, not a prediction).
#pragma once

#include <array>

#include "core/monitors/detector_statistics.h"

namespace armfault {

struct MonitorConfig;

// The significance a sequential decision's held statistic carries (0 standard errors, in
// quanta) and is judged against: its CUSUM alone decides.
inline constexpr double kSequentialSignificance = 0.0;

// Siegmund's ARL0 [looks] of a one-sided CUSUM with allowance k > 0 and threshold h >= 0.
double SiegmundArl(double h, double k);
// The threshold h >= 0 whose SiegmundArl is `arl_looks` (0 when even h = 0 runs longer).
double CusumThreshold(double arl_looks, double k);

// Seconds between looks of each detector (Detectors() order): look_memories x its fit's memory.
std::array<double, kDetectorCount> SequentialLooks(const MonitorConfig& config);
// Each detector's model error m, the bound on a healthy deviation's bias (Detectors() order), in its units.
std::array<double, kDetectorCount> SequentialModelErrors(const MonitorConfig& config);
// The CUSUMs of an arm of `joints` joints of which `sensed` read a torque sensor.
int SequentialTestCount(int joints, int sensed);
// Each detector's threshold h for the config's target rate over `tests` CUSUMs.
DetectorThresholds SequentialThresholds(const MonitorConfig& config, int tests);
DetectorThresholds SequentialThresholds(const MonitorConfig& config, int tests, double target_per_hour);

// One CUSUM fed at its looks.
class Cusum {
 public:
  Cusum(double look_s, double allowance_sd) : look_s_(look_s), k_(allowance_sd) {}
  // A tick of dt seconds in which the detector has innovation z (nothing when it has no
  // statistic). Returns the statistic S after it.
  double Tick(double dt, double z);
  double statistic() const { return s_; }

 private:
  double look_s_, k_;
  double since_look_s_ = 0;
  double s_ = 0;
};

}  // namespace armfault
