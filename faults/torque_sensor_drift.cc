// torque_sensor_drift: the strain-gauge bridge or amplifier drifts: the reading gains an
// offset growing at drift_Nm_per_s from onset. Effect: RMS of the reading's error.
#include <cmath>

#include "faults/family_support.h"  // the shared pieces; registry.cc lists this family

namespace armfault {

namespace {

class TorqueSensorDrift : public Fault {
 public:
  TorqueSensorDrift(const FaultCommon& c, double rate) : Fault("torque_sensor_drift", c.joint_index, c.timing), rate_(rate) {}
  void Apply(double severity, double t_s, HardwareCondition* c) const override {
    c->torque_sensor_drift_Nm += severity * rate_ * (t_s - timing().onset_s);
  }
  nlohmann::json Parameters() const override { return {{"drift_Nm_per_s", rate_}}; }
  std::unique_ptr<EffectMeter> MakeEffectMeter(const JointModel&) const override {
    return MakeRmsMeter("sensor_error_rms_Nm", timing().onset_s, 3.0, 0.1,
                        [](const JointTick& j) { return j.signals.tau_sensor_Nm - j.tau_true_Nm; });
  }

 private:
  double rate_;
};

}  // namespace

std::unique_ptr<Fault> MakeTorqueSensorDrift(ObjectReader& reader, const RobotConfig& robot,
                                             const FaultMagnitudeSpec& magnitude) {
  ErrorList errors;  // the common keys and this family's, each on its own
  const FaultCommon common = ReadFaultCommon(reader, robot, {"drift_Nm_per_s"}, &errors);
  double rate = 1.0;
  errors.Try([&] {
    ReadMagnitude(reader, magnitude, &rate);
  });
  errors.ThrowIfAny();
  return std::make_unique<TorqueSensorDrift>(common, rate);
}

}  // namespace armfault
