// friction_increase: bearing and harmonic-drive wear. With "friction_terms": "all" (the
// default) every friction term of the joint scales by friction_factor >= 1: the motor side's
// viscous b, Coulomb F_c and static F_s, and the gear's mesh loss and load-dependent friction,
// so that 1.5 means 1.5x the friction torque at the same speed, load and temperature (the
// lubricant's law multiplies them all, so at every temperature). "motor_side" scales b, F_c
// and F_s only. The brake is not friction of the joint and never scales. Effect: dissipated
// friction power against the healthy friction law on the same motion and temperature.
#include <cmath>

#include "core/base/suggest.h"
#include "core/plant/drive/friction.h"
#include "core/plant/parts/gear_thermal.h"
#include "core/plant/parts/load_friction.h"
#include "faults/family_support.h"  // the shared pieces; registry.cc lists this family

namespace armfault {

namespace {

enum class FrictionTerms { kAll, kMotorSide };

class FrictionIncrease : public Fault {
 public:
  FrictionIncrease(const FaultCommon& c, double factor, FrictionTerms terms)
      : Fault("friction_increase", c.joint_index, c.timing), factor_(factor), terms_(terms) {}
  void Apply(double severity, double, HardwareCondition* c) const override {
    const double scale = 1.0 + severity * (factor_ - 1.0);
    c->friction_factor *= scale;
    if (terms_ == FrictionTerms::kAll) c->gear_friction_factor *= scale;
  }
  nlohmann::json Parameters() const override {
    return {{"friction_factor", factor_}, {"friction_terms", terms_ == FrictionTerms::kAll ? "all" : "motor_side"}};
  }
  std::unique_ptr<EffectMeter> MakeEffectMeter(const JointModel& joint) const override {
    const FrictionParams friction = joint.params.friction;
    const GearboxParams gearbox = joint.params.gearbox;
    const double ratio = joint.ratio;
    const double mesh = joint.params.drive.mesh_loss_fraction;
    return MakeRatioMeter("friction_power_vs_healthy_model", timing().onset_s, 1.0, 0.05,
                          [=](const JointTick& j) {
                            // The healthy law at the tick's speed, torque and gear temperature
                            // (simulation.cc DriveJoint without the brake and the one-step lag).
                            const double speed = std::fabs(j.qd_rad_s);
                            double viscous = 1, dry = 1, load_Nm = 0;
                            if (gearbox.present) {
                              viscous = LubricantFactor(gearbox, j.gear_temp_C);
                              dry = std::pow(viscous, gearbox.coulomb_exponent);
                              load_Nm = LoadFrictionNm(gearbox, j.tau_true_Nm, j.qd_rad_s, ratio);
                            }
                            const double motor_Nm = std::fabs(ViscousFrictionNm(friction, viscous, j.qd_rad_s)) +
                                                    BreakawayFrictionNm(friction, dry, j.qd_rad_s);
                            const double gear_Nm = mesh * std::fabs(j.tau_true_Nm) / ratio + load_Nm;
                            return RatioTerms{speed > 0.02, j.p_friction_W, ratio * speed * (motor_Nm + gear_Nm)};
                          });
  }

 private:
  double factor_;
  FrictionTerms terms_;
};

}  // namespace

std::unique_ptr<Fault> MakeFrictionIncrease(ObjectReader& reader, const RobotConfig& robot,
                                            const FaultMagnitudeSpec& magnitude) {
  ErrorList errors;  // the common keys and this family's, each on its own
  const FaultCommon common = ReadFaultCommon(reader, robot, {"friction_factor", "friction_terms"}, &errors);
  double f = 1.0;
  errors.Try([&] {
    ReadMagnitude(reader, magnitude, &f);
  });
  FrictionTerms terms = FrictionTerms::kAll;
  errors.Try([&] {
    if (!reader.Has("friction_terms")) return;
    const std::string name = reader.RequireString("friction_terms");
    if (name == "all") terms = FrictionTerms::kAll;
    else if (name == "motor_side") terms = FrictionTerms::kMotorSide;
    else {
      const std::string near = NearestWord(name, {"all", "motor_side"});
      throw InputError("", reader.PointerTo("friction_terms"),
                       "unknown friction_terms " + nlohmann::json(name).dump() + " (known: all, motor_side)",
                       near.empty() ? "" : "did you mean \"" + near + "\"?");
    }
  });
  errors.ThrowIfAny();
  return std::make_unique<FrictionIncrease>(common, f, terms);
}

}  // namespace armfault
