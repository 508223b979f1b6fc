#include "campaigns/data/log_reference.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/base/json_input.h"
#include "core/plant/simulation.h"
#include "core/plant/motion/trajectory.h"
#include "core/run_config.h"

namespace armfault {
namespace {

// The log's reference, as the controller sampled it: exact at every tick, linear between.
class LoggedReference final : public Trajectory {
 public:
  LoggedReference(const std::vector<std::vector<JointSignals>>& ticks, size_t joint, double dt) : dt_(dt) {
    bool velocity = true;
    for (const auto& t : ticks) {
      q_.push_back(t[joint].q_ref_rad), qd_.push_back(t[joint].qd_ref_rad_s);
      velocity = velocity && std::isfinite(qd_.back());
    }
    // No logged velocity (an import without the column): the reference's own slope.
    if (!velocity) {
      for (size_t k = 0; k < q_.size(); ++k) {
        const size_t lo = k > 0 ? k - 1 : 0, hi = std::min(k + 1, q_.size() - 1);
        qd_[k] = (q_[hi] - q_[lo]) / (static_cast<double>(hi - lo) * dt_);
      }
    }
  }
  TrajectoryPoint At(double t_s) const override {
    TrajectoryPoint p;
    const double last = static_cast<double>(q_.size() - 1);
    const double x = std::clamp(t_s / dt_, 0.0, last);
    const size_t k = std::min(static_cast<size_t>(x), q_.size() - 2);
    const double u = x - static_cast<double>(k);
    p.q_rad = q_[k] + u * (q_[k + 1] - q_[k]);
    p.qd_rad_s = qd_[k] + u * (qd_[k + 1] - qd_[k]);
    // The controller reads the reference at its ticks: there, a central difference of the
    // logged velocity (a forward one would lead the acceleration by half a period).
    const size_t c = std::min(static_cast<size_t>(std::lround(x)), q_.size() - 1);
    const size_t lo = c > 0 ? c - 1 : 0, hi = std::min(c + 1, q_.size() - 1);
    p.qdd_rad_s2 = (qd_[hi] - qd_[lo]) / (static_cast<double>(hi - lo) * dt_);
    return p;
  }
  const char* type() const override { return "log"; }

 private:
  double dt_;
  std::vector<double> q_, qd_;
};

}  // namespace

std::vector<std::vector<JointSignals>> SimulateAlongLog(const RobotConfig& robot, double control_dt_s,
                                                        const std::vector<std::vector<JointSignals>>& log, uint64_t seed,
                                                        const std::string& source) {
  const size_t n = robot.modules.size();
  if (log.size() < 2) throw InputError(source, "", "the log holds " + std::to_string(log.size()) + " ticks: no motion to run");
  for (size_t t = 0; t < log.size(); ++t) {
    if (log[t].size() != n) {
      throw InputError(source, "", "tick " + std::to_string(t) + " holds " + std::to_string(log[t].size()) +
                                       " joints; the robot has " + std::to_string(n));
    }
    for (size_t j = 0; j < n; ++j) {
      if (!std::isfinite(log[t][j].q_ref_rad)) {
        throw InputError(source, "", "tick " + std::to_string(t) + ": joint " + std::to_string(j + 1) +
                                         "'s q_ref_rad is not a number (the reference the robot is run along)");
      }
    }
  }
  RunConfig run;
  run.robot = robot;
  run.duration_s = control_dt_s * static_cast<double>(log.size() - 1);
  run.seed = seed;
  for (size_t j = 0; j < n; ++j) {
    run.trajectories[static_cast<int>(j) + 1] = std::make_shared<LoggedReference>(log, j, control_dt_s);
  }
  const ArmModel model(run.robot);
  std::vector<std::vector<JointSignals>> out;
  out.reserve(log.size());
  const RunResult r = Simulate(model, MakeRunSpec(run), [&](const Tick& tick) {
    std::vector<JointSignals> row;
    row.reserve(tick.joints->size());
    for (const JointTick& j : *tick.joints) row.push_back(j.signals);
    out.push_back(std::move(row));
  });
  if (!r.ok) throw InputError(source, "", "the robot did not run the log's motion: " + r.failure_reason);
  return out;
}

}  // namespace armfault
