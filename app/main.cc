// armfault: fault-injection campaigns for power-efficiency health monitoring of robot joints.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "app/commands.h"
#include "app/suggest.h"
#include "core/base/json_input.h"
#include "core/monitors/monitor.h"
#include "core/plant/ode_runtime.h"

int main(int argc, char** argv) {
  armfault::InitOde();  // before any thread starts
  // Named, so usage lines say "armfault" and not the path it was started from.
  CLI::App app{"armfault: fault-injection campaigns for power-efficiency health monitoring of robot joints", "armfault"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("armfault ") + ARMFAULT_VERSION);

  armfault::TraceOptions trace;
  CLI::App* trace_cmd = app.add_subcommand("trace", "simulate one run and write its time series as CSV");
  trace_cmd->add_option("run", trace.run_file, "run JSON file (default: thesis experiment 1), or a campaign with --run");
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
  // With --run the positional file is a campaign: one of its cases, re-run as the campaign ran it.
  trace_cmd->add_option("--run", trace.run_id, "re-run this case of the campaign file (its run_id or case number)");

  armfault::CampaignRunOptions campaign_run;
  CLI::App* run_cmd = app.add_subcommand("run", "run a campaign (default: the built-in thesis sweep) and score the monitor");
  run_cmd->add_option("campaign", campaign_run.campaign_file, "campaign JSON file (default: the built-in thesis sweep)");
  run_cmd->add_option("-o,--output-dir", campaign_run.output_dir,
                      "output directory: campaign.json, results.jsonl (one line per run), decisions.jsonl (what `tune` "
                      "reads), results.csv, summary.json, junit.xml")
      ->capture_default_str();
  run_cmd->add_option("-j,--jobs", campaign_run.threads, "threads (0: all cores)")->capture_default_str();
  run_cmd->add_option("--shard", campaign_run.shard, "run shard K of N (K/N, K from 0); default from SLURM_ARRAY_TASK_ID/COUNT or JOB_COMPLETION_INDEX");
  run_cmd->add_option("--shard-count", campaign_run.shard_count, "shard count N with JOB_COMPLETION_INDEX (Kubernetes Indexed Job)");
  run_cmd->add_flag("--resume", campaign_run.resume, "continue an interrupted run in the same output directory");
  run_cmd->add_flag("-q,--quiet", campaign_run.quiet, "no progress output");
  run_cmd->add_flag("--early-stop", campaign_run.early_stop,
                    "stop as soon as every floor is decided: runs go in an even sweep of the campaign and each floor is "
                    "decided when the whole campaign's rate is predicted on one side of its bound (writes early_stop.json)");
  run_cmd->add_option("--early-stop-confidence", campaign_run.early_stop_confidence,
                      "the probability at which --early-stop decides a floor")
      ->capture_default_str();
  run_cmd->add_flag("--summary-only", campaign_run.summary_only,
                    "small CI artefacts: after the summary, remove decisions.jsonl and results.csv, leaving "
                    "campaign.json, results.jsonl, summary.json and junit.xml (report and diff work; tune does not)");

  armfault::ExportCommandOptions export_options;
  CLI::App* export_cmd = app.add_subcommand(
      "export", "write every run's monitor signals (gzip CSV at the control rate) with the ground truth in a manifest, "
                "for data-driven detectors");
  export_cmd->add_option("campaign", export_options.campaign_file, "campaign JSON file")->required();
  export_cmd->add_option("-o,--output-dir", export_options.output_dir, "output directory")->capture_default_str();
  export_cmd->add_option("-j,--jobs", export_options.threads, "threads (0: all cores)")->capture_default_str();
  export_cmd->add_option("--shard", export_options.shard, "export shard K of N (K/N), as `run --shard`");
  export_cmd->add_option("--shard-count", export_options.shard_count, "shard count N with JOB_COMPLETION_INDEX");
  export_cmd->add_option("--split", export_options.split,
                         "train/validation/test fractions by seed, e.g. 0.6/0.2/0.2 (a \"split\" column in the manifest)");
  export_cmd->add_flag("-q,--quiet", export_options.quiet, "no progress output");

  armfault::ScoreCommandOptions score;
  CLI::App* score_cmd = app.add_subcommand(
      "score", "score verdicts made offline (JSON Lines: run_id, t_s, joint, family, alarm, magnitude) as a live "
               "monitor is scored; writes summary.json and junit.xml with the campaign's floors");
  score_cmd->add_option("dir", score.dir, "output directory of `armfault export` or `armfault run`")->required();
  score_cmd->add_option("verdicts", score.verdicts_file, "verdicts JSON Lines file")->required();
  score_cmd->add_option("-o,--output-dir", score.output_dir, "output directory (default: DIR/scored)");

  std::string validate_file;
  CLI::App* validate_cmd = app.add_subcommand("validate", "check a campaign file and print its run count");
  validate_cmd->add_option("campaign", validate_file, "campaign JSON file")->required();

  armfault::MergeOptions merge;
  CLI::App* merge_cmd = app.add_subcommand("merge", "join the output directories of `run --shard K/N` into one, as an unsharded run");
  merge_cmd->add_option("dirs", merge.input_dirs, "the output directory of every shard 0..N-1")->required();
  merge_cmd->add_option("-o,--output-dir", merge.output_dir,
                        "output directory: campaign.json, results.jsonl, decisions.jsonl, results.csv, summary.json, "
                        "junit.xml, as an unsharded run writes them")
      ->required();

  int bench_repeats = 10;
  CLI::App* bench_cmd = app.add_subcommand("bench", "cost of a run against bare ODE stepping, and parallel throughput");
  bench_cmd->add_option("--repeats", bench_repeats, "timed runs per figure")->capture_default_str()->check(CLI::Range(1, 100000));

  armfault::ThesisOptions thesis;
  CLI::App* thesis_cmd = app.add_subcommand(
      "thesis", "run the thesis experiments 1-3 and compare with the published efficiencies (writes thesis.json, thesis.md)");
  thesis_cmd->add_option("-o,--output-dir", thesis.output_dir, "output directory")->capture_default_str();
  thesis_cmd->add_option("--seed", thesis.seed, "noise seed")->capture_default_str();

  armfault::DiffCommandOptions diff;
  CLI::App* diff_cmd = app.add_subcommand(
      "diff", "compare two campaign results (A = baseline, B = candidate) metric by metric, with significance tests");
  diff_cmd->add_option("dir_a", diff.dir_a, "baseline output directory (results.jsonl)")->required();
  diff_cmd->add_option("dir_b", diff.dir_b, "candidate output directory (results.jsonl)")->required();
  diff_cmd->add_option("--alpha", diff.alpha, "significance level")->capture_default_str();
  diff_cmd->add_option("--tolerance", diff.tolerance, "allowed worsening of a rate (absolute)")->capture_default_str();
  diff_cmd->add_option("--latency-tolerance", diff.latency_tolerance_s, "allowed increase of the median latency [s]")
      ->capture_default_str();
  diff_cmd->add_option("-o,--output", diff.json_output, "write every comparison as JSON");
  diff_cmd->add_option("--markdown", diff.markdown_output, "write the table as Markdown");

  armfault::ReportCommandOptions report;
  CLI::App* report_cmd = app.add_subcommand(
      "report", "write DIR/report.html (self-contained plots: ROC, detection probability, confusion, latency, "
                "table 5-3, one run over time) and DIR/report.md");
  report_cmd->add_option("dir", report.dir, "output directory of `armfault run` (summary.json, results.jsonl)")
      ->required();
  report_cmd->add_option("--run", report.run_id, "run_id of the run to plot over time (default: the first missed faulty run)");
  report_cmd->add_option("-o,--output", report.output, "HTML file (default: DIR/report.html; the .md goes beside it)");

  armfault::TuneCommandOptions tune;
  CLI::App* tune_cmd = app.add_subcommand(
      "tune", "re-score monitor thresholds from a campaign's stored decision statistics (no new simulation); "
              "writes DIR/tuning.json and a tuned monitor JSON");
  tune_cmd->add_option("dir", tune.dir,
                       "campaign output directory: reads decisions.jsonl (or, from an older armfault, the decisions "
                       "inline in results.jsonl)")
      ->required();
  tune_cmd->add_option("--sweep", tune.sweep, "worn limits to sweep, e.g. kt_factor.worn=0.85:0.99:15,friction_factor.worn=1.3");
  tune_cmd->add_option("--rule", tune.rule, "operating point: max_detection (under --false-alarm-ceiling), youden, min_cost")
      ->capture_default_str();
  tune_cmd->add_option("--false-alarm-ceiling", tune.false_alarm_ceiling, "max_detection: highest false-alarm rate allowed")
      ->capture_default_str();
  tune_cmd->add_option("--miss-cost", tune.miss_cost, "min_cost: cost of a missed fault")->capture_default_str();
  tune_cmd->add_option("--false-alarm-cost", tune.false_alarm_cost, "min_cost: cost of a false alarm")->capture_default_str();
  // Not -o: -o names a command's main output, and tune's is DIR/tuning.json.
  tune_cmd->add_option("--monitor-out", tune.monitor_output, "tuned monitor JSON (default DIR/tuned-monitor.json)");
  tune_cmd->add_option("-j,--jobs", tune.threads, "threads (0: all cores)")->capture_default_str();

  armfault::BoundaryCommandOptions boundary;
  CLI::App* boundary_cmd = app.add_subcommand(
      "boundary", "find each cell's detection boundary (the magnitude detected with 90 % probability at 95 % "
                  "confidence) with batches of runs chosen from the results so far; writes a run directory and "
                  "DIR/boundary.json");
  boundary_cmd->add_option("campaign", boundary.campaign_file, "campaign JSON file with a \"search\" block");
  boundary_cmd->add_option("--from", boundary.from_dir,
                           "instead of searching, estimate each cell's boundary from the runs in this output "
                           "directory (writes DIR/boundary.json)");
  boundary_cmd->add_option("-o,--output-dir", boundary.output_dir, "output directory")->capture_default_str();
  boundary_cmd->add_option("-j,--jobs", boundary.threads, "threads (0: all cores); the results do not depend on it")
      ->capture_default_str();
  boundary_cmd->add_flag("--resume", boundary.resume, "continue an interrupted search in the same output directory");
  boundary_cmd->add_option("--max-batches", boundary.max_batches, "stop after this many batches (--resume continues)");
  boundary_cmd->add_flag("-q,--quiet", boundary.quiet, "no progress output");

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
    const std::string hint = armfault::SuggestForParseError(app, argc, argv);
    if (!hint.empty()) std::fprintf(stderr, "%s\n", hint.c_str());
    return 2;
  }

  try {
    if (*trace_cmd) return trace.run_id.empty() ? armfault::RunTrace(trace) : armfault::TraceCampaignCase(trace);
    if (*thesis_cmd) return armfault::RunThesis(thesis);
    if (*run_cmd) return armfault::RunCampaignCommand(campaign_run);
    if (*validate_cmd) return armfault::ValidateCommand(validate_file);
    if (*export_cmd) return armfault::ExportCommand(export_options);
    if (*score_cmd) return armfault::ScoreCommand(score);
    if (*merge_cmd) return armfault::MergeCommand(merge);
    if (*bench_cmd) return armfault::BenchCommand(bench_repeats);
    if (*tune_cmd) return armfault::TuneCommand(tune);
    if (*diff_cmd) return armfault::DiffCommand(diff);
    if (*report_cmd) return armfault::ReportCommand(report);
    if (*boundary_cmd) return armfault::BoundaryCommand(boundary);
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
