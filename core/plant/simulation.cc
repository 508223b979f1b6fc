#include "core/plant/simulation.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <sstream>

#include "core/plant/drive/brake.h"
#include "core/plant/drive/encoder.h"
#include "core/plant/drive/friction.h"
#include "core/plant/parts/gear_thermal.h"
#include "core/plant/parts/load_friction.h"
#include "core/plant/robot/mass_properties.h"
#include "core/base/json_input.h"
#include "core/plant/ode_runtime.h"
#include "core/plant/ode_world.h"
#include "core/plant/engine/articulated_world.h"
#include "core/base/rng.h"
#include "core/plant/robot/rigid_body_dynamics.h"
#include "core/plant/parts/torque_ripple.h"
#include "core/plant/drive/torque_sensor.h"

namespace armfault {

namespace {

constexpr double kMaxLinkSpeed_rad_s = 100.0;  // far beyond any drive: the run has diverged
// Copper resistance rises 0.393 %/K; an NdFeB magnet's flux (K_T) falls about 0.1 %/K.
constexpr double kCopperPerK = 0.00393;
constexpr double kMagnetLossPerK = 0.001;

// The run's mechanics in the model's engine.
std::unique_ptr<ArmWorld> NewWorld(const ArmModel& model, const std::vector<double>& q0, const std::vector<double>& qd0) {
  if (model.articulated()) return std::make_unique<ArticulatedWorld>(*model.articulated(), q0, qd0);
  return std::make_unique<OdeWorld>(model, q0, qd0);
}

// Per-joint data of one run.
struct JointRuntime {
  DriveState drive;
  ControllerState controller;
  Rng rng{0};
  double q_initial = 0;
  double q = 0, qd = 0;
  double rotor_rate = 0;       // rotor speed relative to the stator [rad/s], after the last step
  double tau_transmitted = 0;  // latest true transmitted torque (link side)
  double viscous_torque = 0;   // viscous friction torque of the current physics step (motor side)
  double ripple_torque = 0;    // gear kinematic error and cogging in the current step (motor side; 0 if off)
  double i_cmd = 0;
  double winding_temp_C = 20;
  double gear_temp_C = 20;     // gearbox node (only with the drive's gearbox group)
  double p_gear_heat_W = 0;    // friction power the gearbox node took in the last physics step
  int last_adc_code = 0;
  bool brake_engaged = false;
  bool driver_enabled = true;
  bool limit_stop = false;
  // sums over the current control period
  double sum_supply = 0, sum_copper = 0, sum_inverter = 0, sum_quiescent = 0, sum_friction = 0;
  double sum_mech = 0, sum_emf = 0, sum_magnetic = 0, peak_current = 0;
  double sum_torque = 0, sum_current_sq = 0, sum_brake = 0;
  double sum_ripple = 0;
  double brake_share = 0;  // brake's part of the dry-friction bound in the current step
  std::array<double, 3> phase_current{};
};

std::string FormatFailure(double t, int joint, const std::string& what, double value) {
  std::ostringstream s;
  s << "simulation diverged at t=" << t << " s: joint " << joint + 1 << " " << what << " " << value;
  return s.str();
}

// The joint's reference at `t`: its trajectory's, or holding the initial angle.
TrajectoryPoint ReferenceAt(const JointRunOptions& o, const JointRuntime& r, double t) {
  TrajectoryPoint ref;
  if (o.trajectory) ref = o.trajectory->At(t);
  else ref.q_rad = r.q_initial;
  return ref;
}

// The robot model's transmitted torque of every joint for every joint's reference at `t`: the
// feedforward of the joints without a torque sensor.
void ReferenceTorques(const ArmModel& model, const std::vector<JointRunOptions>& options,
                      const std::vector<JointRuntime>& rt, double t, std::vector<double>* tau_Nm) {
  const size_t n = options.size();
  thread_local std::vector<double> q, qd, qdd;
  q.resize(n), qd.resize(n), qdd.resize(n);
  for (size_t j = 0; j < n; ++j) {
    const TrajectoryPoint ref = ReferenceAt(options[j], rt[j], t);
    q[j] = ref.q_rad, qd[j] = ref.qd_rad_s, qdd[j] = ref.qdd_rad_s2;
  }
  TransmittedTorques(model.rigid_bodies(), q.data(), qd.data(), qdd.data(), tau_Nm->data());
}

// One joint at a controller tick: reads the sensors (the torque sensor as its lead condition
// allows), runs the controller, and writes the tick record: the signals beside the truth and
// the mean powers of the period just ended (`first_tick`: none yet). Draws the joint's noise
// in a fixed order.
// `model_torque_Nm`: the feedforward when the joint has no torque sensor (ReferenceTorques).
void ControllerTick(const JointModel& jm, const JointRunOptions& o, const HardwareCondition& cond, double t,
                    bool first_tick, int steps, double model_torque_Nm, JointRuntime* runtime, JointTick* tick_out) {
  JointRuntime& r = *runtime;
  JointTick& tick = *tick_out;
  const TrajectoryPoint ref = ReferenceAt(o, r, t);

  const TorqueSensorParams& ts = jm.params.torque_sensor;
  const double noise = r.rng.Normal();  // drawn every tick so streams stay aligned
  switch (cond.torque_sensor_lead) {
    case SensorLead::kHealthy:
      // The unit's gauge errors act on the torque; a drift fault adds to the reading. With a
      // gearbox group the gauge's thermal drift follows the gearbox node (gear_thermal.h).
      if (jm.params.gearbox.present) {
        r.last_adc_code = TorqueSensorAdcCode(
            ts, TorqueSensorVoltage(ts,
                                    DriftedSensorInputNm(jm.params.gearbox, r.gear_temp_C, ts.gain_error, ts.offset_error_Nm,
                                                         r.tau_transmitted) +
                                        cond.torque_sensor_drift_Nm,
                                    noise));
      } else {
        r.last_adc_code = TorqueSensorAdcCode(
            ts, TorqueSensorVoltage(ts, (1.0 + ts.gain_error) * r.tau_transmitted + ts.offset_error_Nm + cond.torque_sensor_drift_Nm,
                                    noise));
      }
      break;
    case SensorLead::kSupply:
    case SensorLead::kGround:
      r.last_adc_code = TorqueSensorAdcCode(ts, StuckLeadVoltage(ts, cond.torque_sensor_lead));
      break;
    case SensorLead::kOpen:
      break;  // the ADC input floats at its last held value
  }
  ControllerInputs ci;
  ci.encoder_count = EncoderCount(jm.params.encoder, jm.ratio * r.q);
  ci.torque_reading_Nm = ts.present ? TorqueFromAdcCode(ts, r.last_adc_code) : 0.0;
  ci.model_torque_Nm = model_torque_Nm;
  ci.reference = ref;
  ControllerOutputs co;
  if (r.driver_enabled) {
    StepController(jm.controller, ci, &r.controller, &co);
    r.i_cmd = co.current_command_A;
  } else {
    co.position_rad = ci.encoder_count * jm.controller.link_rad_per_count;
    r.i_cmd = 0;
  }

  const double inv = first_tick ? 0.0 : 1.0 / steps;
  const double supply_noise = r.rng.Normal();
  JointSignals& sig = tick.signals;
  sig.q_ref_rad = ref.q_rad;
  sig.qd_ref_rad_s = ref.qd_rad_s;
  sig.q_meas_rad = co.position_rad;
  sig.qd_est_rad_s = co.velocity_rad_s;
  sig.tau_sensor_Nm = ts.present ? ci.torque_reading_Nm : std::nan("");  // no sensor: NaN (joint_signals.h)
  sig.i_cmd_A = r.i_cmd;
  tick.q_rad = r.q;
  tick.qd_rad_s = r.qd;
  tick.tau_true_Nm = r.tau_transmitted;
  tick.i_phase_a_A = r.phase_current[0];
  sig.v_bus_meas_V = jm.params.inverter.bus_voltage_V;
  tick.p_supply_W = r.sum_supply * inv;
  tick.p_copper_W = r.sum_copper * inv;
  tick.p_inverter_W = r.sum_inverter * inv;
  tick.p_quiescent_W = r.sum_quiescent * inv;
  tick.p_friction_W = r.sum_friction * inv;
  tick.p_mech_out_W = r.sum_mech * inv;
  tick.p_emf_W = r.sum_emf * inv;
  tick.p_magnetic_W = r.sum_magnetic * inv;
  tick.p_ripple_W = r.sum_ripple * inv;
  tick.i_supply_A = tick.p_supply_W / jm.params.inverter.bus_voltage_V;
  const InverterParams& inv_p = jm.params.inverter;
  sig.i_supply_meas_A = (1.0 + inv_p.supply_current_gain_error) * tick.i_supply_A + inv_p.supply_current_offset_error_A +
                         inv_p.supply_current_noise_A * supply_noise;
  tick.winding_temp_C = r.winding_temp_C;
  tick.gear_temp_C = jm.params.gearbox.present ? r.gear_temp_C : std::nan("");
  sig.winding_temp_C = jm.params.winding_temperature_sensor ? r.winding_temp_C : std::nan("");
  tick.peak_phase_current_A = r.peak_current;
  tick.torque_motor_Nm = r.sum_torque * inv;
  tick.current_sq_A2 = r.sum_current_sq * inv;
  tick.brake_torque_Nm = r.sum_brake * inv;
  tick.brake_engaged = r.brake_engaged;
  tick.driver_enabled = r.driver_enabled && !r.drive.tripped;
  tick.limit_stop = r.limit_stop;
}

// Books the period's sums into the run's energies and starts the next period.
void BookPeriod(double dt, JointRuntime* runtime, JointEnergy* energy) {
  JointRuntime& r = *runtime;
  JointEnergy& e = *energy;
  e.supply_J += r.sum_supply * dt;
  e.copper_J += r.sum_copper * dt;
  e.inverter_J += r.sum_inverter * dt;
  e.quiescent_J += r.sum_quiescent * dt;
  e.friction_J += r.sum_friction * dt;
  e.mech_out_J += r.sum_mech * dt;
  e.emf_J += r.sum_emf * dt;
  e.magnetic_J += r.sum_magnetic * dt;
  e.ripple_J += r.sum_ripple * dt;
  r.sum_supply = r.sum_copper = r.sum_inverter = r.sum_quiescent = r.sum_friction = 0;
  r.sum_mech = r.sum_emf = r.sum_magnetic = r.peak_current = 0;
  r.sum_torque = r.sum_current_sq = r.sum_brake = r.sum_ripple = 0;
}

// Before a physics step: the drive's electrical sub-steps (the winding's temperature scaling
// R and K_T) and the winding's heating; the rotor's dry-friction bound and the motor torque less
// viscous friction as a couple on rotor and stator.
void DriveJoint(const JointModel& jm, const HardwareCondition& cond, int substeps, double dt, double ambient_C,
                ArmWorld* world, int j, JointRuntime* runtime) {
  JointRuntime& r = *runtime;
  DriveInputs di;
  di.current_command_A = r.i_cmd;
  di.enabled = r.driver_enabled;
  di.motor_angle_rad = jm.ratio * r.q;
  di.motor_speed_rad_s = r.rotor_rate;
  DriveOutputs dout;
  // The winding's temperature scales its resistance and the magnet's flux (K_T).
  HardwareCondition warm = cond;
  const double above_20 = r.winding_temp_C - 20.0;
  if (above_20 != 0.0) {
    warm.resistance_factor *= 1.0 + kCopperPerK * above_20;
    warm.kt_factor *= 1.0 - kMagnetLossPerK * above_20;
  }
  StepDrive(jm.drive, warm, di, substeps, &r.drive, &dout);
  const MotorParams& motor = jm.params.motor;
  const GearboxParams& gearbox = jm.params.gearbox;
  if (!gearbox.present) {
    r.winding_temp_C += dt / motor.thermal_time_constant_s *
                        (ambient_C + motor.thermal_resistance_K_per_W * dout.p_copper_W - r.winding_temp_C);
  } else {
    // Winding and gearbox nodes together; the gearbox takes the previous step's friction power.
    ThermalNodes nodes{r.winding_temp_C, r.gear_temp_C};
    StepThermalNodes(motor.thermal_resistance_K_per_W, motor.thermal_time_constant_s, gearbox, ambient_C, dout.p_copper_W,
                     r.p_gear_heat_W, dt, &nodes);
    r.winding_temp_C = nodes.winding_C;
    r.gear_temp_C = nodes.gear_C;
  }
  r.sum_supply += dout.p_supply_W;
  r.sum_copper += dout.p_copper_W;
  r.sum_inverter += dout.p_inverter_W;
  r.sum_quiescent += dout.p_quiescent_W;
  r.sum_emf += dout.p_emf_W;
  r.sum_magnetic += dout.p_magnetic_W;
  r.peak_current = std::max(r.peak_current, dout.peak_phase_current_A);
  r.sum_torque += dout.torque_Nm;
  r.sum_current_sq += dout.current_sq_A2;
  r.phase_current = dout.phase_current_A;

  // Motor-side dry friction (Coulomb + Stribeck, brake, and the mesh loss referred to the
  // rotor) as the rotor's bounded velocity row with target 0; motor torque less viscous
  // friction as a couple between rotor and stator. Wear (friction_increase) scales every
  // term but the brake: friction_factor the motor side's, gear_friction_factor the gear's.
  // With a gearbox group: friction against the gearbox node's temperature (the lubricant's
  // law) and the load-dependent, direction-dependent gear friction, both from the previous
  // step's state (load_friction.h).
  const FrictionParams& fp = jm.params.friction;
  const double brake = BrakeTorqueLimitNm(jm.params.brake, cond, r.brake_engaged);
  double viscous_factor = cond.friction_factor, dry_factor = cond.friction_factor, load_Nm = 0;
  if (gearbox.present) {
    const double f = LubricantFactor(gearbox, r.gear_temp_C);
    viscous_factor *= f;
    dry_factor *= std::pow(f, gearbox.coulomb_exponent);
    load_Nm = LoadFrictionNm(gearbox, r.tau_transmitted, r.qd, jm.ratio);
  }
  // Wear scales the gear's terms one by one (a factor 1 leaves the sum's rounding as it is).
  const double gear = cond.gear_friction_factor;
  const double dry = BreakawayFrictionNm(fp, dry_factor, r.qd) +
                     gear * (jm.params.drive.mesh_loss_fraction * std::fabs(r.tau_transmitted) / jm.ratio) +
                     gear * load_Nm + brake;
  r.brake_share = dry > 0 ? brake / dry : 0.0;
  r.viscous_torque = ViscousFrictionNm(fp, viscous_factor, r.qd);
  double couple_Nm = dout.torque_Nm - r.viscous_torque;
  if (jm.params.ripple.enabled) {
    // Position-dependent ripple (core/plant/parts/torque_ripple.h) at the step's mid-point angle.
    r.ripple_torque = RippleTorqueNm(jm.params.ripple, jm.ratio, jm.ratio * r.q + 0.5 * dt * r.rotor_rate, r.rotor_rate, 1.0 / dt);
    couple_Nm += r.ripple_torque;
  }
  world->SetJoint(j, couple_Nm, dry);
}

// After a physics step: the joint's angle, rate, rotor rate and transmitted torque from the
// world, the period's mechanical and friction powers, and the limit switch.
void ReadBackJoint(const JointModel& jm, const ArmWorld& world, int j, JointRuntime* runtime) {
  JointRuntime& r = *runtime;
  const JointReadout o = world.Joint(j);
  const double qd_new = o.qd_rad_s;
  r.q = o.q_rad;
  r.qd = qd_new;
  r.rotor_rate = o.rotor_rate_rad_s;
  r.tau_transmitted = o.tau_transmitted_Nm;
  const double dry_torque = o.dry_torque_Nm;
  r.sum_mech += r.tau_transmitted * qd_new;
  r.sum_friction += (r.viscous_torque - dry_torque) * r.rotor_rate;
  r.sum_ripple += r.ripple_torque * r.rotor_rate;
  // What heats the gearbox node in the next step: the joint's friction less the brake's share.
  if (jm.params.gearbox.present) {
    r.p_gear_heat_W = (r.viscous_torque - dry_torque * (1.0 - r.brake_share)) * r.rotor_rate;
  }
  // The dry elements share the constraint torque in proportion to their bounds (exact
  // while slipping, when each is at its bound); the brake is reported link side.
  r.sum_brake += jm.ratio * std::fabs(dry_torque) * r.brake_share;
  const ModuleParams& m = jm.params;
  if (!r.limit_stop && (r.q < m.min_angle_deg * M_PI / 180 || r.q > m.max_angle_deg * M_PI / 180)) {
    // Limit switch: the joint controller disables the drive and engages the brake.
    r.limit_stop = true;
    r.driver_enabled = false;
    r.brake_engaged = true;
  }
}

}  // namespace

ArmModel::ArmModel(RobotConfig config) : config_(std::move(config)) {
  Validate(config_, "");
  physics_dt_s_ = 1.0 / config_.physics_rate_Hz;
  const double rate = config_.modules[0].controller.rate_Hz;
  for (size_t i = 1; i < config_.modules.size(); ++i) {
    if (config_.modules[i].controller.rate_Hz != rate) {
      throw InputError("", "/modules/" + std::to_string(i) + "/controller/rate_Hz",
                       "all joint controllers must run at the same rate (" + FormatNumber(rate) + " Hz)");
    }
  }
  steps_per_tick_ = static_cast<int>(std::lround(config_.physics_rate_Hz / rate));
  const double substep = physics_dt_s_ / config_.electrical_substeps;

  rigid_ = MakeRigidBodyModel(config_, config_.payload_kg);
  const int n = static_cast<int>(config_.modules.size());
  if (config_.engine == PhysicsEngine::kArticulated) {  // Validate checked the chain (CheckEngineTakes)
    articulated_ = std::make_shared<const ArticulatedModel>(MakeArticulatedModel(rigid_, config_.constraint_force_mixing));
  }
  const bool general = !config_.bodies.empty();
  for (int i = 0; i < n; ++i) {
    const ModuleParams& m = config_.modules[i];
    const RigidJoint& rj = rigid_.joints[i];
    JointModel jm;
    jm.params = m;
    jm.drive = MakeDriveConstants(m, substep);
    jm.controller = MakeControllerConstants(m);
    jm.ratio = m.drive.ratio;
    jm.rotor_inertia_kg_m2 = m.motor.rotor_inertia_kg_m2;
    jm.axis = rj.axis;
    jm.rotor_centre_m = rj.rotor_centre_m;
    jm.anchor_m = rj.anchor_m;
    jm.mass_kg = rj.mass_kg;
    jm.com_m = rj.com_m;
    jm.inertia_kg_m2 = rj.inertia_kg_m2;
    // What ODE is given, checked once more on the built numbers (Validate checked the same
    // derivation): ODE asserts on a body that is not positive definite, aborting the process.
    const std::string problem = BodyMassProblem(jm.mass_kg, jm.inertia_kg_m2);
    if (!problem.empty()) {
      throw InputError("", general ? "/bodies/" + std::to_string(i) : "/links/" + std::to_string(i),
                       "link " + std::to_string(i + 1) + "'s body: " + problem);
    }
    const std::string rotor_problem =
        BodyMassProblem(kRotorMass_kg, jm.rotor_inertia_kg_m2 * Eigen::Matrix3d::Identity());
    if (!rotor_problem.empty()) {
      throw InputError("", "/modules/" + std::to_string(i) + "/motor/rotor_inertia_kg_m2", "the rotor body's " + rotor_problem);
    }
    joints_.push_back(jm);
  }
}

RunResult Simulate(const ArmModel& model, const RunSpec& spec, const TickObserver& observer) {
  const int n = model.joint_count();
  std::vector<JointRunOptions> options = spec.joints;
  if (options.empty()) options.resize(n);
  if (static_cast<int>(options.size()) != n) {
    throw InputError("", "", "the run specifies " + std::to_string(options.size()) + " joints, the robot has " +
                                 std::to_string(n));
  }
  std::vector<double> q0(n), qd0(n);
  std::vector<JointRuntime> rt(n);
  for (int j = 0; j < n; ++j) {
    const JointRunOptions& o = options[j];
    q0[j] = o.has_initial_angle ? o.initial_angle_rad : (o.trajectory ? o.trajectory->At(0).q_rad : 0.0);
    qd0[j] = o.initial_velocity_rad_s;
    rt[j].q_initial = rt[j].q = q0[j];
    rt[j].qd = qd0[j];
    rt[j].rotor_rate = model.joint(j).ratio * qd0[j];
    rt[j].rng = Rng(MixSeed(spec.seed, static_cast<uint64_t>(j)));
    rt[j].driver_enabled = o.powered;
    rt[j].winding_temp_C = spec.ambient_C;
    rt[j].gear_temp_C = spec.ambient_C;
    if (spec.start == ThermalStart::kWarm) {
      // The drive's stated duty's steady state (gear_thermal.h); a drive without a gearbox group
      // states none and starts at ambient.
      const ModuleParams& m = model.joint(j).params;
      const ThermalNodes warm = WarmSteadyState(m.motor.thermal_resistance_K_per_W, m.gearbox, spec.ambient_C);
      rt[j].winding_temp_C = warm.winding_C;
      rt[j].gear_temp_C = warm.gear_C;
    }
    rt[j].brake_engaged = !o.powered && !o.brake_held_released;
  }

  RunResult result;
  result.energy.resize(n);
  std::vector<HardwareCondition> conditions(n);
  std::vector<JointTick> ticks(n);
  const double dt = model.physics_dt_s();
  const double tc = model.control_dt_s();
  const int steps = model.steps_per_tick();
  const int substeps = model.config().electrical_substeps;
  const long total_ticks = std::lround(spec.duration_s / tc);
  const double ambient_C = spec.ambient_C;
  double t_ode = 0;  // the time ODE was last asked to reach (its failure's time)
  bool sensorless = false;  // some joint without a torque sensor: its controller needs the model's torque
  for (int j = 0; j < n; ++j) sensorless = sensorless || !model.joint(j).params.torque_sensor.present;
  std::vector<double> model_torque(n, 0.0);

  try {
    const std::unique_ptr<ArmWorld> world = NewWorld(model, q0, qd0);
    result.kinetic_start_J = world->KineticEnergy_J();
    result.potential_start_J = world->PotentialEnergy_J();

    for (long k = 0;; ++k) {
      const double t = k * tc;
      // --- controller tick: sensors -> controllers -> commands, and the tick record ---
      if (spec.hardware) spec.hardware->Apply(t, &conditions);  // a sensor fault acts from its onset tick
      if (sensorless) ReferenceTorques(model, options, rt, t, &model_torque);
      for (int j = 0; j < n; ++j) {
        ControllerTick(model.joint(j), options[j], conditions[j], t, k == 0, steps, model_torque[j], &rt[j], &ticks[j]);
        BookPeriod(dt, &rt[j], &result.energy[j]);
      }
      result.end_time_s = t;
      if (observer) observer(Tick{t, &ticks});
      for (int j = 0; j < n; ++j) {
        if (!std::isfinite(rt[j].q) || !std::isfinite(rt[j].qd) || std::fabs(rt[j].qd) > kMaxLinkSpeed_rad_s) {
          result.ok = false;
          result.failure_reason = FormatFailure(t, j, "velocity [rad/s]", rt[j].qd);
          return result;
        }
      }
      if (k >= total_ticks || (spec.stop && spec.stop())) break;

      // --- physics steps until the next tick ---
      for (int s = 0; s < steps; ++s) {
        const double ts = t + s * dt;
        t_ode = ts + dt;
        if (spec.hardware && s > 0) spec.hardware->Apply(ts, &conditions);  // s = 0: applied at the tick
        for (int j = 0; j < n; ++j) DriveJoint(model.joint(j), conditions[j], substeps, dt, ambient_C, world.get(), j, &rt[j]);
        world->Step(dt);
        for (int j = 0; j < n; ++j) ReadBackJoint(model.joint(j), *world, j, &rt[j]);
      }
    }
    result.kinetic_end_J = world->KineticEnergy_J();
    result.potential_end_J = world->PotentialEnergy_J();
  } catch (const OdeError& e) {
    // ODE's last resort (core/plant/ode_runtime.h): the world is destroyed by now; the thread's
    // ODE data is renewed so that its next run is as on a fresh thread. This run fails.
    RenewOdeThreadData();
    result.ok = false;
    std::ostringstream reason;
    reason << "ODE failed in the step to t=" << t_ode << " s: " << e.what();
    result.failure_reason = reason.str();
  }
  return result;
}

double StepBareOde(const ArmModel& model, double duration_s, bool friction_rows) {
  const int n = model.joint_count();
  OdeWorld ode(model, std::vector<double>(n, 0.0), std::vector<double>(n, 0.0));
  for (int j = 0; friction_rows && j < n; ++j) {
    const JointModel& jm = model.joint(j);
    dJointSetAMotorParam(ode.drag(j), dParamFMax, BreakawayFrictionNm(jm.params.friction, 1.0, 1.0));
  }
  const long steps = std::lround(duration_s / model.physics_dt_s());
  for (long s = 0; s < steps; ++s) dWorldStep(ode.world(), model.physics_dt_s());
  double checksum = 0;
  for (int j = 0; j < n; ++j) checksum += dJointGetHingeAngle(ode.joint(j));
  return checksum;
}

double StepBareArticulated(const ArmModel& model, double duration_s) {
  const int n = model.joint_count();
  const ArticulatedModel own = model.articulated() ? ArticulatedModel{} : MakeArticulatedModel(model.rigid_bodies(), model.config().constraint_force_mixing);
  ArticulatedWorld world(model.articulated() ? *model.articulated() : own, std::vector<double>(n, 0.0), std::vector<double>(n, 0.0));
  const long steps = std::lround(duration_s / model.physics_dt_s());
  for (long s = 0; s < steps; ++s) {
    for (int j = 0; j < n; ++j) world.SetJoint(j, 0.0, BreakawayFrictionNm(model.joint(j).params.friction, 1.0, 1.0));
    world.Step(model.physics_dt_s());
  }
  double checksum = 0;
  for (int j = 0; j < n; ++j) checksum += world.Joint(j).q_rad;
  return checksum;
}

std::vector<BodyPose> OdeBodyPoses(const ArmModel& model, const std::vector<double>& q) {
  const int n = model.joint_count();
  OdeWorld ode(model, q, std::vector<double>(n, 0.0));
  std::vector<BodyPose> poses(n);
  for (int j = 0; j < n; ++j) {
    const dReal* c = dBodyGetPosition(ode.body(j));
    poses[j].com_m = Eigen::Vector3d(c[0], c[1], c[2]);
    const dReal* R = dBodyGetRotation(ode.body(j));
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) poses[j].rotation(r, c) = R[4 * r + c];
    }
  }
  return poses;
}

}  // namespace armfault
