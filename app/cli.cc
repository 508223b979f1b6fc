// armfault's command line: every subcommand, parsed and run (app/cli.h). The `armfault` binary
// (app/main.cc) and `python3 -m armfault` (the Python package, which can also build a Python
// monitor named in a campaign) both run it.
#include "app/cli.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "app/commands/commands.h"
#include "app/suggest.h"
#include "core/base/json_input.h"
#include "core/monitors/monitor.h"
#include "core/plant/ode_runtime.h"

namespace {

// One subcommand: its CLI11 setup and what it runs once chosen. Each Add*Command keeps the
// options its CLI11 options write to (`o`) alive in the closure that reads them.
struct Command {
  CLI::App* cli;
  std::function<int()> run;
};

Command AddTraceCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::TraceOptions>();
  CLI::App* cmd = app.add_subcommand("trace", "simulate one run and write its time series as CSV");
  cmd->add_option("run", o->run_file, "run JSON file (default: thesis experiment 1), or a campaign with --run");
  cmd->add_option("--robot", o->robot, "robot preset (mrr-config1, pendulum, ur-class)");
  cmd->add_option("--duration", o->duration_s, "duration [s]");
  cmd->add_option("--seed", o->seed, "noise seed");
  cmd->add_option("--joint", o->joint_specs,
                  "J=<trajectory JSON>, e.g. 3='{\"type\":\"sine_pair\",\"amplitude_deg\":25,\"omega_rad_s\":1.2732}'");
  cmd->add_option("--fault", o->fault_specs,
                  "fault JSON, e.g. '{\"family\":\"kt_degradation\",\"joint\":3,\"kt_factor\":0.6,\"onset_s\":2}'");
  cmd->add_option("-o,--output", o->output, "trace CSV path")->capture_default_str();
  cmd->add_option("--monitor-out", o->monitor_output, "write the monitor's verdicts and windows as JSON");
  cmd->add_option("--statistics", o->statistics_output,
                  "write every statistic the monitor publishes, per tick and joint, beside its threshold, as CSV "
                  "(t_s, joint, statistic, family, value, threshold, above)");
  cmd->add_flag("-q,--quiet", o->quiet, "no summary");
  // With --run the positional file is a campaign: one of its cases, re-run as the campaign ran it.
  cmd->add_option("--run", o->run_id, "re-run this case of the campaign file (its run_id or case number)");
  return {cmd, [o] { return o->run_id.empty() ? armfault::RunTrace(*o) : armfault::TraceCampaignCase(*o); }};
}

Command AddRunCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::CampaignRunOptions>();
  CLI::App* cmd = app.add_subcommand("run", "run a campaign (default: the built-in thesis sweep) and score the monitor");
  cmd->add_option("campaign", o->campaign_file, "campaign JSON file (default: the built-in thesis sweep)");
  cmd->add_option("-o,--output-dir", o->output_dir,
                  "output directory: campaign.json, results.jsonl (one line per run), decisions.jsonl (what `tune` "
                  "reads), results.csv, summary.json, junit.xml")
      ->capture_default_str();
  cmd->add_option("-j,--jobs", o->threads, "threads (0: all cores)")->capture_default_str();
  cmd->add_option("--shard", o->shard, "run shard K of N (K/N, K from 0); default from SLURM_ARRAY_TASK_ID/COUNT or JOB_COMPLETION_INDEX");
  cmd->add_option("--shard-count", o->shard_count, "shard count N with JOB_COMPLETION_INDEX (Kubernetes Indexed Job)");
  cmd->add_flag("--resume", o->resume, "continue an interrupted run in the same output directory");
  cmd->add_flag("--force", o->force,
                "replace the results of another campaign in the output directory (without it they are kept and "
                "the run stops with exit 2)");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress output");
  cmd->add_flag("--early-stop", o->early_stop,
                "stop as soon as every floor is decided: runs go in an even sweep of the campaign and each floor is "
                "decided when the whole campaign's rate is predicted on one side of its bound (writes early_stop.json)");
  cmd->add_option("--early-stop-confidence", o->early_stop_confidence,
                  "the probability at which --early-stop decides a floor")
      ->capture_default_str();
  cmd->add_flag("--summary-only", o->summary_only,
                "small CI artefacts: after the summary, remove decisions.jsonl and results.csv, leaving "
                "campaign.json, results.jsonl, summary.json and junit.xml (report and diff work; tune does not)");
  return {cmd, [o] { return armfault::RunCampaignCommand(*o); }};
}

