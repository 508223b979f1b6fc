// URDF robots: what is read from the file, the errors a bad file gives, and cross-checks that
// would catch a wrong robot: forward kinematics against the published Denavit-Hartenberg chain
// of the ur-class arm, ODE's accelerations from rest and its holding torques against an
// independent mass matrix and gravity vector computed here, and the URDF armfault writes for
// mrr-config1 giving the preset's results.
#include "core/plant/robot/urdf_robot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "core/base/json_input.h"
#include "core/plant/robot/mass_properties.h"
#include "core/plant/simulation.h"
#include "core/run_config.h"
#include "tests/core/plant/independent_model.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;
using testing::HasSubstr;
using testing_support::Accelerations;
using testing_support::Independent;
using testing_support::RigidModel;

const nlohmann::json kUrDrives = {{"shoulder_pan", "industrial-large"}, {"shoulder_lift", "industrial-large"},
                                  {"elbow", "industrial-large"},        {"wrist_1", "industrial-small"},
                                  {"wrist_2", "industrial-small"},      {"wrist_3", "industrial-small"}};

// A two-joint arm whose parts the error tests replace.
std::string TwoJoint(const std::string& joint2_type = "revolute", const std::string& extra = "",
                     const std::string& link2_inertial =
                         "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" "
                         "ixz=\"0\" iyz=\"0\"/></inertial>") {
  return R"(<?xml version="1.0"?>
<robot name="two">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0 0 0.1"/><mass value="2"/><inertia ixx="0.02" iyy="0.02" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2">)" + link2_inertial + R"(</link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="100" velocity="3"/></joint>
  <joint name="j2" type=")" + joint2_type + R"("><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="100" velocity="3"/></joint>
)" + extra + "</robot>\n";
}

const nlohmann::json kTwoDrives = {{"j1", "industrial-large"}, {"j2", "industrial-small"}};

std::string ErrorOf(const std::string& urdf, const nlohmann::json& drives = kTwoDrives) {
  try {
    RobotFromUrdfText(urdf, "arm.urdf", drives, "/robot/drives");
  } catch (const InputError& e) {
    std::string all;
    for (const InputError& one : e.errors()) all += one.what() + std::string("\n");
    return all;
  }
  return "";
}

TEST(UrdfRobotTest, ReadsTheUrClassArm) {
  const RobotConfig r = RobotPreset("ur-class");
  ASSERT_EQ(r.bodies.size(), 6u);
  EXPECT_TRUE(r.links.empty());
  const double masses[] = {3.761, 8.058, 2.846, 1.37, 1.3, 0.365};
  const char* names[] = {"shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"};
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(r.bodies[i].joint_name, names[i]);
    EXPECT_DOUBLE_EQ(r.bodies[i].mass_kg, masses[i]);
    EXPECT_DOUBLE_EQ(r.modules[i].min_angle_deg, -360);
    EXPECT_DOUBLE_EQ(r.modules[i].max_angle_deg, 360);
  }
  EXPECT_EQ(r.modules[0].type, "industrial-large");
  EXPECT_EQ(r.modules[5].type, "industrial-small");
  // Joint 1 vertical at the base, joint 2 horizontal 0.1625 m above it (UR5e d1).
  EXPECT_NEAR(std::fabs(r.bodies[0].axis[2]), 1.0, 1e-12);
  EXPECT_NEAR(r.bodies[1].anchor_m[2], 0.1625, 1e-12);
  EXPECT_NEAR(r.bodies[1].axis[2], 0.0, 1e-12);
}

