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
// state and XᵀX (6×6), the winding-temperature sum, and the previous tick's signals (the
// virtual torque sensor's accelerations and the per-period quantities need them): none of it
// grows. What grows: 7 doubles per joint per usable tick (moving one way), the torque
// balance's regressors and target terms, since its target needs the electrical fit's gain,
// known only at End (commissioning.cc says why it is not summed linearly in the gain). The
// recording it replaces kept 9 doubles per joint per tick, moving or not, and a vector per tick.
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
  // Ticks given so far, and the (joint, usable tick) pairs kept for the torque balance (7
  // doubles each): what the fit holds that grows with the commissioning's length.
  long ticks() const { return ticks_; }
  long kept_rows() const;

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
