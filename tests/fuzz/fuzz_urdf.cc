// Fuzz target: a URDF file's text, read by liburdfdom and armfault's chain builder
// (core/plant/robot/urdf_robot.h) with an industrial-small drive on every moving joint, built into an
// ArmModel and, when it parsed, simulated for 0.02 s with every joint holding its start. A URDF
// is untrusted input parsed by third-party C++: every input must end in a robot or an
// InputError, never an abort, a hang or a sanitizer report.
#include "core/plant/simulation.h"
#include "core/plant/robot/urdf_robot.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace armfault;
  return fuzz::RejectCleanly([&] {
    const std::string text = fuzz::Text(data, size);
    nlohmann::json drives = nlohmann::json::object();
    for (const std::string& joint : UrdfMovingJoints(text, fuzz::kSource)) drives[joint] = "industrial-small";
    RobotConfig robot = RobotFromUrdfText(text, fuzz::kSource, drives, "/robot/drives");
    Validate(robot, "/robot");
    const ArmModel model(robot);
    RunSpec spec;
    spec.duration_s = 0.02;
    Simulate(model, spec, TickObserver());
  });
}
