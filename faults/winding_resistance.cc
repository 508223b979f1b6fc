// winding_resistance: an overheating winding; the phase resistance becomes
// resistance_factor x R (>= 1). Effect: copper loss per ampere squared, i.e. R itself.
#include "faults/family_support.h"  // the shared pieces; registry.cc lists this family

namespace armfault {

namespace {

class WindingResistance : public Fault {
 public:
  WindingResistance(const FaultCommon& c, double factor)
      : Fault("winding_resistance", c.joint_index, c.timing), factor_(factor) {}
  void Apply(double severity, double, HardwareCondition* c) const override {
    c->resistance_factor *= 1.0 + severity * (factor_ - 1.0);
  }
  nlohmann::json Parameters() const override { return {{"resistance_factor", factor_}}; }
  std::unique_ptr<EffectMeter> MakeEffectMeter(const JointModel& joint) const override {
    return MakeRatioMeter("winding_resistance_ohm", timing().onset_s, joint.params.motor.phase_resistance_ohm, 0.02,
                          [](const JointTick& j) { return RatioTerms{j.current_sq_A2 > 0.01, j.p_copper_W, j.current_sq_A2}; });
  }

 private:
  double factor_;
};

}  // namespace

std::unique_ptr<Fault> MakeWindingResistance(ObjectReader& reader, const RobotConfig& robot,
                                             const FaultMagnitudeSpec& magnitude) {
  ErrorList errors;  // the common keys and this family's, each on its own
  const FaultCommon common = ReadFaultCommon(reader, robot, {"resistance_factor"}, &errors);
  double f = 1.0;
  errors.Try([&] {
    ReadMagnitude(reader, magnitude, &f);
  });
  errors.ThrowIfAny();
  return std::make_unique<WindingResistance>(common, f);
}

}  // namespace armfault
