// inverter_short: a short in the driver, of resistance_ohm: between phases a and b at the
// motor terminals (phase_phase), phase a to ground (phase_ground), or phase a's high-side
// switch shorted (switch). The over-current it causes trips the driver's protection, which
// opens all switches for the rest of the run; the short itself stays (core/plant/drive/motor.h).
// Effect: peak phase current after onset against before, and the protection tripping.
#include <algorithm>

#include "faults/family_support.h"  // the shared pieces; registry.cc lists this family

namespace armfault {

namespace {

class InverterShort : public Fault {
 public:
  InverterShort(const FaultCommon& c, ShortKind kind, std::string name, double ohm)
      : Fault("inverter_short", c.joint_index, c.timing), kind_(kind), name_(std::move(name)), ohm_(ohm) {}
  void Apply(double severity, double, HardwareCondition* c) const override {
    if (severity < 0.5) return;
    c->short_kind = kind_;
    c->short_resistance_ohm = ohm_;
  }
  nlohmann::json Parameters() const override { return {{"kind", name_}, {"resistance_ohm", ohm_}}; }
  std::unique_ptr<EffectMeter> MakeEffectMeter(const JointModel&) const override {
    return std::make_unique<Meter>(timing().onset_s);
  }

 private:
  class Meter : public EffectMeter {
   public:
    explicit Meter(double onset) : onset_(onset) {}
    void Observe(double t, const JointTick& j) override {
      if (t < onset_) {
        before_ = std::max(before_, j.peak_phase_current_A);
      } else {
        after_ = std::max(after_, j.peak_phase_current_A);
        tripped_ = tripped_ || !j.driver_enabled;
      }
    }
    FaultEffect Result() const override {
      FaultEffect e;
      e.measure = "peak_phase_current_A";
      e.healthy = before_;
      e.faulty = after_;
      e.took_effect = tripped_ || after_ > 1.5 * std::max(before_, 1.0);
      if (!e.took_effect) e.note = "no over-current and the protection did not trip";
      return e;
    }

   private:
    double onset_;
    double before_ = 0, after_ = 0;
    bool tripped_ = false;
  };

  ShortKind kind_;
  std::string name_;
  double ohm_;
};

}  // namespace

std::unique_ptr<Fault> MakeInverterShort(ObjectReader& reader, const RobotConfig& robot,
                                         const FaultMagnitudeSpec& magnitude) {
  ErrorList errors;  // the common keys and this family's, each on its own
  const FaultCommon common = ReadFaultCommon(reader, robot, {"kind", "resistance_ohm"}, &errors);
  std::string kind;
  ShortKind value = ShortKind::kPhasePhase;
  errors.Try([&] {
    if (!reader.ShouldRead("kind")) return;
    kind = reader.RequireString("kind");
    if (kind == "phase_phase") value = ShortKind::kPhasePhase;
    else if (kind == "phase_ground") value = ShortKind::kPhaseGround;
    else if (kind == "switch") value = ShortKind::kSwitch;
    else throw InputError("", reader.PointerTo("kind"), "unknown kind \"" + kind + "\" (known: phase_phase, phase_ground, switch)");
  });
  double ohm = 0.1;
  errors.Try([&] {
    ReadMagnitude(reader, magnitude, &ohm, /*required=*/false);
  });
  errors.ThrowIfAny();
  return std::make_unique<InverterShort>(common, value, kind, ohm);
}

}  // namespace armfault
