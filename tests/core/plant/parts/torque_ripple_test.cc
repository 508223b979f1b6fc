// Position-dependent torque ripple (core/plant/parts/torque_ripple.h): the band limit, conservation,
// the spectrum of the transmitted torque at constant speed (the lines where they belong, no
// aliased cogging line, and a check that would flag one), the energy balances with ripple on,
// and that a robot without the "ripple" group runs exactly as before.
#include "core/plant/parts/torque_ripple.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <memory>

#include "core/plant/simulation.h"
#include "core/run_config.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using testing_support::Recording;

TEST(RippleBandGainTest, PassesBelowAFifthOfTheRateAndStopsAboveTwoFifths) {
  EXPECT_EQ(RippleBandGain(0, 1000), 1.0);
  EXPECT_EQ(RippleBandGain(200, 1000), 1.0);
  EXPECT_NEAR(RippleBandGain(300, 1000), 0.5, 1e-12);
  EXPECT_EQ(RippleBandGain(400, 1000), 0.0);
  EXPECT_EQ(RippleBandGain(499, 1000), 0.0);
  EXPECT_NEAR(RippleBandGain(1200, 4000), 0.5, 1e-12);  // the fractions scale with the rate
  double last = 1.0;
  for (double f = 0; f < 500; f += 1) {
    const double g = RippleBandGain(f, 1000);
    EXPECT_LE(g, last) << f;  // smooth and monotonic: no line grows with speed in the roll-off
    last = g;
  }
}

// tau = -dV/dtheta, and the work over a revolution is zero: the ripple makes no energy.
TEST(RippleTorqueTest, IsTheSlopeOfAPeriodicPotential) {
  RippleParams p;
  p.enabled = true;
  p.phase_2x_deg = 30;
  p.phase_1x_deg = -70;
  p.cogging_phase_deg = 10;
  const double gamma = 101;
  const double h = 1e-6;
  double work = 0, gross = 0;
  const int n = 100000;
  for (int k = 0; k < n; ++k) {
    const double theta = 2 * M_PI * (k + 0.5) / n;
    const double tau = RippleTorqueNm(p, gamma, theta, 0, 1000);
    const double slope = (RipplePotentialJ(p, gamma, theta + h) - RipplePotentialJ(p, gamma, theta - h)) / (2 * h);
    EXPECT_NEAR(tau, -slope, 1e-6) << theta;
    work += tau * 2 * M_PI / n;
    gross += std::fabs(tau) * 2 * M_PI / n;
  }
  EXPECT_GT(gross, 0.05);
  EXPECT_NEAR(work, 0, 1e-9 * gross);
  // The lines as documented: 2x of 0.3 arcmin through 13 000 N m/rad is 1.13 N m at the link.
  const double arcmin = M_PI / 180 / 60;
  RippleParams only_2x = p;
  only_2x.kinematic_error_1x_arcmin = 0;
  only_2x.cogging_Nm = 0;
  only_2x.phase_2x_deg = 0;
  EXPECT_NEAR(RippleTorqueNm(only_2x, gamma, M_PI / 4, 0, 1000) * gamma, 13000 * 0.3 * arcmin, 1e-12);
  EXPECT_NEAR(RippleTorqueNm(only_2x, gamma, M_PI / 4, 0, 1000) * gamma, 1.1345, 1e-4);
  // A line in the stop band is gone, unless the band limit is off (tests only).
  RippleParams cog = p;
  cog.kinematic_error_2x_arcmin = cog.kinematic_error_1x_arcmin = 0;
  const double fast = 2 * M_PI * 30;  // 30 rev/s: cogging at 540 Hz
  EXPECT_EQ(RippleTorqueNm(cog, gamma, 0.3, fast, 1000), 0.0);
  cog.band_limited = false;
  EXPECT_NE(RippleTorqueNm(cog, gamma, 0.3, fast, 1000), 0.0);
}

