// kt_degradation: magnet flux or winding damage; torque constant and back-EMF constant both
// become n K_T. Magnitude: kt_factor n in (0, 1]. Effect: torque per ampere actually produced.
#include <cmath>

#include "faults/family_support.h"  // the shared pieces; registry.cc lists this family

namespace armfault {

namespace {

class KtDegradation : public Fault {
 public:
  KtDegradation(const FaultCommon& c, double kt_factor) : Fault("kt_degradation", c.joint_index, c.timing), n_(kt_factor) {}
  void Apply(double severity, double, HardwareCondition* c) const override {
    c->kt_factor *= 1.0 - severity * (1.0 - n_);
  }
  nlohmann::json Parameters() const override { return {{"kt_factor", n_}}; }
  std::unique_ptr<EffectMeter> MakeEffectMeter(const JointModel& joint) const override {
    // Rotor torque per ampere actually flowing: two conducting phases carry I each, so
    // i_a^2 + i_b^2 + i_c^2 = 2 I^2 and a healthy motor gives |T| = K_T I.
    return MakeRatioMeter("torque_per_ampere_Nm_per_A", timing().onset_s, joint.params.motor.kt_Nm_per_A, 0.03,
                          [](const JointTick& j) {
                            return RatioTerms{j.current_sq_A2 > 0.08, std::fabs(j.torque_motor_Nm),
                                              std::sqrt(0.5 * j.current_sq_A2)};
                          });
  }

 private:
  double n_;
};

}  // namespace

std::unique_ptr<Fault> MakeKtDegradation(ObjectReader& reader, const RobotConfig& robot,
                                         const FaultMagnitudeSpec& magnitude) {
  ErrorList errors;  // the common keys and this family's, each on its own
  const FaultCommon common = ReadFaultCommon(reader, robot, {"kt_factor"}, &errors);
  double n = 1.0;
  errors.Try([&] {
    ReadMagnitude(reader, magnitude, &n);
  });
  errors.ThrowIfAny();
  return std::make_unique<KtDegradation>(common, n);
}

}  // namespace armfault