TEST(UrdfRobotTest, MergesFixedChildrenAndReadsTheFullInertiaTensor) {
  // l2 carries a fixed child of 1 kg 0.2 m further out; l2's inertial is rotated 90 deg about x.
  const std::string extra = R"(<link name="tool"><inertial><origin xyz="0 0 0"/><mass value="1"/>
      <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <joint name="fix" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0 0 0.2"/></joint>)";
  const std::string inertial =
      "<inertial><origin xyz=\"0 0 0\" rpy=\"1.5707963267948966 0 0\"/><mass value=\"1\"/>"
      "<inertia ixx=\"0.01\" iyy=\"0.02\" izz=\"0.03\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
  const RobotConfig r = RobotFromUrdfText(TwoJoint("revolute", extra, inertial), "arm.urdf", kTwoDrives, "/drives");
  ASSERT_EQ(r.bodies.size(), 2u);
  const JointBody& b = r.bodies[1];
  EXPECT_DOUBLE_EQ(b.mass_kg, 2.0);
  EXPECT_NEAR(b.com_m[2], 0.4 + 0.1, 1e-12);  // halfway between l2 (z 0.4) and the tool (z 0.6)
  // Rx(90): the y and z moments swap; each body moved 0.1 m along z adds m d^2 about x and y.
  EXPECT_NEAR(b.inertia_kg_m2[0], 0.01 + 0.001 + 2 * 0.01, 1e-12);
  EXPECT_NEAR(b.inertia_kg_m2[1], 0.03 + 0.001 + 2 * 0.01, 1e-12);
  EXPECT_NEAR(b.inertia_kg_m2[2], 0.02 + 0.001, 1e-12);
  EXPECT_NEAR(r.payload_point_m[2], 0.6, 1e-12);  // the tool frame
  // The joint's range from its limits, in degrees.
  EXPECT_NEAR(r.modules[1].max_angle_deg, 1.5 * 180 / M_PI, 1e-9);
}

TEST(UrdfRobotTest, BadFilesAreErrorsNamingTheFileAndTheElement) {
  EXPECT_THAT(ErrorOf(TwoJoint("prismatic")), HasSubstr("arm.urdf: <joint name=\"j2\">: a prismatic joint: only revolute"));
  EXPECT_THAT(ErrorOf(TwoJoint("floating")), HasSubstr("arm.urdf: <joint name=\"j2\">: a floating joint"));
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", "", "")), HasSubstr("arm.urdf: <joint name=\"j2\">: it moves link(s) \"l2\" with no mass"));
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", "",
                               "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" iyy=\"-0.01\" izz=\"0.01\" "
                               "ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>")),
              HasSubstr("<joint name=\"j2\">: the body it moves (link(s) \"l2\"): its smallest principal moment of inertia"));
  const std::string branch = R"(<link name="l3"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <joint name="j3" type="revolute"><parent link="l1"/><child link="l3"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>)";
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", branch)), HasSubstr("arm.urdf: <robot>: a branching tree: joints"));
  EXPECT_THAT(ErrorOf("<robot name=\"x\"><link name=\"a\"/></robot>"), HasSubstr("no revolute or continuous joint"));
  EXPECT_THAT(ErrorOf("<robot name=\"x\"><link name="), HasSubstr("arm.urdf: <robot>: urdfdom cannot read it"));
  EXPECT_THAT(ErrorOf("not xml at all"), HasSubstr("arm.urdf: <robot>: urdfdom cannot read it"));
  std::string far = TwoJoint();
  far.replace(far.find("<origin xyz=\"0 0 0.3\""), std::string("<origin xyz=\"0 0 0.3\"").size(), "<origin xyz=\"0 0 1e300\"");
  EXPECT_THAT(ErrorOf(far), HasSubstr("<joint name=\"j2\">: the joint or its body's centre of mass lies more than 1000 m"));
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", "", "<inertial><mass value=\"5000\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\" "
                                               "ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>")),
              HasSubstr("<joint name=\"j2\">: the body it moves (link(s) \"l2\") weighs 5000 kg"));
  // The general form read from JSON keeps the same limits, naming the field.
  nlohmann::json general = RobotToJson(RobotPreset("ur-class"));
  general["bodies"][2]["com_m"][0] = 2e3;
  try {
    RobotFromJson(general, "/robot");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/robot/bodies/2/com_m/0: 2000 is outside [-1000, 1000]");
  }
}

