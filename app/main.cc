// armfault: fault-injection campaigns for power-efficiency health monitoring of robot joints.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "app/commands.h"
#include "core/json_input.h"
#include "core/ode_runtime.h"

int main(int argc, char** argv) {
  armfault::InitOde();  // before any thread starts
  CLI::App app{"armfault: fault-injection campaigns for power-efficiency health monitoring of robot joints"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("armfault ") + ARMFAULT_VERSION);

  armfault::TraceOptions trace;
  CLI::App* trace_cmd = app.add_subcommand("trace", "simulate one run and write its time series as CSV");
  trace_cmd->add_option("run", trace.run_file, "run JSON file (default: thesis experiment 1)");
  trace_cmd->add_option("--robot", trace.robot, "robot preset (mrr-config1, pendulum)");
  trace_cmd->add_option("--duration", trace.duration_s, "duration [s]");
  trace_cmd->add_option("--seed", trace.seed, "noise seed");
  trace_cmd->add_option("--joint", trace.joint_specs,
                        "J=<trajectory JSON>, e.g. 3='{\"type\":\"sine_pair\",\"amplitude_deg\":25,\"omega_rad_s\":1.2732}'");
  trace_cmd->add_option("--fault", trace.fault_specs,
                        "fault JSON, e.g. '{\"family\":\"kt_degradation\",\"joint\":3,\"kt_factor\":0.6,\"onset_s\":2}'");
  trace_cmd->add_option("-o,--output", trace.output, "trace CSV path")->capture_default_str();
  trace_cmd->add_option("--monitor-out", trace.monitor_output, "write the monitor's verdicts and windows as JSON");
  trace_cmd->add_flag("-q,--quiet", trace.quiet, "no summary");

  std::string run_dir = "out";
  CLI::App* run_cmd = app.add_subcommand("run", "the main job: thesis experiment 1 with the monitor, then the thesis experiments 1-3");
  run_cmd->add_option("-o,--output-dir", run_dir, "output directory")->capture_default_str();

  armfault::ThesisOptions thesis;
  CLI::App* thesis_cmd = app.add_subcommand(
      "thesis", "run the thesis experiments 1-3 and compare with the published efficiencies (writes thesis.json, thesis.md)");
  thesis_cmd->add_option("-o,--output-dir", thesis.output_dir, "output directory")->capture_default_str();
  thesis_cmd->add_option("--seed", thesis.seed, "noise seed")->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }

  try {
    if (*trace_cmd) return armfault::RunTrace(trace);
    if (*thesis_cmd) return armfault::RunThesis(thesis);
    if (*run_cmd) {
      std::filesystem::create_directories(run_dir);
      armfault::TraceOptions exp1;
      exp1.output = (std::filesystem::path(run_dir) / "exp1-trace.csv").string();
      std::printf("thesis experiment 1: top joint q = 25 (sin(8t/2pi) - 0.5 sin(16t/2pi)) deg, 10 s\n");
      const int status = armfault::RunTrace(exp1);
      if (status != 0) return status;
      std::printf("\n");
      armfault::ThesisOptions all;
      all.output_dir = run_dir;
      return armfault::RunThesis(all);
    }
  } catch (const armfault::InputError& e) {
    std::fprintf(stderr, "armfault: error: %s\n", e.what());
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    std::fprintf(stderr, "armfault: error: %s\n", e.what());
    return 2;
  }
  return 2;
}
