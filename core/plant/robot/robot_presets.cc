// The robot presets and the drive catalogue: the built-in robots ("mrr-config1", "pendulum",
// "ur-class") and the module defaults of each drive type. Parsing, validation and output of a
// robot: robot_config.cc.
#include <string>
#include <vector>

#include "core/base/json_input.h"
#include "core/plant/robot/robot_config.h"
#include "core/plant/robot/robot_config_internal.h"
#include "core/plant/robot/ur_class_urdf.h"
#include "core/plant/robot/urdf_robot.h"

namespace armfault {

namespace {

std::string Known(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

RobotConfig MrrConfig1() {
  RobotConfig r;
  r.name = "mrr-config1";
  r.modules = {ModuleDefaults("MRR1", ""), ModuleDefaults("MRR2", ""), ModuleDefaults("MRR2", "")};
  // Base module: vertical axis; upper modules: horizontal axes; at the zero pose link 2 stands
  // upright and link 3 is horizontal, so the top joint lifts its link and tool against
  // gravity as in the thesis experiments.
  LinkParams l1;
  l1.mass_kg = 2.5;   // link + MRR2 module 2 mounted on it (assumption)
  l1.length_m = 0.20;
  l1.radius_m = 0.05;
  l1.direction = {0, 0, 1};
  l1.joint_axis = {0, 0, 1};
  LinkParams l2;
  l2.mass_kg = 1.8;   // link + MRR2 module 3 (assumption)
  l2.length_m = 0.30;
  l2.radius_m = 0.045;
  l2.direction = {0, 0, 1};  // upright: joint 2 carries the top link's moment, not its own
  l2.joint_axis = {0, -1, 0};  // positive angles lift the link
  LinkParams l3;
  l3.mass_kg = 1.0;   // end link with flange (assumption)
  l3.length_m = 0.25;
  l3.radius_m = 0.035;
  l3.direction = {1, 0, 0};
  l3.joint_axis = {0, -1, 0};
  r.links = {l1, l2, l3};
  r.base_position_m = {0, 0, 0.15};
  r.payload_kg = 2.0;  // tool at the flange: the top joint's load is mostly gravity (docs/assumptions.md)
  return r;
}

// One hanging link, motor disconnected by the caller: the analytic-pendulum check.
RobotConfig Pendulum() {
  RobotConfig r;
  r.name = "pendulum";
  r.modules = {ModuleDefaults("MRR2", "")};
  LinkParams l;
  l.mass_kg = 1.0;
  l.length_m = 0.5;
  l.radius_m = 0.02;
  l.direction = {0, 0, -1};
  l.joint_axis = {0, 1, 0};
  r.links = {l};
  r.base_position_m = {0, 0, 1.0};
  return r;
}

// Drives of a 48 V industrial arm (UR-class: wrist joints of 28 N m, shoulder and elbow of
// 150 N m). Strain-wave gears and frameless motors sized from public catalogues; the values,
// their sources and the gain rule: docs/assumptions.md, "Industrial drive types".
ModuleParams IndustrialDrive(const std::string& type) {
  ModuleParams m;
  const bool small = type == "industrial-small";
  m.type = type;
  m.min_angle_deg = -360;
  m.max_angle_deg = 360;
  MotorParams& mo = m.motor;
  mo.kt_Nm_per_A = small ? 0.044 : 0.10;
  mo.phase_resistance_ohm = small ? 0.5 : 0.15;
  mo.phase_inductance_H = small ? 0.3e-3 : 0.15e-3;
  mo.pole_pairs = small ? 5 : 7;
  // Motor rotor plus the wave generator (CSF-14: 0.033 kg cm^2; CSG-25: 0.282 kg cm^2).
  mo.rotor_inertia_kg_m2 = small ? 1.5e-5 : 1.1e-4;
  mo.thermal_resistance_K_per_W = small ? 4.0 : 1.5;
  mo.thermal_time_constant_s = small ? 600 : 1200;
  InverterParams& in = m.inverter;
  in.bus_voltage_V = 48.0;
  in.command_limit_A = small ? 10.0 : 16.0;
  in.current_per_volt_A_per_V = in.command_limit_A / 1.5;  // the DAC's +-1.5 V span the range
  in.switch_resistance_ohm = small ? 0.02 : 0.01;
  in.quiescent_power_W = small ? 2.0 : 3.0;
  in.overcurrent_trip_A = small ? 30.0 : 45.0;
  m.drive.ratio = small ? 100.0 : 120.0;
  m.drive.mesh_loss_fraction = 0.2;  // about 80 % efficiency at rated torque, 20 degC
  // Motor side, as functions of the link velocity: link-side Coulomb about 1.5 and 5 N m.
  m.friction = small ? FrictionParams{0.0008, 0.015, 0.017, 15.0} : FrictionParams{0.0042, 0.042, 0.046, 15.0};
  m.brake.holding_torque_Nm = small ? 0.6 : 2.5;  // above the motor's peak torque
  TorqueSensorParams& ts = m.torque_sensor;
  ts.full_scale_Nm = small ? 60.0 : 250.0;
  ts.offset_Nm = 0;
  ts.adc_bits = 14;
  ts.noise_Nm = small ? 0.05 : 0.15;
  m.encoder.counts_per_rev = 16384;
  ControllerParams& c = m.controller;
  // The gain rule (docs/assumptions.md): the controller's model is the datasheet's, its
  // robust gain the motor-side Coulomb friction; lambda and K_P as the thesis's.
  c.kt_hat_Nm_per_A = mo.kt_Nm_per_A;
  c.b_hat = m.friction.viscous_Nm_s_per_rad;
  c.fc_hat_Nm = m.friction.coulomb_Nm;
  c.fs_hat_Nm = m.friction.static_Nm;
  c.ft_hat = m.friction.stribeck_s2_per_rad2;
  c.im_hat_kg_m2 = mo.rotor_inertia_kg_m2;
  c.ku_robust_Nm = m.friction.coulomb_Nm;
  return m;
}

// The industrial drives with their "gearbox" group on: a gearbox node, the lubricant's Vogel
// law, direction-dependent load friction and sensor drift. Values and their sources:
// docs/assumptions.md, "Gearbox temperature, load and sensor drift".
ModuleParams IndustrialThermalDrive(const std::string& type) {
  const bool small = type == "industrial-small-thermal";
  ModuleParams m = IndustrialDrive(small ? "industrial-small" : "industrial-large");
  m.type = type;
  GearboxParams& g = m.gearbox;
  g.present = true;
  g.thermal_resistance_K_per_W = small ? 3.0 : 1.2;
  g.thermal_time_constant_s = small ? 1800 : 3000;
  g.winding_coupling_W_per_K = small ? 0.5 : 1.5;
  g.reference_C = 20;
  g.vogel_B_K = 277;
  g.vogel_C_C = -100;
  g.coulomb_exponent = 0.5;
  g.load_friction_driving = 0.05;
  g.load_friction_backdriven = 0.10;
  // 0.02 %FS/K zero drift, 0.01 %/K span drift of a temperature-compensated strain-gauge sensor.
  g.sensor_offset_Nm_per_K = 0.0002 * m.torque_sensor.full_scale_Nm;
  g.sensor_gain_per_K = 1e-4;
  g.warm_copper_loss_W = small ? 3.0 : 10.0;
  g.warm_friction_loss_W = small ? 4.0 : 15.0;
  return m;
}

// A six-joint UR5e-class arm from its URDF (campaigns/files/robots/ur-class.urdf, built in):
// shoulder and elbow joints on the large industrial drive, the wrists on the small one.
RobotConfig UrClass() {
  const nlohmann::json drives = {{"shoulder_pan", "industrial-large"}, {"shoulder_lift", "industrial-large"},
                                 {"elbow", "industrial-large"},        {"wrist_1", "industrial-small"},
                                 {"wrist_2", "industrial-small"},      {"wrist_3", "industrial-small"}};
  RobotConfig r = RobotFromUrdfText(kUrClassUrdf, "ur-class.urdf (built in)", drives, "/drives");
  r.name = "ur-class";
  r.payload_kg = 0.5;  // a light gripper at the flange
  return r;
}

struct Preset {
  const char* name;
  RobotConfig (*make)();
};
const std::vector<Preset>& Presets() {
  static const std::vector<Preset> presets = {{"mrr-config1", &MrrConfig1}, {"pendulum", &Pendulum}, {"ur-class", &UrClass}};
  return presets;
}

}  // namespace

bool TypeHasGearbox(const std::string& type) {
  return type == "industrial-small-thermal" || type == "industrial-large-thermal";
}

ModuleParams ModuleDefaults(const std::string& type, const std::string& pointer) {
  ModuleParams m;  // struct defaults are the MRR2 values
  if (type == "MRR2") return m;
  if (type == "MRR1") {
    // Moog BN-42-33EU-03 frameless motor (peak 8.82 N m, 697 W): parameters not printed in the
    // thesis are chosen for a 48 V-class winding of that size (docs/assumptions.md).
    m.type = "MRR1";
    m.min_angle_deg = -60;
    m.max_angle_deg = 60;
    m.motor.kt_Nm_per_A = 0.12;
    m.motor.phase_resistance_ohm = 0.15;
    m.motor.phase_inductance_H = 0.2e-3;
    m.motor.pole_pairs = 4;
    m.motor.thermal_resistance_K_per_W = 3.1;  // rated 42 W of copper loss heats it by 130 K
    m.motor.thermal_time_constant_s = 1200;
    m.motor.rotor_inertia_kg_m2 = 1.5e-4;
    m.inverter.command_limit_A = 6.0;
    m.friction = {0.0025, 0.05, 0.054, 15.0};
    m.brake.holding_torque_Nm = 10.0;  // above the motor's 8.82 N m peak
    m.encoder.counts_per_rev = 5000;
    m.controller.kt_hat_Nm_per_A = 0.12;
    m.controller.b_hat = 0.0055;
    m.controller.fc_hat_Nm = 0.05;
    m.controller.fs_hat_Nm = 0.054;
    m.controller.im_hat_kg_m2 = 1.5e-4;
    return m;
  }
  if (type == "industrial-small" || type == "industrial-large") return IndustrialDrive(type);
  if (type == "industrial-small-thermal" || type == "industrial-large-thermal") return IndustrialThermalDrive(type);
  throw InputError("", pointer, "unknown module type \"" + type + "\" (known: " + Known(ModuleTypeNames()) + ")");
}

std::vector<std::string> ModuleTypeNames() {
  return {"MRR1", "MRR2", "industrial-small", "industrial-large", "industrial-small-thermal", "industrial-large-thermal"};
}

std::vector<std::string> RobotPresetNames() {
  std::vector<std::string> names;
  for (const auto& p : Presets()) names.push_back(p.name);
  return names;
}

RobotConfig RobotPreset(const std::string& name, const std::string& pointer) {
  for (const auto& p : Presets()) {
    if (name == p.name) return p.make();
  }
  throw InputError("", pointer, "unknown robot preset \"" + name + "\" (known: " + Known(RobotPresetNames()) + ")");
}

}  // namespace armfault