TEST(UrdfRobotTest, ANumberThatIsNotOneNamesItsElementAttributeAndValue) {
  // urdfdom reads these as 0 without a word, which read as "no mass" or "moment 0".
  auto inertial = [](const std::string& mass, const std::string& ixx) {
    return "<inertial><mass value=\"" + mass + "\"/><inertia ixx=\"" + ixx +
           "\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
  };
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", "", inertial("1.0kg", "0.01"))),
              HasSubstr("arm.urdf: <link name=\"l2\"><inertial><mass>: value=\"1.0kg\": expected a finite number"));
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", "", inertial("nan", "0.01"))),
              HasSubstr("<link name=\"l2\"><inertial><mass>: value=\"nan\": expected a finite number"));
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", "", inertial("1", "abc"))),
              HasSubstr("<link name=\"l2\"><inertial><inertia>: ixx=\"abc\": expected a finite number"));
  std::string origin = TwoJoint();
  origin.replace(origin.find("<origin xyz=\"0 0 0.3\""), std::string("<origin xyz=\"0 0 0.3\"").size(), "<origin xyz=\"0 0\"");
  EXPECT_THAT(ErrorOf(origin), HasSubstr("arm.urdf: <joint name=\"j2\"><origin>: xyz=\"0 0\": expected 3 finite numbers"));
  // A long value is cut for the message.
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", "", inertial(std::string(100, 'x'), "0.01"))),
              HasSubstr("value=\"" + std::string(40, 'x') + "...\""));
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", "", inertial("1", " 0.01"))),  // urdfdom: 0
              HasSubstr("<inertia>: ixx=\" 0.01\": expected a finite number"));
  EXPECT_EQ(ErrorOf(TwoJoint("revolute", "", inertial("1e0", "0.01"))), "");
}

TEST(UrdfRobotTest, MimicJointsAndClosedChainsAreNamedAsSuch) {
  std::string mimic = TwoJoint();
  mimic.replace(mimic.find("<limit lower=\"-1.5\""), 0, "<mimic joint=\"j1\" multiplier=\"1\"/>");
  EXPECT_THAT(ErrorOf(mimic), HasSubstr("arm.urdf: <joint name=\"j2\">: it mimics joint \"j1\" (<mimic>)"));
  // Before: read as an independent driven joint.
  const std::string loop = R"(<joint name="j3" type="revolute"><parent link="base"/><child link="l2"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>)";
  EXPECT_THAT(ErrorOf(TwoJoint("revolute", loop)),
              HasSubstr("arm.urdf: <link name=\"l2\">: it is the child of joints \"j2\" and \"j3\": a closed chain"));
}

TEST(UrdfRobotTest, DrivesMustNameEveryMovingJointAndNoOther) {
  EXPECT_THAT(ErrorOf(TwoJoint(), {{"j1", "industrial-large"}}),
              HasSubstr("/robot/drives: no drive for joint \"j2\" of arm.urdf"));
  try {
    RobotFromUrdfText(TwoJoint(), "arm.urdf", {{"j1", "industrial-large"}, {"j2", "industrial-small"}, {"j_2", "MRR2"}},
                      "/robot/drives");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/robot/drives/j_2: \"j_2\" is not a moving joint of arm.urdf (its joints: j1, j2)"));
    EXPECT_EQ(e.hint(), "did you mean \"j2\"?");
  }
  EXPECT_THAT(ErrorOf(TwoJoint(), {{"j1", "industrial-large"}, {"j2", "industrial-huge"}}),
              HasSubstr("/robot/drives/j2/type: unknown module type \"industrial-huge\""));
  EXPECT_THAT(ErrorOf(TwoJoint(), {{"j1", "industrial-large"}, {"j2", {{"type", "MRR2"}, {"motor", {{"kt_Nm_per_A", -1}}}}}}),
              HasSubstr("/robot/drives/j2/motor/kt_Nm_per_A"));
}

TEST(UrdfRobotTest, TransmissionReductionIsCheckedAgainstTheDrive) {
  auto with = [](const std::string& reduction) {
    return TwoJoint("revolute", "<transmission name=\"t2\"><type>transmission_interface/SimpleTransmission</type>"
                                "<joint name=\"j2\"/><actuator name=\"m2\"><mechanicalReduction>" +
                                    reduction + "</mechanicalReduction></actuator></transmission>");
  };
  EXPECT_EQ(ErrorOf(with("100")), "");  // industrial-small: 100:1
  EXPECT_EQ(ErrorOf(with("1")), "");    // ROS's placeholder: not stated
  EXPECT_THAT(ErrorOf(with("50")), HasSubstr("arm.urdf: <transmission name=\"t2\">: joint \"j2\" has a mechanicalReduction of 50, "
                                             "the drive's ratio is 100"));
}

