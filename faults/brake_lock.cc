// brake_lock: the power-off brake drags or fails to release: a brake torque on the motor
// shaft of drag_fraction x the holding torque; at 1.0 the joint cannot move (the drive's
// peak torque is below the holding torque). Effect: brake torque applied, link side.
#include "faults/family_support.h"  // the shared pieces; registry.cc lists this family

namespace armfault {

namespace {

class BrakeLock : public Fault {
 public:
  BrakeLock(const FaultCommon& c, double fraction, double holding_Nm)
      : Fault("brake_lock", c.joint_index, c.timing), fraction_(fraction), holding_Nm_(holding_Nm) {}
  void Apply(double severity, double, HardwareCondition* c) const override {
    c->brake_drag_Nm += severity * fraction_ * holding_Nm_;
  }
  nlohmann::json Parameters() const override { return {{"drag_fraction", fraction_}}; }
  std::unique_ptr<EffectMeter> MakeEffectMeter(const JointModel& joint) const override {
    const double margin = 0.01 * joint.ratio * holding_Nm_;
    return MakeMeanMeter("brake_torque_Nm", timing().onset_s, margin,
                         [](const JointTick& j) { return j.brake_torque_Nm; });
  }

 private:
  double fraction_;
  double holding_Nm_;
};

}  // namespace

std::unique_ptr<Fault> MakeBrakeLock(ObjectReader& reader, const RobotConfig& robot,
                                     const FaultMagnitudeSpec& magnitude) {
  ErrorList errors;  // the common keys and this family's, each on its own
  const FaultCommon common = ReadFaultCommon(reader, robot, {"drag_fraction"}, &errors);
  double f = 1.0;
  errors.Try([&] {
    ReadMagnitude(reader, magnitude, &f);
  });
  errors.ThrowIfAny();
  return std::make_unique<BrakeLock>(common, f, robot.modules[common.joint_index].brake.holding_torque_Nm);
}

}  // namespace armfault
