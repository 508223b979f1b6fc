// Robot description as plain data: joint modules (motor, inverter, harmonic drive, friction,
// brake, torque sensor, encoder, controller gains) and links. Parsed strictly from JSON,
// validated right after parsing, and shipped as presets ("mrr-config1").
//
// Conventions: SI units; "motor side" quantities act on the motor shaft, "link side" on the
// joint output; angles in JSON are degrees, inside the code radians. Geometry is given in
// the world frame at the zero pose (all joint angles 0), z up.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <string>
#include <vector>

#include "core/plant/parts/torque_ripple.h"  // RippleParams
#include "core/plant/parts/gear_thermal.h"

namespace armfault {

class ErrorList;

// Brushless DC motor, three phases in star, trapezoidal back-EMF (thesis eq 4-1 ... 4-3).
struct MotorParams {
  double kt_Nm_per_A = 0.165;           // torque constant = line back-EMF constant [V s/rad]
  double phase_resistance_ohm = 0.6;    // per phase (assumption, docs/assumptions.md)
  double phase_inductance_H = 0.4e-3;   // per phase (assumption)
  double pole_pairs = 3;                // (assumption)
  double rotor_inertia_kg_m2 = 3.46e-5; // thesis table 5-2
  // Winding temperature, first order (docs/assumptions.md): C dT/dt = P_copper - (T - T_amb)/R_th.
  // Resistance rises 0.393 %/K and K_T falls 0.1 %/K from the 20 °C values above.
  double thermal_resistance_K_per_W = 11.0;  // winding to ambient (assumption, docs/assumptions.md)
  double thermal_time_constant_s = 900;      // R_th C (assumption)
};

// Inverter (driver power stage) fed from the DC bus, with its current loop.
struct InverterParams {
  double bus_voltage_V = 70.0;             // thesis table 5-1
  double current_per_volt_A_per_V = 4.0;   // driver conversion factor, thesis table 5-1
  double command_limit_A = 6.0;            // DAC range 0..3 V around 1.5 V: +-1.5 V x 4 A/V
  double current_loop_bandwidth_Hz = 1500; // PI current loop crossover (assumption)
  double switch_resistance_ohm = 0.03;     // MOSFET on-resistance per switch (assumption)
  double switching_time_s = 100e-9;        // rise + fall time per transition (assumption)
  double pwm_frequency_Hz = 20000;         // (assumption)
  double diode_drop_V = 0.8;               // freewheeling diode forward drop (assumption)
  double quiescent_power_W = 2.0;          // driver logic, DSP, sensors (assumption)
  double overcurrent_trip_A = 20.0;        // over-current protection threshold (assumption)
  double supply_current_noise_A = 0.005;   // supply-current sensor noise, 1 sigma (assumption)
  // This unit's supply-current sensor errors (plant truth; the monitor is not told them):
  // reading = (1 + gain_error) I + offset_error + noise.
  double supply_current_gain_error = 0;
  double supply_current_offset_error_A = 0;
};

// Harmonic drive: rigid ratio plus a load-dependent mesh loss (torque-proportional friction
// of the wave generator and flexspline), which the controller's friction model does not know.
struct HarmonicDriveParams {
  double ratio = 101.0;               // thesis table 5-1
  double mesh_loss_fraction = 0.24;   // Coulomb-like loss = fraction x |transmitted torque| (assumption)
};

// Friction on the motor shaft, thesis eq 3-8, as a function of the link velocity q_dot
// (the thesis's DSP code evaluates it that way):
//   f = b q_dot + (F_c + F_s exp(-F_t q_dot^2)) sat(q_dot)   [N m, motor side]
struct FrictionParams {
  double viscous_Nm_s_per_rad = 0.00124;  // b, table 5-2
  double coulomb_Nm = 0.025;              // F_c, table 5-2
  double static_Nm = 0.027;               // F_s, table 5-2
  double stribeck_s2_per_rad2 = 15.0;     // F_t, table 5-2
};

// Power-off brake on the motor shaft: engaged when unpowered.
struct BrakeParams {
  double holding_torque_Nm = 2.0;  // motor side, above the motor's 1.6 N m peak (assumption)
};

// Strain-gauge joint torque sensor on the harmonic-drive output with amplifier and ADC.
// Reading chain: V = center_V + (tau - offset_Nm) * (adc_range_V/2) / full_scale_Nm + noise,
// clipped to [0, adc_range_V], quantised to adc_bits; mapped back with the thesis formula
// tau = full_scale_Nm (V - center_V) / (adc_range_V/2) + offset_Nm.
// Optional (`"torque_sensor": null`, as on UR-class arms): without one the reading is NaN, the
// controller's torque feedforward comes from the robot model (core/plant/motion/controller.h) and the
// families that need the sensor are errors on that joint.
struct TorqueSensorParams {
  bool present = true;
  double full_scale_Nm = 28.0;
  double offset_Nm = 3.5077;
  double adc_range_V = 3.0;
  double adc_bits = 12;
  double noise_Nm = 0.03;   // 1 sigma at the amplifier output, in N m (assumption)
  // This unit's gauge and amplifier errors (plant truth; the controller's mapping and the
  // monitor keep the nominal one): the amplifier sees (1 + gain_error) tau + offset_error_Nm.
  double gain_error = 0;
  double offset_error_Nm = 0;
};

// Incremental encoder on the motor shaft.
struct EncoderParams {
  double counts_per_rev = 2540;  // thesis DSP code: pi/1270 rad per count
};

// The thesis joint controller (appendix C), run at rate_Hz.
struct ControllerParams {
  double rate_Hz = 500;
  double lambda_per_s = 70;          // error-mixing gain
  double kp_adaptive = 1e-3;         // K_P of the parametric term
  double ku_robust_Nm = 0.025;       // K_u
  double epsilon_robust = 0.1;       // boundary layer of the robust term
  double kt_hat_Nm_per_A = 0.167;    // the controller's torque constant
  double b_hat = 0.002728;           // friction model in the controller (motor side, link velocity)
  double fc_hat_Nm = 0.02558;
  double fs_hat_Nm = 0.027;
  double ft_hat = 15.0;
  double im_hat_kg_m2 = 3.46e-5;
  double torque_filter_rad_s = 50;   // torque-sensor low-pass cut-off
  double velocity_window = 16;       // max samples of the adaptive backward difference
  double velocity_min_counts = 8;    // counts that end the adaptive window early
};

struct ModuleParams {
  std::string type = "MRR2";
  double min_angle_deg = -120.0;
  double max_angle_deg = 120.0;
  MotorParams motor;
  InverterParams inverter;
  HarmonicDriveParams drive;
  FrictionParams friction;
  BrakeParams brake;
  TorqueSensorParams torque_sensor;
  EncoderParams encoder;
  ControllerParams controller;
  bool winding_temperature_sensor = false;  // a sensor the monitor may read (JointSignals::winding_temp_C)
  RippleParams ripple;  // optional "ripple" group: gear kinematic error and cogging (core/plant/parts/torque_ripple.h)
  // Optional "gearbox" group (core/plant/parts/gear_thermal.h): the gearbox thermal node, friction
  // against lubricant temperature, load-dependent friction, torque sensor drift. Absent
  // (present = false): all of these off.
  GearboxParams gearbox;
};

// Link i follows joint i. It starts at the joint anchor and extends along `direction` by
// length_m; joint i+1 sits at its end. Mass properties: a solid cylinder of radius_m unless
// inertia_kg_m2 gives the principal moments about the centre of mass (about the link
// direction and two perpendicular axes).
struct LinkParams {
  double mass_kg = 1.0;
  double length_m = 0.2;
  double radius_m = 0.04;
  double com_fraction = 0.5;                  // centre of mass along the link, 0 = joint end
  std::array<double, 3> direction = {1, 0, 0};
  std::array<double, 3> joint_axis = {0, 1, 0};
  bool has_inertia = false;
  std::array<double, 3> inertia_kg_m2 = {0, 0, 0};  // (along, perp1, perp2)
};

// Joint i and the body it moves, as the plant builds them, in world coordinates at the zero
// pose (all joint angles 0): the general form of a robot (a URDF robot, core/plant/robot/urdf_robot.h,
// arrives in it; the `links` shorthand is turned into it by ArmModel). The body is every link
// joint i moves up to the next moving joint, fixed children merged in (payload excluded).
struct JointBody {
  std::string joint_name;                       // for messages ("joint_3" if none)
  std::array<double, 3> anchor_m = {0, 0, 0};   // a point on the joint axis
  std::array<double, 3> axis = {0, 0, 1};       // unit joint axis
  double mass_kg = 1.0;
  std::array<double, 3> com_m = {0, 0, 0};      // centre of mass
  // Inertia about the centre of mass, world axes: xx, yy, zz, xy, xz, yz [kg m^2].
  std::array<double, 6> inertia_kg_m2 = {1e-3, 1e-3, 1e-3, 0, 0, 0};
  // The frame of the link that follows the joint (URDF: the child link's frame) at the zero
  // pose: origin and row-major rotation. Not used by the plant (its bodies keep the world's
  // axes); written out (RobotToJson) so that a monitor or a tool can place the link.
  std::array<double, 3> frame_origin_m = {0, 0, 0};
  std::array<double, 9> frame_rotation = {1, 0, 0, 0, 1, 0, 0, 0, 1};
};

// The engine that steps the arm's mechanics (core/plant/engine/arm_world.h): ODE, the default and
// the reference (core/plant/ode_world.h), or the joint-space engine for serial chains of 1 to 7
// revolute joints (core/plant/engine/articulated_world.h). JSON: "engine": "ode" | "articulated".
enum class PhysicsEngine { kOde, kArticulated };
const char* EngineName(PhysicsEngine engine);
std::vector<std::string> EngineNames();
// The engine named by `value` (at `pointer`); anything else throws InputError naming the known
// engines, with the nearest as its did-you-mean.
PhysicsEngine EngineFromJson(const nlohmann::json& value, const std::string& pointer);
// The articulated engine's limit (kMaxEngineJoints, core/plant/engine/joint_space_dynamics.h).
constexpr int kMaxArticulatedJoints = 7;

struct RobotConfig {
  std::string name = "custom";
  PhysicsEngine engine = PhysicsEngine::kOde;
  std::vector<ModuleParams> modules;   // one per joint, base first
  std::vector<LinkParams> links;       // one per joint (the shorthand), or empty when `bodies` is given
  std::vector<JointBody> bodies;       // one per joint (the general form), or empty when `links` is given
  // Where the payload sits (world, zero pose) when the robot is given by `bodies`: the tool
  // frame's origin (core/plant/robot/urdf_robot.h); with `links`, the end of the last link.
  std::array<double, 3> payload_point_m = {0, 0, 0};
  std::array<double, 3> base_position_m = {0, 0, 0};
  double payload_kg = 0.0;             // point mass at the end of the last link
  double gravity_m_s2 = 9.81;
  double physics_rate_Hz = 1000;
  int electrical_substeps = 20;        // per physics step; 20 at 1 kHz = 50 us << L/R
  // ODE's constraint force mixing (dWorldSetCFM): the joints' and gears' regularisation. 1e-10 is
  // ODE's own default in double precision; the accelerations' error against exact rigid-body
  // dynamics is proportional to it (4e-5 of the largest on ur-class at 1e-10: docs/robot-format.md).
  double constraint_force_mixing = 1e-10;
};

// Tolerances a datasheet states for a unit (relative half-widths unless named otherwise): what
// a monitor may know without commissioning. Not the values a unit drew. A campaign states them
// ("tolerances"); a monitor widens its limits by them (WidenedForTolerances, the power monitor).
struct StatedTolerances {
  double kt = 0, winding_resistance = 0, switch_resistance = 0, switching_loss = 0, quiescent_power = 0;
  double mesh_loss = 0, rotor_inertia = 0, stribeck_velocity = 0, friction = 0;
  double torque_sensor_gain = 0, torque_sensor_offset_Nm = 0;
  double supply_current_gain = 0, supply_current_offset_A = 0, bus_voltage = 0;
  double ambient_max_C = 20;  // warmest ambient the robot is specified for (datasheet values at 20 °C)
  double ambient_min_C = 20;
};

// Module (drive) defaults by type: the drive catalogue ("MRR1", "MRR2" of the thesis;
// "industrial-small", "industrial-large"; "industrial-small-thermal", "industrial-large-thermal":
// the same with their "gearbox" group on, docs/assumptions.md); throws InputError for an unknown type.
ModuleParams ModuleDefaults(const std::string& type, const std::string& pointer);
std::vector<std::string> ModuleTypeNames();

// A drive (module) from JSON: {"type": ..., <group>: {overrides}}; errors go to `errors`, the
// type's defaults stand in for bad values. Throws only when `value` is not an object.
ModuleParams DriveFromJson(const nlohmann::json& value, const std::string& pointer, ErrorList* errors);

// Joint i's unit axis at the zero pose, world frame, whichever form the robot is given in.
std::array<double, 3> JointAxisOf(const RobotConfig& robot, int joint);

// Robot presets ("mrr-config1", "pendulum"). Throws InputError naming the known presets.
RobotConfig RobotPreset(const std::string& name, const std::string& pointer = "");
std::vector<std::string> RobotPresetNames();

// A robot from JSON: a preset name (string), or an object {"name", "modules", "links", ...};
// each module starts from its type's defaults and overrides the fields given.
// Unknown keys and out-of-range values throw InputError with their JSON pointer.
// A URDF robot ({"urdf": "arm.urdf", "drives": {...}, ...}, core/plant/robot/urdf_robot.h) reads its
// file relative to `base_dir` (the directory of the file that names it).
RobotConfig RobotFromJson(const nlohmann::json& value, const std::string& pointer, const std::string& base_dir = "");
nlohmann::json RobotToJson(const RobotConfig& robot);

// Throws InputError at `pointer` (where the engine is named) when `robot`'s engine cannot take
// it, saying why: the articulated engine takes serial chains of 1 to 7 revolute joints.
void CheckEngineTakes(const RobotConfig& robot, const std::string& pointer);

// Cross-field checks (counts match, directions non-zero, the engine takes the robot, ...); throws InputError.
void Validate(const RobotConfig& robot, const std::string& pointer);

}  // namespace armfault