Command AddExportCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::ExportCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "export", "write every run's monitor signals (gzip CSV at the control rate) with the ground truth in a manifest, "
                "for data-driven detectors");
  cmd->add_option("campaign", o->campaign_file, "campaign JSON file")->required();
  cmd->add_option("-o,--output-dir", o->output_dir, "output directory")->capture_default_str();
  cmd->add_option("-j,--jobs", o->threads, "threads (0: all cores)")->capture_default_str();
  cmd->add_option("--shard", o->shard, "export shard K of N (K/N), as `run --shard`");
  cmd->add_option("--shard-count", o->shard_count, "shard count N with JOB_COMPLETION_INDEX");
  cmd->add_option("--split", o->split,
                  "train/validation/test fractions by seed, e.g. 0.6/0.2/0.2 (a \"split\" column in the manifest)");
  cmd->add_option("--gzip-level", o->gzip_level,
                  "zlib level of runs/*.csv.gz, 1 (fastest; about a fifth larger) to 9 (smallest); the text is the same")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "no progress output");
  return {cmd, [o] { return armfault::ExportCommand(*o); }};
}

Command AddImportCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::ImportCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "import", "recorded logs (CSV in any column names and units) into an export's layout, resampled to the control "
                "rate by a map (docs/import.md), so that score and report take them");
  cmd->add_option("logs", o->logs, "CSV logs (plain or gzip): one per run, or split into runs by the map's run_column")
      ->required();
  cmd->add_option("--map", o->map_file, "MAP.json: columns, units, time, robot, labels")->required();
  cmd->add_option("-o,--output-dir", o->output_dir, "output directory (must not exist, or be empty)")->required();
  cmd->add_flag("-q,--quiet", o->quiet, "no summary of the runs");
  return {cmd, [o] { return armfault::ImportCommand(*o); }};
}

Command AddScoreCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::ScoreCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "score", "score verdicts made offline (JSON Lines: run_id, t_s, joint, family, alarm, magnitude) as a live "
               "monitor is scored; writes summary.json and junit.xml with the campaign's floors");
  cmd->add_option("dir", o->dir, "output directory of `armfault export` or `armfault run`")->required();
  cmd->add_option("verdicts", o->verdicts_file, "verdicts JSON Lines file")->required();
  cmd->add_option("-o,--output-dir", o->output_dir, "output directory (default: DIR/scored)");
  return {cmd, [o] { return armfault::ScoreCommand(*o); }};
}

Command AddReplayCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::ReplayCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "replay", "run a monitor over recorded signals (an export or an import) tick by tick and score it as `run` does; "
                "gives the false alarms per hour of operation of healthy and unlabelled runs");
  cmd->add_option("dir", o->dir, "output directory of `armfault export` or `armfault import`")->required();
  cmd->add_option("--monitor", o->monitor_file,
                  "a JSON file holding a monitor as a campaign's \"monitor\" key (default: the campaign's)");
  cmd->add_option("-o,--output-dir", o->output_dir, "output directory (default: DIR/replayed)");
  cmd->add_option("--commission", o->commission_run,
                  "commission the monitor from this healthy run of DIR (a run_id) instead of as the campaign did");
  cmd->add_option("-j,--jobs", o->threads, "worker threads (default: all cores); never changes a result");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress output");
  return {cmd, [o] { return armfault::ReplayCommand(*o); }};
}

