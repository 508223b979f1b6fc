// `armfault import LOG... --map MAP.json -o DIR`: recorded logs into an export's layout
// (campaigns/data/import.h, docs/import.md).
#include <chrono>
#include <cstdio>

#include "app/commands/commands.h"
#include "campaigns/data/import.h"

namespace armfault {

int ImportCommand(const ImportCommandOptions& o) {
  const ImportMap map = ReadImportMap(o.map_file);
  const auto start = std::chrono::steady_clock::now();
  const ImportResult r = ImportLogs(o.logs, map, {o.output_dir, nullptr});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("imported %ld runs (%ld rows, %ld control ticks, longest %.3f s) from %zu logs -> %s/manifest.jsonl, "
              "manifest.csv, runs/*.csv.gz\n",
              r.runs, r.rows, r.ticks, r.max_end_s, o.logs.size(), o.output_dir.c_str());
  if (!o.quiet) {
    std::fprintf(stderr, "import: %.3f s, %.0f rows/s\n", seconds, seconds > 0 ? static_cast<double>(r.rows) / seconds : 0.0);
    std::printf("next: armfault score %s VERDICTS.jsonl  (scores verdicts your detector wrote on these runs)\n",
                o.output_dir.c_str());
  }
  return 0;
}

}  // namespace armfault
