// "cosine_ramp": q = offset + A (1 - cos(2 pi t / T)).
// Rises smoothly from the offset (zero velocity at t = 0) to offset + 2A at T/2 and back.
#include "core/plant/motion/trajectories.h"

#include <cmath>

namespace armfault {

namespace {

class CosineRamp final : public Trajectory {
 public:
  CosineRamp(double amplitude_rad, double period_s, double offset_rad)
      : a_(amplitude_rad), w_(2.0 * trajectory_detail::kPi / period_s), offset_(offset_rad), period_s_(period_s) {}

  TrajectoryPoint At(double t_s) const override {
    const double wt = w_ * t_s;
    TrajectoryPoint p;
    p.q_rad = offset_ + a_ * (1.0 - std::cos(wt));
    p.qd_rad_s = a_ * w_ * std::sin(wt);
    p.qdd_rad_s2 = a_ * w_ * w_ * std::cos(wt);
    return p;
  }
  const char* type() const override { return "cosine_ramp"; }
  double shortest_period_s() const override { return period_s_; }

 private:
  const double a_;       // [rad]
  const double w_;       // 2 pi / T [rad/s]
  const double offset_;  // [rad]
  const double period_s_;
};

}  // namespace

std::unique_ptr<Trajectory> MakeCosineRamp(ObjectReader& reader, const InputContext& /*ctx*/) {
  using namespace trajectory_detail;
  ErrorList errors;  // every key on its own
  errors.Try([&] { reader.AllowOnly({"amplitude_deg", "period_s", "offset_deg"}); });
  double amplitude_deg = 0.0, period_s = 1.0, offset_deg = 0.0;
  errors.Try([&] {
    if (reader.ShouldRead("amplitude_deg")) amplitude_deg = reader.RequireNumber("amplitude_deg");
  });
  errors.Try([&] {
    if (!reader.ShouldRead("period_s")) return;
    period_s = reader.RequireNumber("period_s");
    RequireAbove(period_s, 0.0, reader.PointerTo("period_s"));
  });
  errors.Try([&] { reader.OptionalNumber("offset_deg", &offset_deg); });
  errors.ThrowIfAny();
  return std::make_unique<CosineRamp>(DegToRad(amplitude_deg), period_s, DegToRad(offset_deg));
}

}  // namespace armfault