Command AddCalibrateCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::CalibrateCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "fit one unit's drive parameters to a healthy log (an export or an import) and write its twin: "
                   "a robot file, each value with a 95 % interval (docs/calibration.md)");
  cmd->add_option("dir", o->dir, "output directory of `armfault export` or `armfault import`")->required();
  cmd->add_option("--run", o->run, "the healthy run (run_id) to calibrate on")->required();
  cmd->add_option("--robot", o->robot, "the datasheet robot: a preset or a robot file (default: DIR's campaign.json)");
  cmd->add_option("-o,--output", o->output_file, "the twin's robot file to write (and NAME.calibration.json beside it)")->required();
  cmd->add_option("--block-s", o->block_s, "bootstrap block length [s] (default 2)");
  cmd->add_option("--resamples", o->resamples, "bootstrap resamples (default 400)");
  return {cmd, [o] { return armfault::CalibrateCommand(*o); }};
}

Command AddValidateCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::ValidateOptions>();
  CLI::App* cmd = app.add_subcommand("validate", "check a campaign file and print its run count");
  cmd->add_option("campaign", o->campaign_file, "campaign JSON file")->required();
  cmd->add_flag("--load-plugins", o->load_plugins,
                "also load the monitor's plugin library and check its settings (this runs the library's code)");
  return {cmd, [o] { return armfault::ValidateCommand(*o); }};
}

Command AddMergeCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::MergeOptions>();
  CLI::App* cmd = app.add_subcommand("merge", "join the output directories of `run --shard K/N` into one, as an unsharded run");
  cmd->add_option("dirs", o->input_dirs, "the output directory of every shard 0..N-1")->required();
  cmd->add_option("-o,--output-dir", o->output_dir,
                  "output directory: campaign.json, results.jsonl, decisions.jsonl, results.csv, summary.json, "
                  "junit.xml, as an unsharded run writes them")
      ->required();
  return {cmd, [o] { return armfault::MergeCommand(*o); }};
}

Command AddBenchCommand(CLI::App& app) {
  struct Options {
    int repeats = 0;
    std::vector<double> durations_s;
    bool shift = false;
    std::string robot;
    std::string engine;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("bench", "cost of a run against bare ODE stepping, and parallel throughput; "
                                              "with --duration or --shift, cost against a run's length");
  cmd->add_option("--repeats", o->repeats, "timed runs per figure (default 10; 3 with --duration or --shift)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--duration", o->durations_s,
                  "simulated length [s] of a healthy mrr-config1 run, all joints moving (repeatable): its peak "
                  "memory and time per simulated second")
      ->check(CLI::Range(0.002, 3600.0));
  cmd->add_flag("--shift", o->shift, "the same for 10 s, 10 min and 1 h");
  cmd->add_option("--robot", o->robot,
                  "measure healthy 10-s runs of this robot, every joint moving (a preset or a robot JSON file) "
                  "instead of the thesis sweep on mrr-config1");
  cmd->add_option("--engine", o->engine,
                  "step the full runs with this engine: ode (default) or articulated; the bare stepping they are "
                  "compared with stays ODE's");
  return {cmd, [o] {
            if (o->shift || !o->durations_s.empty()) {
              std::vector<double> d = o->durations_s;
              if (o->shift) d.insert(d.end(), {10.0, 600.0, 3600.0});
              return armfault::BenchLengthCommand(d, o->repeats > 0 ? o->repeats : 3);
            }
            return armfault::BenchCommand(o->repeats > 0 ? o->repeats : 10, o->robot, o->engine);
          }};
}

Command AddRobotCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::RobotCommandOptions>();
  CLI::App* cmd = app.add_subcommand("robot", "print a robot in full (every key filled in), or write it as a URDF and "
                                              "a robot file with its drives");
  cmd->add_option("robot", o->robot, "a robot preset (mrr-config1, pendulum, ur-class) or a JSON file: a robot, "
                                     "or a run or campaign file (its \"robot\")")
      ->required();
  cmd->add_option("--urdf", o->urdf_dir, "write NAME.urdf and NAME.robot.json into this directory");
  return {cmd, [o] { return armfault::RobotCommand(*o); }};
}