TEST(UrdfRobotTest, DynamicsGiveTheFrictionWhereTheDriveGivesNone) {
  const std::string urdf = TwoJoint();
  std::string with_dyn = urdf;
  with_dyn.replace(with_dyn.find("<limit lower=\"-1.5\""), 0, "<dynamics damping=\"2.0\" friction=\"3.0\"/>");
  const RobotConfig r = RobotFromUrdfText(with_dyn, "arm.urdf", kTwoDrives, "/drives");
  EXPECT_DOUBLE_EQ(r.modules[1].friction.viscous_Nm_s_per_rad, 2.0 / 100);
  EXPECT_DOUBLE_EQ(r.modules[1].friction.coulomb_Nm, 3.0 / 100);
  EXPECT_DOUBLE_EQ(r.modules[1].controller.fc_hat_Nm, 3.0 / 100);
  const nlohmann::json own = {{"j1", "industrial-large"},
                              {"j2", {{"type", "industrial-small"}, {"friction", {{"coulomb_Nm", 0.01}}}}}};
  const RobotConfig r2 = RobotFromUrdfText(with_dyn, "arm.urdf", own, "/drives");
  EXPECT_DOUBLE_EQ(r2.modules[1].friction.coulomb_Nm, 0.01);
  // Damping alone (as published files often give) leaves the drive's Coulomb friction.
  std::string damping_only = urdf;
  damping_only.replace(damping_only.find("<limit lower=\"-1.5\""), 0, "<dynamics damping=\"0.5\"/>");
  const RobotConfig r3 = RobotFromUrdfText(damping_only, "arm.urdf", kTwoDrives, "/drives");
  EXPECT_DOUBLE_EQ(r3.modules[1].friction.viscous_Nm_s_per_rad, 0.5 / 100);
  EXPECT_DOUBLE_EQ(r3.modules[1].friction.coulomb_Nm, ModuleDefaults("industrial-small", "").friction.coulomb_Nm);
}

TEST(UrdfRobotTest, RobotJsonReadsTheFileRelativeToItsDirectory) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "armfault_urdf_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "two.urdf") << TwoJoint();
  const nlohmann::json robot = {{"urdf", "two.urdf"}, {"drives", kTwoDrives}, {"payload_kg", 1.0},
                                {"base_position_m", {0, 0, 0.5}}};
  const RobotConfig r = RobotFromJson(robot, "/robot", dir.string());
  EXPECT_NEAR(r.bodies[0].anchor_m[2], 0.6, 1e-12);
  EXPECT_DOUBLE_EQ(r.payload_kg, 1.0);
  // Written out and read back (a campaign's resolved robot): the same bodies, no file needed.
  const RobotConfig back = RobotFromJson(RobotToJson(r), "/robot");
  EXPECT_EQ(RobotToJson(back), RobotToJson(r));
  try {
    RobotFromJson({{"urdf", "missing.urdf"}, {"drives", kTwoDrives}}, "/robot", dir.string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/robot/urdf: cannot read the URDF file \""));
  }
  std::filesystem::remove_all(dir);
}

// --- Cross-checks -----------------------------------------------------------------------

Matrix3d Rx(double a) { return Eigen::AngleAxisd(a, Vector3d::UnitX()).toRotationMatrix(); }
Matrix3d Rz(double a) { return Eigen::AngleAxisd(a, Vector3d::UnitZ()).toRotationMatrix(); }

// The UR5e's standard Denavit-Hartenberg chain and centres of mass, as Universal Robots
// publishes them (independent of the URDF and of its reader).
TEST(UrdfRobotTest, OdeBodiesFollowThePublishedDenavitHartenbergChain) {
  const double d[] = {0.1625, 0, 0, 0.1333, 0.0997, 0.0996};
  const double a[] = {0, -0.425, -0.3922, 0, 0, 0};
  const double alpha[] = {M_PI / 2, 0, 0, M_PI / 2, -M_PI / 2, 0};
  const double com[6][3] = {{0, -0.02561, 0.00193}, {0.2125, 0, 0.11336}, {0.15, 0, 0.0265},
                            {0, -0.0018, 0.01634},  {0, 0.0018, 0.01634}, {0, 0, -0.001159}};
  RobotConfig robot = RobotPreset("ur-class");
  robot.payload_kg = 0;  // the payload would move the last body's centre of mass
  const ArmModel model(robot);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> q(6);
    for (double& x : q) x = angle(rng);
    const std::vector<BodyPose> poses = OdeBodyPoses(model, q);
    Matrix3d R = Matrix3d::Identity();
    Vector3d p = Vector3d::Zero();
    for (int i = 0; i < 6; ++i) {
      // T_i = T_{i-1} Rz(q) Tz(d) Tx(a) Rx(alpha); the centre of mass is given in frame i.
      p = p + R * Rz(q[i]) * Vector3d(a[i], 0, d[i]);
      R = R * Rz(q[i]) * Rx(alpha[i]);
      const Vector3d c = p + R * Vector3d(com[i][0], com[i][1], com[i][2]);
      EXPECT_NEAR((poses[i].com_m - c).norm(), 0.0, 1e-9) << "trial " << trial << " body " << i + 1;
      // The ODE body's rotation from the zero pose is the DH frame's, relative to its zero pose.
    }
  }
}

