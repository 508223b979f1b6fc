#include "campaigns/running/monitor_cost.h"

#include "core/base/output_file.h"

#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "campaigns/running/run_dir.h"
#include "campaigns/running/run_pipeline.h"
#include "core/base/json_input.h"

namespace armfault {

namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

// Bytes the process holds on the heap now. A sanitizer build (tools/sanitizers.sh) replaces
// malloc, and glibc's mallinfo2 then reads 0, so it asks the sanitizer's allocator instead.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define ARMFAULT_SANITIZER_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define ARMFAULT_SANITIZER_ALLOCATOR 1
#endif
#endif
#ifdef ARMFAULT_SANITIZER_ALLOCATOR
extern "C" size_t __sanitizer_get_current_allocated_bytes();
double HeapBytes() { return static_cast<double>(__sanitizer_get_current_allocated_bytes()); }
#else
double HeapBytes() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks + m.hblkhd);
}
#endif

}  // namespace

std::optional<double> ProbeMonitorHeapBytes(const Campaign& campaign) {
  if (CaseCount(campaign) == 0) return std::nullopt;
  try {
    PreparedRun prepared = PrepareCase(campaign, CaseAt(campaign, 0), nullptr);
    if (!prepared.model) return std::nullopt;  // its unit's commissioning failed: the run's record says why
    // The first kHeapProbeSpan_s of the case: a monitor's state is bounded, so its
    // heap has levelled out by then, and the probe adds at most that much simulation to `run`.
    prepared.spec.duration_s = std::min(prepared.spec.duration_s, kHeapProbeSpan_s);
    // The monitor alone in the plant's loop (no tap, no effect meters, no clock). Its heap is
    // what the process holds above the baseline taken before it is made, at the second tick:
    // the plant makes its buffers (ODE's step arena) in its first period and reuses them, so at
    // each later tick's observer it holds the same heap and the difference is the monitor's.
    // The first tick's signals are kept and given to the monitor first. Sampled at ticks 1, 2,
    // 4, ... and then every kEvery ticks and at the end: the probe's cost per tick stays flat in
    // the run's length (mallinfo2 walks the allocator's bins; calling it every tick cost 13 % of
    // a run).
    constexpr long kEvery = 512;
    std::unique_ptr<HealthMonitor> monitor;
    double before = 0, peak = 0;
    long seen = 0;
    double first_t = 0, last_t = 0;
    std::vector<JointSignals> first, signals;
    auto start = [&] {
      before = HeapBytes();
      monitor = campaign.monitor_model->NewMonitor();
      monitor->KeepWindows(false);  // as in a campaign's runs
      monitor->Observe(first_t, first);
      peak = std::max(before, HeapBytes());
    };
    Simulate(*prepared.model, prepared.spec, [&](const Tick& tick) {
      last_t = tick.t_s;
      if (seen++ == 0) {
        first.resize(tick.joints->size());
        for (size_t j = 0; j < first.size(); ++j) first[j] = (*tick.joints)[j].signals;
        first_t = tick.t_s;
        signals.resize(first.size());
        return;
      }
      if (!monitor) start();
      for (size_t j = 0; j < signals.size(); ++j) signals[j] = (*tick.joints)[j].signals;
      monitor->Observe(tick.t_s, signals);
      if ((seen & (seen - 1)) == 0 || seen % kEvery == 0) peak = std::max(peak, HeapBytes());
    });
    if (seen == 0) return std::nullopt;
    if (!monitor) start();
    peak = std::max(peak, HeapBytes());
    monitor->Finish(last_t);
    peak = std::max(peak, HeapBytes());
    return peak - before;
  } catch (const std::exception&) {
    return std::nullopt;  // the run's own record says why
  }
}