// A link turning at a constant speed after a smooth start (smoothstep velocity over ramp_s).
class ConstantSpeed : public Trajectory {
 public:
  ConstantSpeed(double q0_rad, double speed_rad_s, double ramp_s) : q0_(q0_rad), v_(speed_rad_s), ramp_(ramp_s) {}
  TrajectoryPoint At(double t) const override {
    TrajectoryPoint p;
    if (t < ramp_) {
      const double x = t / ramp_;
      p.q_rad = q0_ + v_ * ramp_ * (x * x * x - 0.5 * x * x * x * x);
      p.qd_rad_s = v_ * (3 * x * x - 2 * x * x * x);
      p.qdd_rad_s2 = v_ / ramp_ * (6 * x - 6 * x * x);
    } else {
      p.q_rad = q0_ + v_ * ramp_ / 2 + v_ * (t - ramp_);
      p.qd_rad_s = v_;
    }
    return p;
  }
  const char* type() const override { return "constant_speed"; }

 private:
  double q0_, v_, ramp_;
};

// The bench of the spectrum test: one MRR2 joint without gravity, a 5 kg tool on a 0.5 m rod
// (link inertia 1.33 kg m^2 against the rotor's I_m gamma^2 = 0.353), its controller at the
// physics rate (1 kHz) so that every physics step is a tick.
enum class Ripple { kOff, kBandLimited, kUnlimited };

RobotConfig SpectrumBench(Ripple ripple) {
  RobotConfig r = RobotPreset("pendulum");
  r.gravity_m_s2 = 0;
  r.payload_kg = 5;
  ModuleParams& m = r.modules[0];
  m.min_angle_deg = -360;
  m.max_angle_deg = 360;
  m.controller.rate_Hz = 1000;
  m.ripple.enabled = ripple != Ripple::kOff;  // the default lines: 2x 0.3', 1x 0.1', K 13 000 N m/rad, cogging 0.01 N m x 18
  m.ripple.phase_2x_deg = 20;
  m.ripple.phase_1x_deg = 50;
  m.ripple.cogging_phase_deg = 80;
  m.ripple.band_limited = ripple != Ripple::kUnlimited;
  return r;
}

double LinkInertia(const RobotConfig& r) {
  const LinkParams& l = r.links[0];
  const double d = l.com_fraction * l.length_m;
  return l.mass_kg * (3 * l.radius_m * l.radius_m + l.length_m * l.length_m) / 12 + l.mass_kg * d * d +
         r.payload_kg * l.length_m * l.length_m;
}

struct SpectrumRun {
  std::vector<double> tau_Nm;  // true transmitted torque, every physics step of the steady part
  double dt_s = 0;
  double rotor_speed_rad_s = 0;  // measured mean over the steady part
  RobotConfig robot;
};

SpectrumRun RunAtConstantSpeed(double link_speed_rad_s, Ripple ripple) {
  SpectrumRun out;
  out.robot = SpectrumBench(ripple);
  const ArmModel model(out.robot);
  RunSpec spec;
  const double ramp_s = 0.5, settle_s = 0.5, steady_s = 4.096;
  spec.duration_s = ramp_s + settle_s + steady_s;
  JointRunOptions joint;
  joint.trajectory = std::make_shared<ConstantSpeed>(-340 * M_PI / 180, link_speed_rad_s, ramp_s);
  spec.joints = {joint};
  Recording rec;
  const RunResult result = Simulate(model, spec, rec.Observer());
  EXPECT_TRUE(result.ok) << result.failure_reason;
  out.dt_s = model.control_dt_s();
  EXPECT_EQ(out.dt_s, model.physics_dt_s());
  double speed = 0;
  for (size_t k = 0; k < rec.t.size(); ++k) {
    if (rec.t[k] < ramp_s + settle_s) continue;
    out.tau_Nm.push_back(rec.ticks[k][0].tau_true_Nm);
    speed += rec.ticks[k][0].qd_rad_s;
  }
  out.rotor_speed_rad_s = out.robot.modules[0].drive.ratio * speed / out.tau_Nm.size();
  return out;
}

// Amplitude [N m] of the line at f_Hz: a Hann-windowed DFT at that one frequency (the mean
// removed), scaled so that a sinusoid of amplitude A reads A.
double LineAmplitude(const std::vector<double>& x, double dt_s, double f_Hz) {
  double mean = 0;
  for (double v : x) mean += v;
  mean /= x.size();
  std::complex<double> sum = 0;
  double wsum = 0;
  const size_t n = x.size();
  for (size_t k = 0; k < n; ++k) {
    const double w = 0.5 - 0.5 * std::cos(2 * M_PI * k / (n - 1));
    sum += w * (x[k] - mean) * std::polar(1.0, -2 * M_PI * f_Hz * k * dt_s);
    wsum += w;
  }
  return 2 * std::abs(sum) / wsum;
}