// Every joint unpowered at `pose`, its brake held engaged or released.
std::vector<JointRunOptions> UnpoweredAt(const std::vector<double>& pose, bool brake_released) {
  std::vector<JointRunOptions> joints;
  for (double angle : pose) {
    JointRunOptions o;
    o.powered = false;
    o.brake_held_released = brake_released;
    o.has_initial_angle = true;
    o.initial_angle_rad = angle;
    joints.push_back(o);
  }
  return joints;
}

RobotConfig Frictionless(RobotConfig r) {
  for (ModuleParams& m : r.modules) {
    m.friction = {0, 0, 0, 0};
    m.drive.mesh_loss_fraction = 0;
  }
  r.physics_rate_Hz = 500;  // one physics step per tick: the first tick's velocity is qdd dt
  return r;
}

// ODE's first-step accelerations from rest, unpowered, brakes released, at `cfm`: the largest
// error against the independent mass matrix, relative to the largest acceleration, over 3 poses.
double FirstStepAccelerationError(double cfm) {
  RobotConfig config = Frictionless(RobotPreset("ur-class"));
  config.constraint_force_mixing = cfm;
  const ArmModel model(config);
  const std::vector<std::vector<double>> poses = {{0, 0, 0, 0, 0, 0}, {0.3, -1.0, 1.2, -0.7, 0.9, 0.2},
                                                  {-2.0, -2.2, 0.4, 1.5, -0.4, 2.5}};
  double worst = 0;
  for (const std::vector<double>& q : poses) {
    const RigidModel rigid = Independent(model, q);
    const VectorXd qdd = rigid.mass.ldlt().solve(rigid.gravity);
    RunSpec spec;
    spec.duration_s = model.control_dt_s();
    spec.joints = UnpoweredAt(q, /*brake_released=*/true);
    std::vector<double> qd;
    EXPECT_TRUE(Simulate(model, spec, [&](const Tick& tick) {
      if (tick.t_s > 0) {
        qd.clear();
        for (const JointTick& j : *tick.joints) qd.push_back(j.qd_rad_s);
      }
    }).ok);
    EXPECT_EQ(qd.size(), 6u);
    if (qd.size() != 6u) return 1.0;
    for (int j = 0; j < 6; ++j) {
      const double ode = qd[j] / model.physics_dt_s();
      worst = std::max(worst, std::fabs(ode - qdd[j]) / qdd.cwiseAbs().maxCoeff());
    }
  }
  return worst;
}

// The bodies, frames, rotors and gears ODE is given are exact: with constraint force mixing at
// 1e-13 the first step's accelerations agree within 1e-6 (measured 4.3e-8; 1e-10 at CFM 0).
// What remains at the shipped CFM (ODE's default 1e-10) is that regularisation alone: the error
// falls in proportion to it (measured 4.3e-5, 4.3e-6, 4.3e-7, 4.3e-8 at 1e-10 ... 1e-13).
TEST(UrdfRobotTest, OdeAccelerationsFromRestMatchAnIndependentMassMatrix) {
  EXPECT_LT(FirstStepAccelerationError(1e-13), 1e-6);
  const double shipped = FirstStepAccelerationError(RobotConfig{}.constraint_force_mixing);
  const double softer_by_100 = FirstStepAccelerationError(1e-12);
  EXPECT_LT(shipped, 1e-4);
  EXPECT_GT(shipped, 1e-6);  // fails if the residual were no longer ODE's (and the bound above could tighten)
  EXPECT_NEAR(shipped / softer_by_100, 100.0, 5.0);
}

