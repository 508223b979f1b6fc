// `armfault calibrate DIR --run RUN [--robot R] -o unit.json`: a twin of one unit, fitted to a
// healthy log of an export or an import (campaigns/data/calibrate.h, docs/calibration.md).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/commands/commands.h"
#include "campaigns/data/calibrate.h"
#include "campaigns/data/replay.h"
#include "core/base/json_input.h"
#include "core/base/output_file.h"
#include "core/base/suggest.h"
#include "core/plant/simulation.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;

std::string Fixed(double v) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

nlohmann::json ParameterJson(const CalibratedParameter& p) {
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  return {{"key", p.key},           {"unit", p.unit},         {"nominal", number(p.nominal)},
          {"estimate", number(p.estimate)}, {"low_95", number(p.low)}, {"high_95", number(p.high)},
          {"identifiable", p.identifiable}};
}

}  // namespace

int CalibrateCommand(const CalibrateCommandOptions& o) {
  const fs::path dir(o.dir);
  if (!fs::is_directory(dir)) {
    throw InputError(o.dir, "", fs::exists(dir) ? "not a directory" : "no such directory (expected the output of armfault export or import)");
  }
  if (o.output_file.empty()) throw InputError("-o", "", "expected the robot file to write (unit.json)");
  if (!(o.block_s > 0) || !std::isfinite(o.block_s)) throw InputError("--block-s", "", "expected a block length > 0 s, got " + FormatNumber(o.block_s));
  if (o.resamples < 50 || o.resamples > 100000) {
    throw InputError("--resamples", "", "expected 50 to 100000 bootstrap resamples, got " + std::to_string(o.resamples));
  }
  // The datasheet: --robot, or the robot DIR's campaign.json was run with.
  const RobotConfig nominal = !o.robot.empty() ? ReadRobotArgument(o.robot) : RecordedRobot(o.dir, "name the robot with --robot");
  const nlohmann::json line = ManifestLine(o.dir, o.run, "--run");
  if (line.contains("family") && line["family"].is_string() && !line["family"].get<std::string>().empty()) {
    throw InputError("--run", "", "run \"" + o.run + "\" is labelled faulty (" + line["family"].get<std::string>() +
                                      "): a twin is calibrated on a healthy log");
  }
  if (!line.contains("signals") || !line["signals"].is_string()) {
    throw InputError((dir / "manifest.jsonl").string(), "", "run \"" + o.run + "\" names no \"signals\" file");
  }
  const fs::path signals = dir / line["signals"].get<std::string>();
  const ArmModel arm(nominal);
  const int joints = arm.joint_count();
  const double dt = arm.control_dt_s();
  std::vector<std::vector<JointSignals>> ticks;
  std::vector<double> times;
  ReadSignalsAtControlRate(signals.string(), joints, dt, &ticks, &times);
  CalibrationOptions options;
  options.block_s = o.block_s;
  options.resamples = o.resamples;
  const UnitCalibration cal = CalibrateUnit(nominal, dt, ticks, options);

  std::printf("calibrated run %s of %s: %zu ticks (%.1f s), %d bootstrap blocks of %g s, 95 %% intervals\n", o.run.c_str(),
              o.dir.c_str(), ticks.size(), dt * static_cast<double>(ticks.size() - 1), cal.blocks, o.block_s);
  nlohmann::json report = {{"run_id", o.run}, {"dir", o.dir}, {"ticks", ticks.size()}, {"blocks", cal.blocks}, {"joints", nlohmann::json::array()}};
  for (const JointCalibration& jc : cal.joints) {
    std::printf("joint %d: residual RMS %.3g W (%.3g A supply current), torque balance %.3g N m; %ld + %ld rows%s\n", jc.joint,
                jc.power_rms_W, jc.current_rms_A, jc.torque_rms_Nm, jc.electrical_rows, jc.balance_rows,
                std::isfinite(jc.winding_temp_C) ? (", winding " + Fixed(jc.winding_temp_C) + " C").c_str() : "");
    nlohmann::json jj = {{"joint", jc.joint},
                         {"power_rms_W", jc.power_rms_W},
                         {"current_rms_A", jc.current_rms_A},
                         {"torque_rms_Nm", jc.torque_rms_Nm},
                         {"parameters", nlohmann::json::array()}};
    for (const CalibratedParameter& p : jc.parameters) {
      std::printf("  %-32s %12s  [%s, %s]  datasheet %s%s\n", p.key.c_str(), Fixed(p.estimate).c_str(), Fixed(p.low).c_str(),
                  Fixed(p.high).c_str(), Fixed(p.nominal).c_str(), p.identifiable ? "" : "  not identifiable: the twin keeps the datasheet's");
      jj["parameters"].push_back(ParameterJson(p));
    }
    report["joints"].push_back(jj);
  }
  const CalibratedParameter& pl = cal.payload;
  std::printf("payload_kg %s [%s, %s]%s\n", Fixed(pl.estimate).c_str(), Fixed(pl.low).c_str(), Fixed(pl.high).c_str(),
              pl.identifiable ? "" : "  not identifiable: the twin keeps the robot's");
  report["payload"] = ParameterJson(pl);

  RobotConfig twin = cal.twin;
  twin.name = nominal.name + "-twin";
  const fs::path out(o.output_file);
  fs::path sidecar = out;
  sidecar.replace_extension(".calibration.json");
  WriteAtomically(out, RobotToJson(twin).dump(2) + "\n");
  WriteAtomically(sidecar, report.dump(2) + "\n");
  std::printf("wrote %s (the twin: a robot object for a run or campaign's \"robot\") and %s (estimates and intervals)\n",
              out.string().c_str(), sidecar.string().c_str());
  return 0;
}

}  // namespace armfault
