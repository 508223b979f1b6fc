// "hold": a constant angle (zero velocity and acceleration).
#include "core/plant/motion/trajectories.h"

namespace armfault {

namespace {

class Hold final : public Trajectory {
 public:
  explicit Hold(double angle_rad) : angle_(angle_rad) {}

  TrajectoryPoint At(double /*t_s*/) const override {
    TrajectoryPoint p;
    p.q_rad = angle_;
    return p;
  }
  const char* type() const override { return "hold"; }

 private:
  const double angle_;  // [rad]
};

}  // namespace

std::unique_ptr<Trajectory> MakeHold(ObjectReader& reader, const InputContext& /*ctx*/) {
  using namespace trajectory_detail;
  ErrorList errors;  // the unknown keys and the angle
  errors.Try([&] { reader.AllowOnly({"angle_deg"}); });
  double angle_deg = 0.0;
  errors.Try([&] { reader.OptionalNumber("angle_deg", &angle_deg); });
  errors.ThrowIfAny();
  return std::make_unique<Hold>(DegToRad(angle_deg));
}

}  // namespace armfault
