// Decisions with a stated false-alarm rate ("decision": "sequential"; docs/monitor.md,
// "Sequential decision"): a one-sided CUSUM per joint and detector on the whitened innovation
// of the detector's residual model, its threshold set from a target number of false alarms per
// healthy hour of the arm.
//
// Residual model. At a look (every L_d seconds in which detector d has a statistic) the
// detector's signed deviation b (detector_statistics.h, in its units) is, on a healthy unit,
//     b_n = beta_n + e_n,  e_n ~ N(0, (s se_n)^2),
//     beta_n = P_m[beta_{n-1} + w_n],  w_n ~ N(0, m^2 L_d / T),  beta_0 ~ N(0, m^2)
// se the estimate's own standard error and s its scale (<detector>_se_scale: the fit's
// covariance is overconfident where its form is not the plant's), beta a bias the fit does not
// know (a warm-up, a lubricant the reference does not follow) that wanders over its model error
// m in T seconds (<detector>_bias_wander_s), anywhere inside it during the first settle_s
// (sequential_settle_s) of the statistic, and never above m (P_m: the projection onto
// beta <= m, and onto |beta| <= m for the signed drift; m fitted on healthy runs,
// docs/assumptions.md). A Kalman filter projected onto the bound follows beta (BiasFilter):
//     P- = min(P + m^2 L_d / T, m^2)  (m^2 while the detector's statistic is younger than
//          settle_s: the reference is still settling, its bias anywhere inside the bound),
//     S = P- + (s se)^2,  nu = b - beta^,
//     K = P- / S,  beta^ <- P_m[beta^ + K nu],  P <- (1 - K) P-,
// and the innovation z = nu / sqrt(S) is white N(0, 1) on a healthy unit: the test's
// false alarms are the rate it is set for. A fault moves b beyond what beta may follow: an
// abrupt one in one innovation, a slow one or one present from the start once beta^ sits at m
// (from there z = (b - m) / sqrt(S)), so wear is never learned away beyond m. Looks L_d =
// look_memories x the memory of the fit behind b apart are nearly independent (correlation
// exp(-look_memories)).
//
// Test. S_0 = 0, S_n = max(0, S_{n-1} + z_n - k) (Page's CUSUM; k = allowance_sd, optimal for a
// shift of 2k standard deviations); alarm when S > h. The sensor drift is signed: two CUSUMs
// (z and -z), its statistic the larger. Siegmund's approximation of the in-control average run
// length in looks,
//     ARL0(h, k) = (exp(2 k b) - 2 k b - 1) / (2 k^2),  b = h + 1.166,
// sets h: the arm's target rate lambda [1/h] is split equally over its N CUSUMs (per joint: K_T,
// resistance, friction, and two for the drift where a torque sensor is read), so each must
// have ARL0 = (3600 / L_d) N / lambda looks. Where the residual model holds, the measured rate is
// the target (a CUSUM that looks less than continuously alarms slightly less); a unit whose
// bias leaves the bound adds its alarms.
#pragma once

#include <algorithm>
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
// Each detector's standard-error scale s (Detectors() order).
std::array<double, kDetectorCount> SequentialSeScales(const MonitorConfig& config);
// Each detector's wander time T [s] (Detectors() order).
std::array<double, kDetectorCount> SequentialWanders(const MonitorConfig& config);
// The CUSUMs of an arm of `joints` joints of which `sensed` read a torque sensor.
int SequentialTestCount(int joints, int sensed);
// Each detector's threshold h for the config's target rate over `tests` CUSUMs.
DetectorThresholds SequentialThresholds(const MonitorConfig& config, int tests);
DetectorThresholds SequentialThresholds(const MonitorConfig& config, int tests, double target_per_hour);

// One CUSUM fed at its looks.
class Cusum {
 public:
  Cusum(double look_s, double allowance_sd) : look_s_(look_s), k_(allowance_sd) {}
  // A tick of dt seconds in which the detector has a statistic: true when a look is due.
  bool Advance(double dt);
  // A look with innovation z: the statistic S after it.
  double Look(double z);
  // Advance, and Look at z when a look is due. Returns S.
  double Tick(double dt, double z);
  double statistic() const { return s_; }
  double look_s() const { return look_s_; }

 private:
  double look_s_, k_;
  double since_look_s_ = 0;
  double s_ = 0;
};

// The healthy bias of a detector's deviation, as the residual model above holds it: a Kalman
// filter on a random walk projected onto beta <= m (|beta| <= m when `signed_bias`).
class BiasFilter {
 public:
  // `bound` m >= 0 [the statistic's units], `wander_s` T > 0, `settle_s` >= 0, `se_scale` s > 0.
  BiasFilter(double bound, double wander_s, double settle_s, double se_scale, bool signed_bias);
  struct Innovation {
    double nu = 0;  // b - beta^ before this look [the statistic's units]
    double sd = 0;  // sqrt(S), its standard deviation
  };
  // A look `look_s` seconds after the last: deviation b with standard error se. Returns the
  // innovation, then takes b.
  Innovation Look(double look_s, double b, double se);
  double bias() const { return beta_; }
  double variance() const { return p_; }

 private:
  double m_, wander_s_, settle_s_, scale_;
  bool signed_;
  double beta_ = 0, p_;
  double age_s_ = 0;  // seconds of looks taken
};

// One detector's sequential test on one joint: its bias filter and its CUSUM (two for the drift).
class SequentialTest {
 public:
  SequentialTest() : SequentialTest(1, 1, 0, 1, 0, 1, false) {}
  SequentialTest(double look_s, double allowance_sd, double bound, double wander_s, double settle_s, double se_scale,
                 bool two_sided);
  // A tick of dt seconds in which the detector reads deviation b with standard error se.
  // `whiten` maps the innovation to its z (z = nu / sd unless a hypothesis caps it). Returns
  // the statistic: S, the larger side's for a two-sided test.
  template <typename Whiten>
  double Tick(double dt, double b, double se, Whiten whiten) {
    const bool due = up_.Advance(dt);
    if (two_sided_) down_.Advance(dt);
    if (due) {
      const BiasFilter::Innovation in = bias_.Look(up_.look_s(), b, se);
      up_.Look(whiten(in.nu, in.sd));
      if (two_sided_) down_.Look(whiten(-in.nu, in.sd));
    }
    return statistic();
  }
  double statistic() const { return two_sided_ ? std::max(up_.statistic(), down_.statistic()) : up_.statistic(); }
  const BiasFilter& bias() const { return bias_; }

 private:
  Cusum up_, down_;
  BiasFilter bias_;
  bool two_sided_;
};

}  // namespace armfault