// The frequency a line at f_Hz shows at when sampled at fs_Hz.
double AliasOf(double f_Hz, double fs_Hz) {
  const double folded = std::fmod(f_Hz, fs_Hz);
  return folded > fs_Hz / 2 ? fs_Hz - folded : folded;
}

// The alias check's floor at `alias_Hz`: what the plant without ripple shows there at the same
// speed (the six-step motor's own torque ripple puts 0.02 to 0.3 N m of lines between 300 and
// 500 Hz at this speed; the largest within +-1 Hz), plus 2 % of the cogging line's link-side
// amplitude gamma C as the transmitted torque would carry it (the tool's share of the inertia):
// the ripple may add no more than that where a line above the Nyquist frequency would fold to.
double AliasFloorNm(const SpectrumRun& without_ripple, const RobotConfig& r, double alias_Hz) {
  const double gamma = r.modules[0].drive.ratio;
  const double rotor = r.modules[0].motor.rotor_inertia_kg_m2 * gamma * gamma;
  const double share = LinkInertia(r) / (LinkInertia(r) + rotor);
  double background = 0;
  for (double df = -1; df <= 1; df += 0.125) {
    background = std::max(background, LineAmplitude(without_ripple.tau_Nm, without_ripple.dt_s, alias_Hz + df));
  }
  return background + 0.02 * gamma * r.modules[0].ripple.cogging_Nm * share;
}

// Slow: every line lies in the pass band (cogging at 18 x 6.4 = 116 Hz): the 1x, 2x and cogging
// lines are in the transmitted torque, each near its rigid prediction (the link's share of the
// ripple torque: the rest accelerates the rotor; the controller, a 70 rad/s loop, takes some of
// the slow lines away).
TEST(RippleSpectrumTest, ResolvedLinesAppearAtTheirFrequencies) {
  const SpectrumRun run = RunAtConstantSpeed(0.4, Ripple::kBandLimited);
  const RobotConfig& r = run.robot;
  const RippleParams& p = r.modules[0].ripple;
  const double gamma = r.modules[0].drive.ratio;
  const double rotor = r.modules[0].motor.rotor_inertia_kg_m2 * gamma * gamma;
  const double share = LinkInertia(r) / (LinkInertia(r) + rotor);
  const double arcmin = M_PI / 180 / 60;
  ASSERT_NEAR(run.rotor_speed_rad_s, 0.4 * gamma, 0.01 * 0.4 * gamma);
  const RippleLines f = RippleLineFrequencies(p, run.rotor_speed_rad_s);
  const double a2 = LineAmplitude(run.tau_Nm, run.dt_s, f.twice_Hz);
  const double a1 = LineAmplitude(run.tau_Nm, run.dt_s, f.once_Hz);
  const double ac = LineAmplitude(run.tau_Nm, run.dt_s, f.cogging_Hz);
  const double pred2 = share * p.drive_stiffness_Nm_per_rad * p.kinematic_error_2x_arcmin * arcmin;
  const double pred1 = share * p.drive_stiffness_Nm_per_rad * p.kinematic_error_1x_arcmin * arcmin;
  const double predc = share * gamma * p.cogging_Nm;
  // Between the lines (and their intermodulation products, all multiples of the 1x frequency).
  double between = 0;
  for (double k : {4.5, 7.5, 10.5}) between = std::max(between, LineAmplitude(run.tau_Nm, run.dt_s, k * f.once_Hz));
  RecordProperty("line_2x_Hz", std::to_string(f.twice_Hz));
  RecordProperty("line_2x_Nm", std::to_string(a2) + " predicted " + std::to_string(pred2));
  RecordProperty("line_1x_Nm", std::to_string(a1) + " predicted " + std::to_string(pred1));
  RecordProperty("line_cogging_Nm", std::to_string(ac) + " predicted " + std::to_string(predc));
  RecordProperty("between_lines_Nm", std::to_string(between));
  // The slow lines sit near the position loop's bandwidth, whose sensitivity peak amplifies
  // them (about 2x at 13 Hz); the cogging line is far above it and matches the rigid share.
  EXPECT_GT(a2 / pred2, 0.5) << a2 << " N m at " << f.twice_Hz << " Hz";
  EXPECT_LT(a2 / pred2, 3.0) << a2 << " N m at " << f.twice_Hz << " Hz";
  EXPECT_GT(a1 / pred1, 0.3) << a1 << " N m at " << f.once_Hz << " Hz";
  EXPECT_LT(a1 / pred1, 3.0) << a1 << " N m at " << f.once_Hz << " Hz";
  EXPECT_NEAR(ac / predc, 1.0, 0.2) << ac << " N m at " << f.cogging_Hz << " Hz";
  EXPECT_LT(between, 0.02 * pred2);
}

