// The arm on ODE (or the joint-space engine: RobotConfig::engine) with its joint modules and
// controllers in the loop.
//
// Model versus data: ArmModel is built once from a RobotConfig, immutable, and shared
// read-only between threads; RunState holds everything one run changes (its own ODE world).
//   RunState state(model, spec);
//   while (!Finished(model, state)) Advance(model, &state, observer);
// or simply Simulate(model, spec, observer).
//
// Timing: the controllers tick at the controller rate (500 Hz); between ticks the world is
// stepped with dWorldStep at the physics rate (1 kHz) and each drive's electrical model with
// `electrical_substeps` sub-steps per physics step. Each tick emits one Tick record.
//
// Engines: the mechanics below are ODE's (core/plant/ode_world.h), the reference; with
// RobotConfig::engine articulated the same bodies, gears, friction and brake rows and the same
// torque sensor are stepped in joint coordinates instead (core/plant/engine/articulated_world.h).
// Both sit behind ArmWorld (core/plant/engine/arm_world.h); the drive network, sensors,
// controllers and the friction bound (with its one-step lag) are shared.
//
// Drivetrain of joint i (rigid, thesis eq 3-7): the link is hinged to its parent (link i-1,
// or the world for joint 1). The rotor is its own ODE body of inertia I_m, geared so that it
// spins at gamma q_dot_i relative to the parent, i.e. its kinetic energy is
//   1/2 I_m (z_i . omega_parent + gamma q_dot_i)^2   (+ 1/2 I_m |omega_parent,transverse|^2),
// which gives the single joint its I_m gamma^2 and a lower joint j the coupling
// I_m gamma (z_i . z_j) q_ddot_j of eq 3-7 / 4-14 (not I_m gamma^2). In ODE the gear is a
// transmission joint in planetary form: the rotor body (isotropic I_m, a 1 g token mass) is
// hinged to the link on an axis parallel to z_i at `kRotorOffset_m` from it, and meshes with
// a sun wheel on the parent centred on the joint axis with radii 1 : gamma-1 (a planet on a
// fixed sun turns 1 + (gamma-1) = gamma times as fast as its carrier, in the same sense).
// Joint 1's sun is a kinematic ground body. Torques (motor side, about z_i):
//   - motor torque K_T-based tau_m on the rotor, reaction on the parent (stator);
//   - viscous motor friction b(q_dot) on the rotor shaft, reaction on the parent;
//   - with a "ripple" group: the gear's kinematic-error torque and the motor's cogging, functions
//     of the rotor angle (core/plant/parts/torque_ripple.h), on the rotor, reaction on the parent;
//   - one bounded velocity row (an AMotor, rotor relative to parent, target 0) with limit
//     Coulomb/Stribeck + brake + mesh loss mu |tau_link| / gamma: exact stiction. With a drive's
//     gearbox group (core/plant/parts/gear_thermal.h) the friction follows the gearbox node's
//     temperature and the row adds the direction-dependent load friction (load_friction.h);
//     both take the previous physics step's tau_link and q_dot (no iteration). The brake
//     and the mesh are before the torque sensor, so all dry friction sits on the rotor shaft.
// tau_link (JointTick::tau_true_Nm, the torque sensor's truth) is the moment about the joint
// axis of the rotor hinge's force on the link: what the harmonic drive passes on.
#pragma once

#include <Eigen/Dense>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/plant/engine/articulated_world.h"
#include "core/plant/motion/controller.h"
#include "core/plant/parts/hardware_condition.h"
#include "core/plant/drive/motor.h"
#include "core/plant/robot/rigid_body_dynamics.h"
#include "core/plant/robot/robot_config.h"
#include "core/plant/motion/trajectory.h"
#include "core/signals/joint_signals.h"

