// Joins the output directories of `armfault run --shard K/N` (K = 0 .. N-1) into one
// directory that holds what an unsharded run writes: campaign.json (shard 0/1), and
// results.jsonl and decisions.jsonl with every line in case order, each copied byte for byte
// (keys this version does not know pass through). A shard of an older armfault, without
// decisions.jsonl, has its decisions inline in results.jsonl: they are written out to
// decisions.jsonl as the runner writes them. The caller writes summary.json and junit.xml.
//
// Checks, each an InputError (exit status 2):
//   - every input has campaign.json with the same version (this binary's), the same resolved
//     campaign and case count, and the same shard count N;
//   - the shards given are exactly 0 .. N-1, each once (the message names the missing or
//     repeated ones);
//   - every shard is complete: as many lines in results.jsonl as it has cases, the last one
//     ending in a newline (the message names the directory, how many runs are missing, and
//     the `--resume` command that finishes it);
//   - its decisions.jsonl goes with its results.jsonl: as many complete lines, each of the
//     same case and run_id (or, without the file, every results line carries "decision");
//     the message names the file and the line;
//   - every line is valid JSON whose "case" is the next one expected.
// Memory: two open files and one line of each per shard, whatever the number of runs.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "campaigns/spec/campaign_spec.h"

namespace armfault {

struct MergeResult {
  CampaignSpec campaign;  // for scoring: name, floors and the resolved campaign (see merge.cc)
  int shards = 0;     // N
  long runs = 0;      // lines written to results.jsonl and decisions.jsonl (= the campaign's case count)
};

// Merges `input_dirs` (in any order) into `output_dir` (created if missing; must not be one
// of the inputs). Writes output_dir/campaign.json, results.jsonl and decisions.jsonl, the
// last two through temporary files so a failed merge leaves no partial results behind.
MergeResult MergeShards(const std::vector<std::string>& input_dirs, const std::string& output_dir);

}  // namespace armfault