TEST(UrdfRobotTest, BrakedArmHoldsTheIndependentGravityTorques) {
  const ArmModel model(RobotPreset("ur-class"));
  const std::vector<double> q = {0.3, -1.0, 1.2, -0.7, 0.9, 0.2};
  const RigidModel rigid = Independent(model, q);
  RunSpec spec;
  spec.duration_s = 0.1;
  spec.joints = UnpoweredAt(q, /*brake_released=*/false);  // driver off, brake engaged: a rigid, static arm
  std::vector<double> tau;
  ASSERT_TRUE(Simulate(model, spec, [&](const Tick& tick) {
    tau.clear();
    for (const JointTick& j : *tick.joints) tau.push_back(j.tau_true_Nm);
  }).ok);
  // The drive passes the link what holds it against gravity: tau = -gravity force. The rotor's
  // token mass hangs on the rotor hinge and moves the reading by at most m g e (5e-4 N m).
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(tau[j], -rigid.gravity[j], 1e-6 * std::fabs(rigid.gravity[j]) + kRotorMass_kg * 9.81 * 0.05 * 6)
        << "joint " << j + 1;
  }
}

// The six-joint arm on a motion of every joint (campaigns/files/ur-class.json's "sweep"): the
// energy balance closes as on mrr-config1 (core/plant/simulation_test.cc), and every joint
// tracks within 0.2 deg with the drive-only gain rule (docs/assumptions.md).
TEST(UrdfRobotTest, SixJointArmClosesItsEnergyBalanceAndTracks) {
  const nlohmann::json run_json = testing_support::UrClassSweepRun(8);
  const RunConfig run = RunConfigFromJson(run_json, "", InputContext{});
  const ArmModel model(run.robot);
  testing_support::Recording rec;
  const RunResult r = Simulate(model, MakeRunSpec(run), rec.Observer());
  ASSERT_TRUE(r.ok) << r.failure_reason;
  double supply = 0, losses = 0, emf = 0, friction = 0, moved = 0;
  for (const JointEnergy& e : r.energy) {
    supply += e.supply_J;
    losses += e.copper_J + e.inverter_J + e.quiescent_J + e.friction_J + e.magnetic_J;
    emf += e.emf_J;
    friction += e.friction_J;
  }
  const double stored = (r.kinetic_end_J - r.kinetic_start_J) + (r.potential_end_J - r.potential_start_J);
  std::vector<double> worst_deg(6, 0.0);
  for (const auto& tick : rec.ticks) {
    for (int j = 0; j < 6; ++j) {
      moved += std::fabs(tick[j].p_emf_W) * model.control_dt_s();
      worst_deg[j] = std::max(worst_deg[j], std::fabs(tick[j].q_rad - tick[j].signals.q_ref_rad) * 180 / M_PI);
    }
  }
  EXPECT_GT(moved, 50.0);
  EXPECT_NEAR(supply, stored + losses, 0.01 * supply);
  EXPECT_NEAR(emf, stored + friction, 0.01 * moved)
      << "emf " << emf << " J, stored " << stored << " J, friction " << friction << " J, moved " << moved << " J";
  for (int j = 0; j < 6; ++j) {
    RecordProperty("worst_tracking_deg_joint_" + std::to_string(j + 1), std::to_string(worst_deg[j]));
    EXPECT_LT(worst_deg[j], 0.2) << "joint " << j + 1;
  }
}

// Along a motion: the frictionless, unpowered arm falls from a pose for 0.3 s. The reference
// integrates the independent model (M(q) qdd = g(q) - C(q, qd) qd, the Coriolis and centrifugal
// terms from M's derivatives by central differences) with RK4 at 20 us. ODE's error is first
// order in its step: within 2 % of the motion at 1 kHz, falling in proportion to the step.
// Measured: 0.23 % at 1 kHz, 0.14 % at 2 kHz, 0.064 % at 5 kHz, 0.034 % at 10 kHz.
VectorXd ReferenceFall(const ArmModel& model, const VectorXd& q0, double duration_s) {
  const double dt = 2e-5;  // RK4: its error (dt^4) is far below ODE's at 10 kHz
  VectorXd q = q0, qd = VectorXd::Zero(q0.size());
  for (long k = 0; k < std::lround(duration_s / dt); ++k) {
    const VectorXd a1 = Accelerations(model, q, qd);
    const VectorXd v2 = qd + 0.5 * dt * a1, a2 = Accelerations(model, q + 0.5 * dt * qd, v2);
    const VectorXd v3 = qd + 0.5 * dt * a2, a3 = Accelerations(model, q + 0.5 * dt * v2, v3);
    const VectorXd v4 = qd + dt * a3, a4 = Accelerations(model, q + dt * v3, v4);
    q += dt / 6 * (qd + 2 * v2 + 2 * v3 + v4);
    qd += dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
  }
  return q;
}

