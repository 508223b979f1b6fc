// The built-in power-efficiency monitor's commissioning (core/monitors/commissioning.cc): fits
// one robot unit's calibration from the healthy signals streamed to it, tick by tick, without
// keeping them.
//
// Inputs: the nominal monitor model (datasheet calibration), the control period [s] (<= 0: the
// model's), then every controller tick's JointSignals of every joint, in time order.
// Output (End): the unit's monitor model, each joint's electrical and mechanical calibration
// fitted (least squares, pulled to the datasheet). Fewer than 3 ticks, or ticks of another
// joint count, leave the nominal model; a joint the motion hardly moved keeps the datasheet's
// torque balance.
//
// Holds per joint the electrical fit's normal equations (4×4), the torque balance's filter
// state, its XᵀX (6×6) and, since its target y = u − a p is linear in the gain a that the
// electrical fit gives only at End, Xᵀu, Xᵀp, uᵀu, uᵀp and pᵀp; the winding-temperature sum;
// and the previous tick's signals (the virtual torque sensor's accelerations and the
// per-period quantities need them). None of it grows with the commissioning's length. Summing
// y's terms apart moves the fit by about 1e-11 relative against forming y per tick (the
// outputs' last digits, 2026-11-25).
#pragma once

#include <memory>
#include <vector>

#include "core/monitors/power_monitor.h"
#include "core/monitors/torque_balance.h"
#include "core/signals/joint_signals.h"

namespace armfault {

class PowerMonitorCommissioning {
 public:
  PowerMonitorCommissioning(const PowerMonitorModel& nominal, double control_dt_s);
  ~PowerMonitorCommissioning();
  PowerMonitorCommissioning(const PowerMonitorCommissioning&) = delete;
  PowerMonitorCommissioning& operator=(const PowerMonitorCommissioning&) = delete;
  // One controller tick, every joint (1-based joint j at index j − 1).
  void Tick(const std::vector<JointSignals>& joints);
  // The unit's model after the ticks given so far.
  PowerMonitorModel End() const;
  // Ticks given so far, and the (joint, usable tick) rows in the torque balance's sums.
  long ticks() const { return ticks_; }
  long balance_rows() const;

 private:
  struct Joint;
  const PowerMonitorModel& nominal_;  // outlives this
  double dt_s_;
  std::vector<Joint> joints_;
  std::vector<BalanceFilter> filters_;
  std::vector<JointSignals> prev_, now_;  // the previous tick, filled; this tick's scratch
  long ticks_ = 0;
  bool valid_ = true;
};

}  // namespace armfault
