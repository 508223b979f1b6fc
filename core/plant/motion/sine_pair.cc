// "sine_pair": q = offset + A (sin(w t) - 0.5 sin(2 w t)).
// Starts at the offset with zero velocity and acceleration, so a run can begin at rest.
#include "core/plant/motion/trajectories.h"

#include <cmath>

namespace armfault {

namespace {

class SinePair final : public Trajectory {
 public:
  SinePair(double amplitude_rad, double omega_rad_s, double offset_rad)
      : a_(amplitude_rad), w_(omega_rad_s), offset_(offset_rad) {}

  TrajectoryPoint At(double t_s) const override {
    const double wt = w_ * t_s;
    TrajectoryPoint p;
    p.q_rad = offset_ + a_ * (std::sin(wt) - 0.5 * std::sin(2.0 * wt));
    p.qd_rad_s = a_ * w_ * (std::cos(wt) - std::cos(2.0 * wt));
    p.qdd_rad_s2 = a_ * w_ * w_ * (2.0 * std::sin(2.0 * wt) - std::sin(wt));
    return p;
  }
  const char* type() const override { return "sine_pair"; }
  double shortest_period_s() const override { return trajectory_detail::kPi / w_; }  // of sin(2 w t)

 private:
  const double a_;       // [rad]
  const double w_;       // [rad/s]
  const double offset_;  // [rad]
};

}  // namespace

std::unique_ptr<Trajectory> MakeSinePair(ObjectReader& reader, const InputContext& /*ctx*/) {
  using namespace trajectory_detail;
  ErrorList errors;  // every key on its own
  errors.Try([&] { reader.AllowOnly({"amplitude_deg", "omega_rad_s", "offset_deg"}); });
  double amplitude_deg = 0.0, omega_rad_s = 1.0, offset_deg = 0.0;
  errors.Try([&] {
    if (reader.ShouldRead("amplitude_deg")) amplitude_deg = reader.RequireNumber("amplitude_deg");
  });
  errors.Try([&] {
    if (!reader.ShouldRead("omega_rad_s")) return;
    omega_rad_s = reader.RequireNumber("omega_rad_s");
    RequireAbove(omega_rad_s, 0.0, reader.PointerTo("omega_rad_s"));
  });
  errors.Try([&] { reader.OptionalNumber("offset_deg", &offset_deg); });
  errors.ThrowIfAny();
  return std::make_unique<SinePair>(DegToRad(amplitude_deg), omega_rad_s, DegToRad(offset_deg));
}

}  // namespace armfault