Command AddThesisCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::ThesisOptions>();
  CLI::App* cmd = app.add_subcommand(
      "thesis", "run the thesis experiments 1-3 and compare with the published efficiencies (writes thesis.json, thesis.md)");
  cmd->add_option("-o,--output-dir", o->output_dir, "output directory")->capture_default_str();
  cmd->add_option("--seed", o->seed, "noise seed")->capture_default_str();
  return {cmd, [o] { return armfault::RunThesis(*o); }};
}

Command AddDiffCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::DiffCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "diff", "compare two campaign results (A = baseline, B = candidate) metric by metric, with significance tests");
  cmd->add_option("dir_a", o->dir_a, "baseline output directory (results.jsonl)")->required();
  cmd->add_option("dir_b", o->dir_b, "candidate output directory (results.jsonl)")->required();
  cmd->add_option("--alpha", o->alpha, "significance level")->capture_default_str();
  cmd->add_option("--tolerance", o->tolerance, "allowed worsening of a rate (absolute)")->capture_default_str();
  cmd->add_option("--latency-tolerance", o->latency_tolerance_s, "allowed increase of the median latency [s]")
      ->capture_default_str();
  cmd->add_option("-o,--output", o->json_output, "write every comparison as JSON");
  cmd->add_option("--markdown", o->markdown_output, "write the table as Markdown");
  return {cmd, [o] { return armfault::DiffCommand(*o); }};
}

Command AddReportCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::ReportCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "report", "write DIR/report.html (self-contained plots: ROC, detection probability, confusion, latency, "
                "table 5-3, one run over time) and DIR/report.md");
  cmd->add_option("dir", o->dir, "output directory of `armfault run` (summary.json, results.jsonl)")
      ->required();
  cmd->add_option("--run", o->run_id, "run_id of the run to plot over time (default: the first missed faulty run)");
  cmd->add_option("-o,--output", o->output, "HTML file (default: DIR/report.html; the .md goes beside it)");
  cmd->add_option("--twin", o->twin_file,
                  "a twin (robot file as `armfault calibrate` writes it, or a preset) run along one recorded run's reference: "
                  "a section with the recorded and the twin's signals side by side and their residuals (docs/calibration.md, \"Compare\")");
  cmd->add_option("--twin-run", o->twin_run,
                  "run_id of the recorded run compared with --twin (default: the run the twin was calibrated on, else the "
                  "first healthy run)");
  cmd->add_option("--recorded", o->recorded_dir,
                  "the export or import DIR replayed, whose signals --twin is compared with (default: DIR if it holds a "
                  "manifest.jsonl, else DIR's parent: replay writes SRC/replayed)");
  return {cmd, [o] { return armfault::ReportCommand(*o); }};
}

Command AddTuneCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::TuneCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "tune", "re-score monitor thresholds from a campaign's stored decision statistics (no new simulation); "
              "writes DIR/tuning.json and a tuned monitor JSON");
  cmd->add_option("dir", o->dir,
                  "campaign output directory: reads decisions.jsonl (or, from an older armfault, the decisions "
                  "inline in results.jsonl)")
      ->required();
  cmd->add_option("--sweep", o->sweep, "worn limits to sweep, e.g. kt_factor.worn=0.85:0.99:15,friction_factor.worn=1.3");
  cmd->add_option("--rule", o->rule, "operating point: max_detection (under --false-alarm-ceiling), youden, min_cost")
      ->capture_default_str();
  cmd->add_option("--false-alarm-ceiling", o->false_alarm_ceiling, "max_detection: highest false-alarm rate allowed")
      ->capture_default_str();
  cmd->add_option("--miss-cost", o->miss_cost, "min_cost: cost of a missed fault")->capture_default_str();
  cmd->add_option("--false-alarm-cost", o->false_alarm_cost, "min_cost: cost of a false alarm")->capture_default_str();
  // Not -o: -o names a command's main output, and tune's is DIR/tuning.json.
  cmd->add_option("--monitor-out", o->monitor_output, "tuned monitor JSON (default DIR/tuned-monitor.json)");
  cmd->add_option("-j,--jobs", o->threads, "threads (0: all cores)")->capture_default_str();
  return {cmd, [o] { return armfault::TuneCommand(*o); }};
}

