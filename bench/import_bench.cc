// `armfault import` speed (at least a million rows a second). A synthetic log in the
// stand-in layout (tests/campaigns/data/import_standin.py): 1 kHz with jitter, time in ms, three
// joints with six mapped columns each (degrees, deg/s, mN m, mA) and a text column, 19 numbers
// parsed per row, resampled to 500 Hz and written as runs/000000.csv.gz.
//   build/armfault_import_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
// Counters: rows/s of wall time (items_per_second, real time), and rows per second of the
// whole process's CPU time (rows_per_cpu_s: the parse on the calling thread plus the deflate
// threads). On n free cores the wall rate is about min(n * rows_per_cpu_s, the calling
// thread's rate, rows_per_main_cpu_s). Figures: docs/import.md, "Speed".
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "campaigns/data/import.h"
#include "core/base/json_input.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;
constexpr long kRows = 200000;

double ProcessCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// The log and the import's output, removed at exit.
struct WorkDir {
  fs::path path;
  ~WorkDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

const fs::path& Work() {
  static const WorkDir dir{[] {
    const fs::path d = fs::temp_directory_path() / ("armfault_import_bench." + std::to_string(::getpid()));
    fs::create_directories(d);
    std::FILE* f = std::fopen((d / "log.csv").c_str(), "w");
    std::string header = "mode,time_ms";
    const char* names[] = {"pos_deg", "ref_deg", "vel_dps", "torque_mNm", "icmd_mA", "isup_mA"};
    for (int j = 1; j <= 3; ++j) {
      for (const char* n : names) header += ",J" + std::to_string(j) + "_" + n;
    }
    std::fprintf(f, "%s\n", header.c_str());
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> jitter(-0.2, 0.2), noise(-1, 1);
    for (long i = 0; i < kRows; ++i) {
      const double t = 86400000.0 + static_cast<double>(i) + (i ? jitter(rng) : 0.0);
      std::fprintf(f, "auto,%.4f", t);
      for (int j = 1; j <= 3; ++j) {
        const double ph = i * 0.001 * 1.27 + j;
        std::fprintf(f, ",%.6g,%.6g,%.6g,%.6g,%.6g,%.6g", 25 * std::sin(ph), 25 * std::sin(ph + 0.01), 31.75 * std::cos(ph),
                     300 * noise(rng), 500 * noise(rng), 30 + 5 * noise(rng));
      }
      std::fprintf(f, "\n");
    }
    std::fclose(f);
    return d;
  }()};
  return dir.path;
}

ImportMap BenchMap() {
  nlohmann::json joints;
  const char* fields[][3] = {{"q_meas_rad", "pos_deg", "deg"},   {"q_ref_rad", "ref_deg", "deg"},
                             {"qd_est_rad_s", "vel_dps", "deg/s"}, {"tau_sensor_Nm", "torque_mNm", "mN m"},
                             {"i_cmd_A", "icmd_mA", "mA"},       {"i_supply_meas_A", "isup_mA", "mA"}};
  for (int j = 1; j <= 3; ++j) {
    for (const auto& f : fields) {
      joints[std::to_string(j)][f[0]] = {{"column", "J" + std::to_string(j) + "_" + f[1]}, {"unit", f[2]}};
    }
  }
  const nlohmann::json m = {{"robot", "mrr-config1"}, {"time", {{"column", "time_ms"}, {"unit", "ms"}}}, {"joints", joints}};
  ImportMap map = ImportMapFromJson(m, "<bench>", ".");
  ValidateImportMap(map);
  return map;
}

void BM_Import(benchmark::State& state) {
  const fs::path& dir = Work();
  const ImportMap map = BenchMap();
  double cpu = 0;
  for (auto _ : state) {
    fs::remove_all(dir / "out");
    const double c0 = ProcessCpuSeconds();
    const ImportResult r = ImportLogs({(dir / "log.csv").string()}, map, {(dir / "out").string(), nullptr});
    cpu += ProcessCpuSeconds() - c0;
    benchmark::DoNotOptimize(r.ticks);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kRows);
  state.counters["rows_per_cpu_s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kRows / cpu);
}
BENCHMARK(BM_Import)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace armfault

BENCHMARK_MAIN();