namespace armfault {

// Immutable description of one joint with its link, derived from the config.
struct JointModel {
  ModuleParams params;
  DriveConstants drive;
  ControllerConstants controller;
  double ratio = 0;                 // gamma: rotor turns gamma q_dot relative to the parent
  double rotor_inertia_kg_m2 = 0;   // I_m of the rotor body (isotropic, see RotorBody below)
  Eigen::Vector3d axis;        // unit joint axis, world frame at the zero pose
  Eigen::Vector3d anchor_m;    // joint position, world frame at the zero pose
  Eigen::Vector3d rotor_centre_m;  // rotor body's spin axis passes here (zero pose, world)
  double mass_kg = 0;          // link (+ payload on the last link)
  Eigen::Vector3d com_m;       // centre of mass at the zero pose
  Eigen::Matrix3d inertia_kg_m2;  // about the centre of mass, zero-pose world axes, excl. rotor
};

class ArmModel {
 public:
  // Validates the config (throws InputError) and derives all constants; with the articulated
  // engine, also that the robot is a chain it takes (1 to 7 revolute joints).
  explicit ArmModel(RobotConfig config);

  const RobotConfig& config() const { return config_; }
  int joint_count() const { return static_cast<int>(joints_.size()); }
  const JointModel& joint(int j) const { return joints_[j]; }
  double physics_dt_s() const { return physics_dt_s_; }
  double control_dt_s() const { return physics_dt_s_ * steps_per_tick_; }
  int steps_per_tick() const { return steps_per_tick_; }
  // The same bodies outside ODE (core/plant/robot/rigid_body_dynamics.h), payload included.
  const RigidBodyModel& rigid_bodies() const { return rigid_; }
  // The engine the runs step with (the config's); the joint-space model when it is the
  // articulated one (null for ODE).
  PhysicsEngine engine() const { return config_.engine; }
  const ArticulatedModel* articulated() const { return articulated_.get(); }

