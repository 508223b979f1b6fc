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

  armfault::CampaignRunOptions campaign_run;
  CLI::App* run_cmd = app.add_subcommand("run", "run a campaign (default: the built-in thesis sweep) and score the monitor");
  run_cmd->add_option("campaign", campaign_run.campaign_file, "campaign JSON file (default: the built-in thesis sweep)");
  run_cmd->add_option("-o,--output-dir", campaign_run.output_dir, "output directory")->capture_default_str();
  run_cmd->add_option("-j,--jobs", campaign_run.threads, "threads (0: all cores)")->capture_default_str();
  run_cmd->add_option("--shard", campaign_run.shard, "run shard K of N (K/N, K from 0); default from SLURM_ARRAY_TASK_ID/COUNT or JOB_COMPLETION_INDEX");
  run_cmd->add_option("--shard-count", campaign_run.shard_count, "shard count N with JOB_COMPLETION_INDEX (Kubernetes Indexed Job)");
  run_cmd->add_flag("--resume", campaign_run.resume, "continue an interrupted run in the same output directory");
  run_cmd->add_flag("-q,--quiet", campaign_run.quiet, "no progress output");

  std::string validate_file;
  CLI::App* validate_cmd = app.add_subcommand("validate", "check a campaign file and print its run count");
  validate_cmd->add_option("campaign", validate_file, "campaign JSON file")->required();

  int bench_repeats = 10;
  CLI::App* bench_cmd = app.add_subcommand("bench", "cost of a run against bare ODE stepping, and parallel throughput");
  bench_cmd->add_option("--repeats", bench_repeats, "timed runs per figure")->capture_default_str()->check(CLI::Range(1, 100000));

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
    if (*run_cmd) return armfault::RunCampaignCommand(campaign_run);
    if (*validate_cmd) return armfault::ValidateCommand(validate_file);
    if (*bench_cmd) return armfault::BenchCommand(bench_repeats);
  } catch (const armfault::InputError& e) {
    std::fprintf(stderr, "armfault: error: %s\n", e.what());
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    std::fprintf(stderr, "armfault: error: %s\n", e.what());
    return 2;
  }
  return 2;
}
