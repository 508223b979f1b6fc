// torque_sensor_stuck: a torque-sensor lead pinched by the harmonic-drive edge, shorted to the
// 5 V supply or to ground, or broken (open): the ADC reads the supply rail (full scale), 0 V,
// or holds its last sample. Magnitude: lead = supply | ground | open. Effect: the reading
// goes flat (its standard deviation, noise included, collapses) or, when the lead comes and
// goes (intermittent), the reading's error against the true torque jumps.
#include "faults/family_support.h"  // the shared pieces; registry.cc lists this family

namespace armfault {

namespace {

class TorqueSensorStuck : public Fault {
 public:
  TorqueSensorStuck(const FaultCommon& c, SensorLead lead, std::string name)
      : Fault("torque_sensor_stuck", c.joint_index, c.timing), lead_(lead), name_(std::move(name)) {}
  void Apply(double severity, double, HardwareCondition* c) const override {
    if (severity >= 0.5) c->torque_sensor_lead = lead_;
  }
  nlohmann::json Parameters() const override { return {{"lead", name_}}; }
  std::unique_ptr<EffectMeter> MakeEffectMeter(const JointModel&) const override {
    return MakeEitherMeter(MakeFlatnessMeter("sensor_reading_std_Nm", timing().onset_s, 0.2,
                                             [](const JointTick& j) { return j.signals.tau_sensor_Nm; }),
                           MakeRmsMeter("sensor_error_rms_Nm", timing().onset_s, 3.0, 0.1,
                                        [](const JointTick& j) { return j.signals.tau_sensor_Nm - j.tau_true_Nm; }));
  }

 private:
  SensorLead lead_;
  std::string name_;
};

}  // namespace

std::unique_ptr<Fault> MakeTorqueSensorStuck(ObjectReader& reader, const RobotConfig& robot,
                                             const FaultMagnitudeSpec&) {
  ErrorList errors;  // the common keys and this family's, each on its own
  const FaultCommon common = ReadFaultCommon(reader, robot, {"lead"}, &errors);
  std::string lead;
  SensorLead value = SensorLead::kSupply;
  errors.Try([&] {
    if (!reader.ShouldRead("lead")) return;
    lead = reader.RequireString("lead");
    if (lead == "supply") value = SensorLead::kSupply;
    else if (lead == "ground") value = SensorLead::kGround;
    else if (lead == "open") value = SensorLead::kOpen;
    else throw InputError("", reader.PointerTo("lead"), "unknown lead \"" + lead + "\" (known: supply, ground, open)");
  });
  errors.ThrowIfAny();
  return std::make_unique<TorqueSensorStuck>(common, value, lead);
}

}  // namespace armfault