nlohmann::json SummarizeMonitorCost(const std::filesystem::path& cost_path, std::optional<double> heap_bytes,
                                    std::optional<double> floor_us_per_tick, const std::string& monitor_type) {
  std::ifstream in(cost_path, std::ios::binary);
  double total_us = 0, max_us = 0;
  long ticks = 0, runs = 0;
  std::vector<double> medians, p99s;
  std::string line;
  long n = 0;
  while (std::getline(in, line)) {
    ++n;
    try {
      const nlohmann::json j = nlohmann::json::parse(line);
      const long t = j.at("ticks").get<long>();
      if (t == 0) continue;
      ++runs;
      ticks += t;
      total_us += j.at("mean_us").get<double>() * static_cast<double>(t);
      medians.push_back(j.at("median_us").get<double>());
      p99s.push_back(j.at("p99_us").get<double>());
      max_us = std::max(max_us, j.at("max_us").get<double>());
    } catch (const std::exception& e) {
      throw InputError(cost_path.string(), "", "line " + std::to_string(n) + ": " + e.what());
    }
  }
  nlohmann::json out = {{"monitor", monitor_type}, {"runs", runs}, {"ticks", ticks}};
  const double mean = ticks > 0 ? total_us / static_cast<double>(ticks) : 0.0;
  out["mean_us_per_tick"] = ticks > 0 ? nlohmann::json(RoundedUs(mean)) : nlohmann::json(nullptr);
  out["median_of_run_medians_us"] = runs > 0 ? nlohmann::json(RoundedUs(Median(medians))) : nlohmann::json(nullptr);
  out["max_of_run_medians_us"] = runs > 0 ? nlohmann::json(*std::max_element(medians.begin(), medians.end())) : nlohmann::json(nullptr);
  out["median_of_run_p99s_us"] = runs > 0 ? nlohmann::json(RoundedUs(Median(p99s))) : nlohmann::json(nullptr);
  out["max_of_run_p99s_us"] = runs > 0 ? nlohmann::json(*std::max_element(p99s.begin(), p99s.end())) : nlohmann::json(nullptr);
  out["max_tick_us"] = runs > 0 ? nlohmann::json(max_us) : nlohmann::json(nullptr);
  out["heap_bytes"] = heap_bytes ? nlohmann::json(*heap_bytes) : nlohmann::json(nullptr);
  if (floor_us_per_tick) {
    char message[200];
    const bool met = ticks > 0 && mean <= *floor_us_per_tick;
    if (ticks == 0) {
      std::snprintf(message, sizeof message, "monitor_us_per_tick: no ticks measured, nothing to measure (floor <= %.3f)",
                    *floor_us_per_tick);
    } else {
      std::snprintf(message, sizeof message, "monitor_us_per_tick %.3f %s %.3f (mean over %ld ticks of %ld runs)", mean,
                    met ? "<=" : ">", *floor_us_per_tick, ticks, runs);
    }
    out["floor"] = {{"bound", *floor_us_per_tick},
                    {"measured", ticks > 0 ? nlohmann::json(RoundedUs(mean)) : nlohmann::json(nullptr)},
                    {"met", met},
                    {"message", message}};
  }
  return out;
}

MonitorCostInput JoinShardMonitorCost(const std::vector<std::string>& shard_dirs, const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  std::vector<std::unique_ptr<std::ifstream>> inputs;
  std::optional<double> heap;
  for (const std::string& dir : shard_dirs) {
    const fs::path lines = fs::path(dir) / "monitor_cost.jsonl";
    if (!fs::exists(lines)) {
      std::error_code ec;
      fs::remove(out / "monitor_cost.jsonl", ec);
      fs::remove(out / "monitor_cost.json", ec);
      return {};
    }
    inputs.push_back(std::make_unique<std::ifstream>(lines, std::ios::binary));
    if (const fs::path summary = fs::path(dir) / "monitor_cost.json"; fs::exists(summary)) {
      const nlohmann::json j = ReadJsonFile(summary.string());
      if (j.contains("heap_bytes") && j["heap_bytes"].is_number()) {
        heap = std::max(heap.value_or(0.0), j["heap_bytes"].get<double>());
      }
    }
  }
  AtomicOutputFile merged(out / "monitor_cost.jsonl");
  for (bool more = true; more;) {
    more = false;
    for (auto& in : inputs) {
      std::string line;
      if (!std::getline(*in, line)) continue;
      merged.Write(line + '\n');
      more = true;
    }
  }
  merged.Commit();
  return {true, heap};
}

}  // namespace armfault
