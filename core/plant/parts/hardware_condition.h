// The condition of one joint module's hardware during a run: what fault families act on.
// A healthy module has the default values. Faults (faults/) change these fields over time;
// the plant reads them every physics step; the controller and the monitor never see them.
#pragma once

namespace armfault {

enum class SensorLead { kHealthy, kSupply, kGround, kOpen };
enum class ShortKind { kNone, kPhasePhase, kPhaseGround, kSwitch };

struct HardwareCondition {
  double kt_factor = 1.0;            // magnet flux / winding: K_T and back-EMF scale together
  double friction_factor = 1.0;      // scales b, F_c, F_s of the motor-side friction
  double gear_friction_factor = 1.0; // scales the harmonic drive's mesh loss and load-dependent friction
  double resistance_factor = 1.0;    // winding resistance (overheating)
  double brake_drag_Nm = 0.0;        // brake torque on the motor shaft while released [N m]
  SensorLead torque_sensor_lead = SensorLead::kHealthy;
  double torque_sensor_drift_Nm = 0.0;  // additive drift of the torque-sensor reading [N m]
  ShortKind short_kind = ShortKind::kNone;
  double short_resistance_ohm = 0.0;    // fault resistance while short_kind != kNone
};

}  // namespace armfault