Command AddBoundaryCommand(CLI::App& app) {
  auto o = std::make_shared<armfault::BoundaryCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "boundary", "find each cell's detection boundary (the magnitude detected with 90 % probability at 95 % "
                  "confidence) with batches of runs chosen from the results so far; writes a run directory and "
                  "DIR/boundary.json");
  cmd->add_option("campaign", o->campaign_file, "campaign JSON file with a \"search\" block");
  cmd->add_option("--from", o->from_dir,
                  "instead of searching, estimate each cell's boundary from the runs in this output "
                  "directory (writes DIR/boundary.json)");
  cmd->add_option("-o,--output-dir", o->output_dir, "output directory")->capture_default_str();
  cmd->add_option("-j,--jobs", o->threads, "threads (0: all cores); the results do not depend on it")
      ->capture_default_str();
  cmd->add_flag("--resume", o->resume, "continue an interrupted search in the same output directory");
  cmd->add_option("--max-batches", o->max_batches, "stop after this many batches (--resume continues)");
  cmd->add_flag("-q,--quiet", o->quiet, "no progress output");
  return {cmd, [o] { return armfault::BoundaryCommand(*o); }};
}

}  // namespace

int armfault::CliMain(int argc, char** argv) {
  armfault::InitOde();  // before any thread starts
  // Line-buffered even on a pipe: stdout's lines (a campaign's header, its floors) and stderr's
  // (progress, warnings) then reach a log in the order they were written.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  // Named, so usage lines say "armfault" and not the path it was started from.
  CLI::App app{"armfault: fault-injection campaigns for power-efficiency health monitoring of robot joints", "armfault"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("armfault ") + ARMFAULT_VERSION);
  // In the order `armfault --help` lists them.
  const std::vector<Command> commands = {
      AddTraceCommand(app),
      AddRunCommand(app),
      AddExportCommand(app),
      AddImportCommand(app),
      AddScoreCommand(app),
      AddReplayCommand(app),
      AddCalibrateCommand(app),
      AddValidateCommand(app),
      AddMergeCommand(app),
      AddBenchCommand(app),
      AddRobotCommand(app),
      AddThesisCommand(app),
      AddDiffCommand(app),
      AddReportCommand(app),
      AddTuneCommand(app),
      AddBoundaryCommand(app),
  };

  // Every --help ends with what the exit status means (docs/campaign-format.md, "Exit status").
  const std::string exit_codes =
      "\nExit status: 0 done (every floor met); 1 a floor missed (run, merge, score, replay) or a metric "
      "significantly worse (diff); 2 invalid input or usage, with the file and JSON pointer; 3 some runs failed (the others are written); 130 interrupted "
      "(Ctrl-C: what is written is kept, and --resume continues).";
  app.footer(exit_codes);
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) sub->footer(exit_codes);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // The nearest command or option first: CLI11's own words for a typo'd command ("A
    // subcommand is required") would mislead.
    const std::string hint = armfault::SuggestForParseError(app, argc, argv);
    if (hint.empty()) {
      app.exit(e);
    } else {
      std::fprintf(stderr, "%s\nRun with --help for more information.\n", hint.c_str());
    }
    return 2;
  }

  try {
    for (const Command& c : commands) {
      if (*c.cli) return c.run();
    }
  } catch (const armfault::InputError& e) {
    // Every error found in the input (a campaign lists all of its own), one per line.
    for (const std::string& line : armfault::ErrorReportLines(e)) std::fprintf(stderr, "armfault: error: %s\n", line.c_str());
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    std::fprintf(stderr, "armfault: error: %s\n", e.what());
    return 2;
  } catch (const armfault::MonitorFailure& e) {
    // The monitor of the one run `trace` simulates failed (a plugin's error return): the run failed.
    std::fprintf(stderr, "armfault: error: monitor failed: %s\n", e.what());
    return 3;
  }
  return 2;
}