// Fast: cogging at 18 x 32 = 579 Hz, above the 500 Hz Nyquist frequency of the 1 kHz step: with
// the band limit nothing shows where it would fold to (421 Hz), while the 2x line (64 Hz) is
// there; without it (band_limited = false) the same check flags the aliased line.
TEST(RippleSpectrumTest, UnresolvedCoggingLeavesNoAliasAndTheCheckCatchesOne) {
  const double fs = 1000, speed = 2.0;
  const SpectrumRun off = RunAtConstantSpeed(speed, Ripple::kOff);
  for (Ripple ripple : {Ripple::kBandLimited, Ripple::kUnlimited}) {
    const SpectrumRun run = RunAtConstantSpeed(speed, ripple);
    const RippleLines f = RippleLineFrequencies(run.robot.modules[0].ripple, run.rotor_speed_rad_s);
    ASSERT_GT(f.cogging_Hz, fs / 2);
    const double alias_Hz = AliasOf(f.cogging_Hz, fs);
    const double at_alias = LineAmplitude(run.tau_Nm, run.dt_s, alias_Hz);
    const double a2 = LineAmplitude(run.tau_Nm, run.dt_s, f.twice_Hz);
    const double floor = AliasFloorNm(off, run.robot, alias_Hz);
    const std::string tag = ripple == Ripple::kBandLimited ? "band_limited" : "unlimited";
    RecordProperty(tag + "_alias_Hz", std::to_string(alias_Hz));
    RecordProperty(tag + "_at_alias_Nm", std::to_string(at_alias) + " floor " + std::to_string(floor));
    RecordProperty(tag + "_line_2x_Nm", std::to_string(a2) + " without ripple " +
                                            std::to_string(LineAmplitude(off.tau_Nm, off.dt_s, f.twice_Hz)));
    EXPECT_GT(a2, 0.3) << tag;  // the resolved 2x line is there in both
    EXPECT_LT(LineAmplitude(off.tau_Nm, off.dt_s, f.twice_Hz), 0.03);  // and not without ripple
    if (ripple == Ripple::kBandLimited) {
      EXPECT_LT(at_alias, floor) << at_alias << " N m at " << alias_Hz << " Hz";
    } else {
      EXPECT_GT(at_alias, 5 * floor) << "the check must flag an unbandlimited cogging line";
    }
  }
}

// Ripple on every joint of experiment 1 (mrr-config1): the mechanical energy still closes, the
// ripple's net work is its potential's change (tiny) although it moved energy back and forth.
TEST(RippleEnergyTest, Experiment1ClosesWithRippleOn) {
  RunConfig run = ThesisExperiment1();
  for (ModuleParams& m : run.robot.modules) m.ripple.enabled = true;
  const ArmModel model(run.robot);
  Recording rec;
  const RunResult r = Simulate(model, MakeRunSpec(run), rec.Observer());
  ASSERT_TRUE(r.ok) << r.failure_reason;
  double supply = 0, losses = 0, emf = 0, friction = 0, ripple = 0, moved = 0, ripple_gross = 0;
  for (const JointEnergy& e : r.energy) {
    supply += e.supply_J;
    losses += e.copper_J + e.inverter_J + e.quiescent_J + e.friction_J + e.magnetic_J;
    emf += e.emf_J;
    friction += e.friction_J;
    ripple += e.ripple_J;
  }
  const double tc = rec.t[1] - rec.t[0];
  for (const auto& tick : rec.ticks) {
    for (const JointTick& j : tick) {
      moved += std::fabs(j.p_emf_W) * tc;
      ripple_gross += std::fabs(j.p_ripple_W) * tc;
    }
  }
  // The ripple's potential can change by at most its range over the run: 2 sum |a| / n per joint.
  double bound = 0;
  for (const ModuleParams& m : run.robot.modules) {
    const double k = m.ripple.drive_stiffness_Nm_per_rad / m.drive.ratio * M_PI / 180 / 60;
    bound += 2 * (k * m.ripple.kinematic_error_2x_arcmin / 2 + k * m.ripple.kinematic_error_1x_arcmin +
                  m.ripple.cogging_Nm / m.ripple.cogging_periods_per_rev);
  }
  const double stored = (r.kinetic_end_J - r.kinetic_start_J) + (r.potential_end_J - r.potential_start_J);
  RecordProperty("ripple_net_J", std::to_string(ripple));
  RecordProperty("ripple_gross_J", std::to_string(ripple_gross));
  RecordProperty("mechanical_residual_J", std::to_string(emf + ripple - stored - friction));
  EXPECT_GT(moved, 10.0);
  EXPECT_NEAR(supply, stored + losses - ripple, 0.01 * supply);
  EXPECT_NEAR(emf + ripple, stored + friction, 0.01 * moved);
  EXPECT_LT(std::fabs(ripple), 1.05 * bound) << "the ripple made energy";
  EXPECT_GT(ripple_gross, 10 * std::fabs(ripple)) << "the ripple did no work at all";
}

