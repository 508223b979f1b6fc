// What the monitor under test costs: per run, the time of its Observe() calls per
// tick (mean, median, 99th percentile, maximum) and of Finish(), written to monitor_cost.jsonl
// beside results.jsonl; per campaign, their aggregate, the heap one monitor instance holds at
// most over a run, and the optional floor "monitor_us_per_tick" (monitor_cost.json).
//
// These are measurements of this machine at this moment, so they live in files of their own:
// results.jsonl, decisions.jsonl, summary.json and junit.xml stay bit-identical for any thread
// count or shard split. Times are wall time (steady_clock) around each call on the run's own
// thread, which a loaded machine inflates (the 99th percentile first); the heap is glibc's
// allocated bytes (mallinfo2: in-use chunks plus mmapped blocks) while one monitor runs alone in
// the loop of the first case's plant, before or after the parallel runs, so nothing else
// allocates meanwhile; sampled at a few ticks (1, 2, 4, ..., then every 512th) so the probe
// costs the same per simulated second however long the run.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "campaigns/spec/campaign.h"
#include "campaigns/running/monitor_clock.h"
#include "campaigns/running/run_dir.h"

namespace armfault {

// The simulated time ProbeMonitorHeapBytes watches at most [s] (docs/campaign-format.md).
inline constexpr double kHeapProbeSpan_s = 600;

// The most heap (bytes) one fresh monitor of the campaign holds, at the sampled ticks, while it
// observes the campaign's first case in the plant's loop, above what the process held before it
// was made; nullopt when the monitor fails on it. Simulates that case once (its first
// kHeapProbeSpan_s). Call with no other thread allocating.
std::optional<double> ProbeMonitorHeapBytes(const Campaign& campaign);

// monitor_cost.json from a run directory's monitor_cost.jsonl (lines of ok runs): the mean over
// every tick of every run (total time / total ticks), the median and the largest of the runs'
// medians and 99th percentiles, the largest single tick, the runs and ticks counted, the heap
// (`heap_bytes`, null when not measured) and, with a floor, its verdict
// {"bound", "measured", "met", "message"}. Throws InputError naming the file and line on a bad
// line.
nlohmann::json SummarizeMonitorCost(const std::filesystem::path& cost_path, std::optional<double> heap_bytes,
                                    std::optional<double> floor_us_per_tick, const std::string& monitor_type);

// `merge`: the shards' monitor_cost.jsonl joined in case order (shard K holds cases K, K + N, ...:
// one line from each in turn, streamed) into `out`; returns what monitor_cost.json is made of
// (campaigns/running/run_dir.h, the table's row) with the largest heap the shards measured. When
// a shard has no monitor_cost.jsonl (one run with --summary-only), writes nothing, removes a
// stale monitor_cost.jsonl and monitor_cost.json from `out`, and returns `write` false.
MonitorCostInput JoinShardMonitorCost(const std::vector<std::string>& shard_dirs, const std::filesystem::path& out);

}  // namespace armfault
