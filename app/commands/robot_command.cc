// `armfault robot NAME|FILE [--urdf DIR]`: a robot in full (every key filled in), or written as
// a URDF plus a robot file that names it with its drives.
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>

#include "app/commands/commands.h"
#include "core/base/json_input.h"
#include "core/base/output_file.h"
#include "core/plant/robot/robot_config.h"
#include "core/plant/robot/urdf_robot.h"

namespace armfault {

RobotConfig ReadRobotArgument(const std::string& what) {
  for (const std::string& name : RobotPresetNames()) {
    if (what == name) return RobotPreset(name);
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(what, ec)) {
    std::string presets;
    for (const std::string& name : RobotPresetNames()) presets += (presets.empty() ? "" : ", ") + name;
    throw InputError("<command line>", "robot", "\"" + what + "\" is neither a robot preset (" + presets + ") nor a file");
  }
  const nlohmann::json file = ReadJsonFile(what);
  const std::string base = std::filesystem::path(what).parent_path().string();
  try {
    const bool wrapper = file.is_object() && file.contains("robot") && !file.contains("modules") && !file.contains("urdf");
    return wrapper ? RobotFromJson(file.at("robot"), "/robot", base) : RobotFromJson(file, "", base);
  } catch (const InputError& e) {
    throw e.WithSource(what);
  }
}

namespace {

// A robot's name as a file name: what is not a letter, digit, '-' or '_' becomes '_', so a name
// cannot reach outside the directory ("../x") or hide a file (".x").
std::string FileStem(const std::string& name) {
  std::string out;
  for (char c : name) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  return out.empty() ? "robot" : out;
}

}  // namespace

int RobotCommand(const RobotCommandOptions& o) {
  const RobotConfig robot = ReadRobotArgument(o.robot);
  if (o.urdf_dir.empty()) {
    std::printf("%s\n", RobotToJson(robot).dump(2).c_str());
    return 0;
  }
  const std::filesystem::path dir(o.urdf_dir);
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec)) {
    throw InputError("--urdf", "", "\"" + o.urdf_dir + "\" exists and is not a directory");
  }
  std::filesystem::create_directories(dir);
  const std::string stem = FileStem(robot.name);
  const std::string urdf_name = stem + ".urdf";
  nlohmann::json file = {{"urdf", urdf_name},
                         {"drives", DrivesJson(robot)},
                         {"name", robot.name},
                         {"base_position_m", robot.base_position_m},
                         {"payload_kg", robot.payload_kg},
                         {"gravity_m_s2", robot.gravity_m_s2},
                         {"physics_rate_Hz", robot.physics_rate_Hz},
                         {"electrical_substeps", robot.electrical_substeps},
                         {"constraint_force_mixing", robot.constraint_force_mixing}};
  WriteAtomically(dir / urdf_name, UrdfText(robot));
  WriteAtomically(dir / (stem + ".robot.json"), file.dump(2) + "\n");
  std::printf("wrote %s and %s (use it as \"robot\": the file's contents, or read it with `armfault robot %s`)\n",
              (dir / urdf_name).string().c_str(), (dir / (stem + ".robot.json")).string().c_str(),
              (dir / (stem + ".robot.json")).string().c_str());
  return 0;
}

}  // namespace armfault
