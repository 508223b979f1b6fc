// A robot driven along a recorded log's own reference: the log that robot would have recorded
// for the same motion. `armfault calibrate` runs its twin so to correct its fit's bias
// (campaigns/data/calibrate.h); `armfault report --twin` so to compare a twin with a recording
// (campaigns/data/twin_compare.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/plant/robot/robot_config.h"
#include "core/signals/joint_signals.h"

namespace armfault {

// `robot` run along the log's reference (every joint's q_ref_rad and qd_ref_rad_s as the
// controller sampled them: exact at every tick, linear between; a joint whose qd_ref_rad_s has
// an empty cell takes the central difference of its q_ref_rad instead, as an import without
// that column has) for the log's duration, control period `control_dt_s`, sensor noise from
// `seed`. Returns one row per control tick, every joint's JointSignals. Throws InputError
// (source `source`) for a log of fewer than two ticks, another joint count than the robot's, a
// q_ref_rad that is not a number, or a run that fails.
std::vector<std::vector<JointSignals>> SimulateAlongLog(const RobotConfig& robot, double control_dt_s,
                                                        const std::vector<std::vector<JointSignals>>& log, uint64_t seed,
                                                        const std::string& source);

}  // namespace armfault
