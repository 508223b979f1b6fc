// `armfault export` against `armfault run` on the same runs (export as fast as run),
// one thread: every 26th case of campaigns/files/five-families.json (8 runs of 10 s, mrr-config1,
// 5001 ticks x 3 joints each), run as `run` runs them (RunCase: the monitor in the loop, its
// record) and exported as `export` writes them (ExportCampaign: no monitor, runs/*.csv.gz at
// zlib level 6, the default, and at 1).
//   build/armfault_export_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
// Goal: export at the default level within 1.7x of run (the rest is zlib's deflate at level 6,
// which the exported bytes fix; measured 1.54x), at --gzip-level 1 within 1.2x (measured 1.13x).
// Figures: docs/monitor-api.md, "Export and score".
#include <benchmark/benchmark.h>

#include <filesystem>

#include "campaigns/spec/campaign.h"
#include "campaigns/data/export.h"
#include "campaigns/running/run_pipeline.h"
#include "campaigns/running/runner.h"

namespace armfault {
namespace {

constexpr ShardSpec kShard{0, 26};

const Campaign& FiveFamilies() {
  static const Campaign c = ReadCampaignFile(std::string(ARMFAULT_SOURCE_DIR) + "/campaigns/files/five-families.json");
  return c;
}

void BM_Run(benchmark::State& state) {
  const Campaign& c = FiveFamilies();
  const long n = kShard.Size(CaseCount(c));
  for (auto _ : state) {
    UnitMonitors units(c);
    for (long k = 0; k < n; ++k) {
      const RunRecord r = RunCase(c, CaseAt(c, kShard.CaseIndex(k)), nullptr, &units);
      if (!r.ok) state.SkipWithError(r.failure_reason.c_str());
      benchmark::DoNotOptimize(r.detected);
    }
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));  // runs
}
BENCHMARK(BM_Run)->Unit(benchmark::kMillisecond)->UseRealTime();

// Arg: the gzip level.
void BM_Export(benchmark::State& state) {
  const Campaign& c = FiveFamilies();
  ExportOptions o;
  o.output_dir = (std::filesystem::temp_directory_path() / "armfault_export_bench").string();
  o.threads = 1;
  o.shard = kShard;
  o.gzip_level = static_cast<int>(state.range(0));
  long runs = 0;
  for (auto _ : state) {
    const ExportResult r = ExportCampaign(c, o);
    if (r.failed) state.SkipWithError("a run failed");
    runs += r.runs;
  }
  std::filesystem::remove_all(o.output_dir);
  state.SetItemsProcessed(runs);
}
BENCHMARK(BM_Export)->Arg(kDefaultGzipLevel)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace armfault

BENCHMARK_MAIN();
