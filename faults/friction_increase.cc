// friction_increase: bearing and harmonic-drive wear; the motor-side friction coefficients
// (viscous b, Coulomb F_c, static F_s) scale by friction_factor >= 1. Effect: dissipated
// friction power against what the healthy friction model gives on the same motion.
#include <cmath>

#include "core/plant/drive/friction.h"
#include "faults/family_support.h"  // the shared pieces; registry.cc lists this family

namespace armfault {

namespace {

class FrictionIncrease : public Fault {
 public:
  FrictionIncrease(const FaultCommon& c, double factor)
      : Fault("friction_increase", c.joint_index, c.timing), factor_(factor) {}
  void Apply(double severity, double, HardwareCondition* c) const override {
    c->friction_factor *= 1.0 + severity * (factor_ - 1.0);
  }
  nlohmann::json Parameters() const override { return {{"friction_factor", factor_}}; }
  std::unique_ptr<EffectMeter> MakeEffectMeter(const JointModel& joint) const override {
    const FrictionParams friction = joint.params.friction;
    const double ratio = joint.ratio;
    const double mesh = joint.params.drive.mesh_loss_fraction;
    return MakeRatioMeter("friction_power_vs_healthy_model", timing().onset_s, 1.0, 0.05,
                          [=](const JointTick& j) {
                            const double speed = std::fabs(j.qd_rad_s);
                            const double healthy = ratio * FrictionTorqueNm(friction, 1.0, j.qd_rad_s) * j.qd_rad_s +
                                                   mesh * std::fabs(j.tau_true_Nm) * speed;
                            return RatioTerms{speed > 0.02, j.p_friction_W, healthy};
                          });
  }

 private:
  double factor_;
};

}  // namespace

std::unique_ptr<Fault> MakeFrictionIncrease(ObjectReader& reader, const RobotConfig& robot,
                                            const FaultMagnitudeSpec& magnitude) {
  ErrorList errors;  // the common keys and this family's, each on its own
  const FaultCommon common = ReadFaultCommon(reader, robot, {"friction_factor"}, &errors);
  double f = 1.0;
  errors.Try([&] {
    ReadMagnitude(reader, magnitude, &f);
  });
  errors.ThrowIfAny();
  return std::make_unique<FrictionIncrease>(common, f);
}

}  // namespace armfault