 private:
  RobotConfig config_;
  RigidBodyModel rigid_;
  std::shared_ptr<const ArticulatedModel> articulated_;
  std::vector<JointModel> joints_;
  double physics_dt_s_ = 0;
  int steps_per_tick_ = 1;
};

// Changes the hardware condition of the joints over time (fault injection). Called before
// every physics step; must be deterministic and thread-safe (const).
class HardwareSchedule {
 public:
  virtual ~HardwareSchedule() = default;
  virtual void Apply(double t_s, std::vector<HardwareCondition>* conditions) const = 0;
};

struct JointRunOptions {
  std::shared_ptr<const Trajectory> trajectory;  // null: hold the initial angle under control
  bool has_initial_angle = false;                // else q_ref(0), or 0 without a trajectory
  double initial_angle_rad = 0;
  double initial_velocity_rad_s = 0;
  bool powered = true;           // unpowered: driver off, brake engaged (unless released below)
  bool brake_held_released = false;  // keep the brake released even when unpowered
};

// How a run's thermal nodes start: at ambient ("cold", today's), or at the steady state of
// each drive's stated duty ("warm": GearboxParams warm_*_loss_W, core/plant/parts/gear_thermal.h;
// a drive without a gearbox group starts at ambient either way).
enum class ThermalStart { kCold, kWarm };

struct RunSpec {
  double duration_s = 10.0;
  uint64_t seed = 1;
  double ambient_C = 20.0;  // the windings start here and cool towards it
  ThermalStart start = ThermalStart::kCold;
  std::vector<JointRunOptions> joints;  // one per joint, or empty for all defaults
  std::shared_ptr<const HardwareSchedule> hardware;  // null: healthy
  // Optional: asked after every tick's observer; true ends the run at that tick (a search for
  // a conditional onset stops there, faults/fault.h ResolveConditionalOnsets).
  std::function<bool()> stop;
};

// One joint at one controller tick: the sensor signals its controller (and a monitor) may use,
// and beside them the simulator's truth. Powers are means over the control period that ends
// at this tick (0 at t = 0).
struct JointTick {
  JointSignals signals;  // reference and sensors, what a monitor sees (core/signals/joint_signals.h)
  // truth
  double winding_temp_C = 20;   // winding temperature (signals.winding_temp_C: the sensor's, if declared)
  double gear_temp_C = 0;       // gearbox node (core/plant/parts/gear_thermal.h); NaN without a gearbox group
  double q_rad = 0, qd_rad_s = 0;
  double tau_true_Nm = 0;       // torque the harmonic drive passes to the link (sensor truth)
  double i_phase_a_A = 0;
  double i_supply_A = 0;        // mean over the period (signals.i_supply_meas_A is the sensor's)
  double peak_phase_current_A = 0;
  bool brake_engaged = false;
  bool driver_enabled = true;
  bool limit_stop = false;
  double p_supply_W = 0, p_copper_W = 0, p_inverter_W = 0, p_quiescent_W = 0;
  double p_friction_W = 0;      // motor friction + harmonic-drive mesh loss + brake, dissipated
                                // (torque x rotor speed relative to the stator)
  double p_mech_out_W = 0;      // tau_true x qd: power delivered to the link
  double p_emf_W = 0;           // electromagnetic power converted to rotor power (work on the rotor)
  double p_magnetic_W = 0;
  double p_ripple_W = 0;        // work of the torque ripple on the rotor (0 without "ripple"): stored, not lost
  // plant-level truth for checking that a fault took effect (means over the period)
  double torque_motor_Nm = 0;   // electromagnetic torque on the rotor
  double current_sq_A2 = 0;     // i_a^2 + i_b^2 + i_c^2
  double brake_torque_Nm = 0;   // |torque| the brake exerts, link side
};

struct Tick {
  double t_s = 0;
  const std::vector<JointTick>* joints = nullptr;
};
using TickObserver = std::function<void(const Tick&)>;

struct JointEnergy {
  double supply_J = 0, copper_J = 0, inverter_J = 0, quiescent_J = 0, friction_J = 0;
  double mech_out_J = 0, emf_J = 0, magnetic_J = 0;
  double ripple_J = 0;  // work of the torque ripple on the rotors: its potential's drop (core/plant/parts/torque_ripple.h)
};

struct RunResult {
  bool ok = true;
  std::string failure_reason;  // set when !ok: what diverged, where and when
  double end_time_s = 0;
  std::vector<JointEnergy> energy;
  double kinetic_start_J = 0, kinetic_end_J = 0;  // links and rotor bodies
  double potential_start_J = 0, potential_end_J = 0;
};

// Runs one simulation; calls `observer` (may be empty) at every controller tick.
// A run that diverges returns ok = false with the reason; it never throws for that.
// Throws InputError if the spec does not fit the model (joint count, initial angle range).
RunResult Simulate(const ArmModel& model, const RunSpec& spec, const TickObserver& observer);

// Bare ODE stepping of the same bodies and joints (links, rotors, hinges, transmissions) with
// no drives, sensors or controllers: the reference cost for benchmarks. With `friction_rows`,
// each rotor also carries the bounded velocity row the simulation uses for dry friction (at
// the breakaway torque), so the LCP is the same size as in a full run. Returns a checksum of
// the final state.
double StepBareOde(const ArmModel& model, double duration_s, bool friction_rows);
// The same in the articulated engine (core/plant/engine/articulated_world.h), with its friction
// rows at the breakaway torque, whichever engine `model` names.
double StepBareArticulated(const ArmModel& model, double duration_s);

// Where ODE puts each link body at the joint angles `q` (at rest): its centre of mass and its
// rotation from the zero pose, world frame. For cross-checks of a robot's kinematics against an
// independent chain of transforms (tests/core/plant/robot/urdf_robot_test.cc).
struct BodyPose {
  Eigen::Vector3d com_m;
  Eigen::Matrix3d rotation;
};
std::vector<BodyPose> OdeBodyPoses(const ArmModel& model, const std::vector<double>& q);

}  // namespace armfault