// The same on the six-joint UR-class arm (tests/core/plant/robot/urdf_robot_test.cc's motion).
TEST(RippleEnergyTest, SixJointArmClosesWithRippleOn) {
  RunConfig run = RunConfigFromJson(testing_support::UrClassSweepRun(8), "", InputContext{});
  for (ModuleParams& m : run.robot.modules) m.ripple.enabled = true;
  const ArmModel model(run.robot);
  Recording rec;
  const RunResult r = Simulate(model, MakeRunSpec(run), rec.Observer());
  ASSERT_TRUE(r.ok) << r.failure_reason;
  double emf = 0, friction = 0, ripple = 0, moved = 0, ripple_gross = 0;
  for (const JointEnergy& e : r.energy) {
    emf += e.emf_J;
    friction += e.friction_J;
    ripple += e.ripple_J;
  }
  for (const auto& tick : rec.ticks) {
    for (const JointTick& j : tick) {
      moved += std::fabs(j.p_emf_W) * model.control_dt_s();
      ripple_gross += std::fabs(j.p_ripple_W) * model.control_dt_s();
    }
  }
  const double stored = (r.kinetic_end_J - r.kinetic_start_J) + (r.potential_end_J - r.potential_start_J);
  RecordProperty("ripple_net_J", std::to_string(ripple));
  RecordProperty("ripple_gross_J", std::to_string(ripple_gross));
  EXPECT_GT(moved, 50.0);
  EXPECT_NEAR(emf + ripple, stored + friction, 0.01 * moved);
  EXPECT_LT(std::fabs(ripple), 0.05 * ripple_gross);
}

// Absent = off: the plant as before, bit for bit; an enabled group of zero lines changes nothing.
TEST(RippleOffTest, ZeroRippleRunsBitForBitAsWithout) {
  RunConfig run = ThesisExperiment1();
  run.duration_s = 2;
  auto energies = [&](const RobotConfig& robot) {
    const ArmModel model(robot);
    return Simulate(model, MakeRunSpec(run), nullptr);
  };
  const RunResult off = energies(run.robot);
  RobotConfig zero = run.robot;
  for (ModuleParams& m : zero.modules) {
    m.ripple.enabled = true;
    m.ripple.kinematic_error_2x_arcmin = m.ripple.kinematic_error_1x_arcmin = m.ripple.cogging_Nm = 0;
  }
  const RunResult z = energies(zero);
  RobotConfig on = run.robot;
  for (ModuleParams& m : on.modules) m.ripple.enabled = true;
  const RunResult o = energies(on);
  for (size_t j = 0; j < off.energy.size(); ++j) {
    EXPECT_EQ(off.energy[j].supply_J, z.energy[j].supply_J);
    EXPECT_EQ(off.energy[j].mech_out_J, z.energy[j].mech_out_J);
    EXPECT_EQ(off.energy[j].ripple_J, 0.0);
    EXPECT_NE(off.energy[j].mech_out_J, o.energy[j].mech_out_J);  // and on does change the run
  }
}

}  // namespace
}  // namespace armfault
