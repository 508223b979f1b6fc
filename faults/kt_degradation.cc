// kt_degradation: magnet flux or winding damage; torque constant and back-EMF constant both
// become n K_T. Magnitude: kt_factor n in (0, 1]. Effect: torque per ampere actually produced.
#include <cmath>

#include "faults/family_support.h"

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
    // Regression of the rotor torque on the commanded current, where the command is large
    // enough for the current loop to follow it closely.
    return MakeRatioMeter("torque_per_ampere_Nm_per_A", timing().onset_s, joint.params.motor.kt_Nm_per_A, 0.03,
                          [](const JointTick& j) {
                            return RatioTerms{std::fabs(j.i_cmd_A) > 0.2, j.torque_motor_Nm * j.i_cmd_A,
                                              j.i_cmd_A * j.i_cmd_A};
                          });
  }

 private:
  double n_;
};

}  // namespace

std::unique_ptr<Fault> MakeKtDegradation(ObjectReader& reader, const RobotConfig& robot) {
  const FaultCommon common = ReadFaultCommon(reader, robot, {"kt_factor"});
  const double n = reader.RequireNumber("kt_factor");
  RequireAbove(n, 0.0, reader.PointerTo("kt_factor"));
  RequireInRange(n, 0.0, 1.0, reader.PointerTo("kt_factor"));
  return std::make_unique<KtDegradation>(common, n);
}

}  // namespace armfault
