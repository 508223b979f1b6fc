// "min_jerk": waypoints [[time_s, angle_deg], ...] joined by quintic minimum-jerk segments,
// s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5, which start and end each segment with zero
// velocity and acceleration (so acceleration is continuous across waypoints). Before the
// first waypoint its angle is held, after the last one the last angle.
#include "core/plant/motion/trajectories.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace armfault {

namespace {

class MinJerk final : public Trajectory {
 public:
  MinJerk(std::vector<double> times_s, std::vector<double> angles_rad)
      : times_(std::move(times_s)), angles_(std::move(angles_rad)) {}

  TrajectoryPoint At(double t_s) const override {
    TrajectoryPoint p;
    // `!(t > first)` also catches NaN, which then holds the first angle.
    if (!(t_s > times_.front())) {
      p.q_rad = angles_.front();
      return p;
    }
    if (t_s >= times_.back()) {
      p.q_rad = angles_.back();
      return p;
    }
    // times_[k] <= t < times_[k + 1]; a waypoint's own time starts its segment at tau = 0,
    // so the waypoint angle is returned exactly.
    const size_t k = static_cast<size_t>(
        std::upper_bound(times_.begin(), times_.end(), t_s) - times_.begin() - 1);
    const double h = times_[k + 1] - times_[k];
    const double u = (t_s - times_[k]) / h;
    const double delta = angles_[k + 1] - angles_[k];
    const double s = u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
    const double ds = 30.0 * u * u * (1.0 - u) * (1.0 - u);          // ds/du
    const double dds = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u);       // d2s/du2
    p.q_rad = angles_[k] + delta * s;
    p.qd_rad_s = delta * ds / h;
    p.qdd_rad_s2 = delta * dds / (h * h);
    return p;
  }
  const char* type() const override { return "min_jerk"; }

 private:
  const std::vector<double> times_;   // [s], >= 0, strictly increasing, at least one
  const std::vector<double> angles_;  // [rad], one per time
};

}  // namespace

std::unique_ptr<Trajectory> MakeMinJerk(ObjectReader& reader, const InputContext& /*ctx*/) {
  using namespace trajectory_detail;
  ErrorList errors;  // the unknown keys and the waypoints
  errors.Try([&] { reader.AllowOnly({"waypoints"}); });
  std::vector<double> times_s, angles_rad;
  errors.Try([&] {
    if (!reader.ShouldRead("waypoints")) return;
    const std::string pointer = reader.PointerTo("waypoints");
    const nlohmann::json& waypoints = reader.Require("waypoints");
    if (!waypoints.is_array() || waypoints.empty()) {
      throw InputError("", pointer,
                       "expected a non-empty array of [time_s, angle_deg] pairs, got " +
                           Describe(waypoints));
    }
    for (size_t i = 0; i < waypoints.size(); ++i) {
      const nlohmann::json& pair = waypoints[i];
      const std::string at = PointerJoin(pointer, i);
      if (!pair.is_array() || pair.size() != 2) {
        throw InputError("", at, "expected a [time_s, angle_deg] pair, got " + Describe(pair));
      }
      const double t = AsNumber(pair[0], PointerJoin(at, size_t{0}));
      const double angle_deg = AsNumber(pair[1], PointerJoin(at, size_t{1}));
      RequireAtLeast(t, 0.0, PointerJoin(at, size_t{0}));
      if (!times_s.empty() && !(t > times_s.back())) {
        throw InputError("", PointerJoin(at, size_t{0}),
                         "waypoint time " + FormatNumber(t) + " s is not after the previous one (" +
                             FormatNumber(times_s.back()) + " s); times must strictly increase");
      }
      times_s.push_back(t);
      angles_rad.push_back(DegToRad(angle_deg));
    }
  });
  errors.ThrowIfAny();
  return std::make_unique<MinJerk>(std::move(times_s), std::move(angles_rad));
}

}  // namespace armfault