TEST(UrdfRobotTest, OdeFollowsTheIndependentModelAlongAFallToFirstOrderInItsStep) {
  const std::vector<double> pose = {0.3, -1.0, 1.2, -0.7, 0.9, 0.2};
  const double duration_s = 0.3;
  RobotConfig robot = Frictionless(RobotPreset("ur-class"));
  robot.physics_rate_Hz = 1000;
  const VectorXd q0 = Eigen::Map<const VectorXd>(pose.data(), 6);
  const VectorXd reference = ReferenceFall(ArmModel(robot), q0, duration_s);
  const double motion = (reference - q0).norm();
  ASSERT_GT(motion, 0.05);  // it really falls
  std::vector<double> errors;
  for (const double rate_Hz : {1000.0, 2000.0, 5000.0, 10000.0}) {
    robot.physics_rate_Hz = rate_Hz;
    const ArmModel model(robot);
    RunSpec spec;
    spec.duration_s = duration_s;
    spec.joints = UnpoweredAt(pose, /*brake_released=*/true);
    VectorXd q(6);
    ASSERT_TRUE(Simulate(model, spec, [&](const Tick& tick) {
      for (int j = 0; j < 6; ++j) q[j] = (*tick.joints)[j].q_rad;
    }).ok);
    errors.push_back((q - reference).norm() / motion);
    RecordProperty("relative_error_at_" + std::to_string(static_cast<int>(rate_Hz)) + "_Hz", std::to_string(errors.back()));
  }
  EXPECT_LT(errors[0], 0.02);
  // First order: the error times the rate stays within a factor 2 of the 1 kHz one.
  const double rates[] = {1000, 2000, 5000, 10000};
  for (int k = 1; k < 4; ++k) {
    const double scaled = errors[k] * rates[k] / (errors[0] * rates[0]);
    EXPECT_GT(scaled, 0.5) << rates[k] << " Hz: " << errors[k];
    EXPECT_LT(scaled, 2.0) << rates[k] << " Hz: " << errors[k];
  }
}

// The URDF armfault writes for a links-shorthand robot, read back, is the same plant.
TEST(UrdfRobotTest, WrittenUrdfOfMrrConfig1GivesThePresetsResults) {
  const RobotConfig preset = RobotPreset("mrr-config1");
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "armfault_urdf_roundtrip";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "mrr.urdf") << UrdfText(preset);
  const nlohmann::json robot = {{"urdf", "mrr.urdf"},
                                {"drives", DrivesJson(preset)},
                                {"payload_kg", preset.payload_kg},
                                {"base_position_m", preset.base_position_m}};
  const RobotConfig read = RobotFromJson(robot, "/robot", dir.string());
  std::filesystem::remove_all(dir);
  ASSERT_EQ(read.bodies.size(), 3u);
  const ArmModel a(preset), b(read);
  RunSpec s;
  s.duration_s = 3;
  s.seed = 5;
  std::vector<double> qa, qb;
  const RunResult ra = Simulate(a, s, [&](const Tick& t) { qa.push_back((*t.joints)[2].tau_true_Nm); });
  const RunResult rb = Simulate(b, s, [&](const Tick& t) { qb.push_back((*t.joints)[2].tau_true_Nm); });
  ASSERT_TRUE(ra.ok && rb.ok);
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(rb.energy[j].supply_J, ra.energy[j].supply_J, 1e-9 * std::fabs(ra.energy[j].supply_J) + 1e-12);
    EXPECT_NEAR(rb.energy[j].emf_J, ra.energy[j].emf_J, 1e-9 * std::fabs(ra.energy[j].supply_J) + 1e-12);
  }
  ASSERT_EQ(qa.size(), qb.size());
  for (size_t k = 0; k < qa.size(); ++k) EXPECT_NEAR(qb[k], qa[k], 1e-9 * 30) << "tick " << k;
}

}  // namespace
}  // namespace armfault
