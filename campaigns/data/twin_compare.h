// A twin against a recording (`armfault report DIR --twin unit.json`, docs/calibration.md,
// "Compare"): the twin (a robot, as `armfault calibrate` writes one) run along one recorded
// run's own reference (campaigns/data/log_reference.h), and per joint each signal as recorded, as
// the twin gives it, and their residual (recorded − twin) tick by tick, with its RMS.
//
// Signals per joint: the supply power U_d·I_d [W] and current I_d [A] (measured, as the
// monitor's electrical balance reads them), the commanded current i [A], the torque-sensor
// reading τ_s [N m] (where the joint has a sensor: a recorded column of numbers), and the
// tracking error q_ref − q_meas [mrad]. A twin of the very unit leaves the sensors' noise and
// quantisation in the residual; a wrong value (K_T, friction, a payload) a systematic part.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/plant/robot/robot_config.h"
#include "core/signals/joint_signals.h"

namespace armfault {

struct TwinSignal {
  std::string key;    // "supply_power_W", "supply_current_A", "commanded_current_A", "torque_sensor_Nm", "tracking_error_mrad"
  std::string label;  // for the page: "supply power U_d·I_d"
  std::string unit;   // "W", "A", "N m", "mrad"
  std::vector<double> recorded, twin;  // per tick (NaN where a value is missing)
  // Over the ticks where both are numbers: RMS of each and of recorded − twin, and its mean.
  double recorded_rms = 0, twin_rms = 0, residual_rms = 0, residual_mean = 0;
  long compared_ticks = 0;
};

struct JointComparison {
  int joint = 0;  // 1-based
  std::vector<TwinSignal> signals;
  const TwinSignal* Find(const std::string& key) const;
};

struct TwinComparison {
  std::string run_id;
  std::string why;           // how the run was chosen, for the page
  std::string twin_file;     // the twin's robot file (or preset), as given
  std::string twin_name;     // its robot's name
  std::string signals_file;  // the recorded run's signals
  std::string family;        // the run's fault family ("" healthy or unlabelled)
  std::optional<double> onset_s;
  double control_dt_s = 0;
  uint64_t seed = 1;         // the twin's sensor noise
  std::vector<double> t_s;   // the recording's ticks
  std::vector<JointComparison> joints;
};

// Runs `twin` along `log` (ticks at `control_dt_s`, times `t_s`) and compares. InputError
// (source `source`) as SimulateAlongLog's.
TwinComparison CompareWithTwin(const RobotConfig& twin, double control_dt_s, const std::vector<double>& t_s,
                               const std::vector<std::vector<JointSignals>>& log, uint64_t seed, const std::string& source);

struct TwinCompareOptions {
  std::string twin_file;     // how the twin was named (errors, the page), and where its calibration sits
  RobotConfig twin;          // read by the caller (a robot file or preset)
  std::string recorded_dir;  // the export or import: manifest.jsonl, runs/*.csv.gz, campaign.json
  // The run; empty: the run the twin was calibrated on (TWIN.calibration.json's "run_id", when
  // the manifest holds it), else the manifest's first healthy run, else its first run.
  std::string run_id;
  std::string run_option = "--twin-run";  // the option that names the run, for errors
  uint64_t seed = 1;
};

// Reads the run's signals from recorded_dir (at its robot's control rate) and compares.
// InputError (exit status 2) for: a recorded_dir without manifest.jsonl or campaign.json, an
// unknown run (naming the nearest run_id), a twin of another joint count or control period
// than the recorded robot (naming the twin file, its "modules" and both values), a signals
// file that does not read.
TwinComparison CompareRecordedRun(const TwinCompareOptions& options);

}  // namespace armfault
