// The one parallel loop of the commands that run or replay many runs (runner, export, replay):
// items made in parallel on a oneTBB arena, handed on in the order they were asked for, one at a
// time, so what is written is the same bytes for any thread count.
#pragma once

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <cstddef>
#include <optional>
#include <type_traits>
#include <utility>

namespace armfault {

// Runs, on `threads` threads (0: every core) with up to 4 items per thread in flight:
//   next()     serially, in order: the next item's key, or nullopt to stop asking;
//   make(key)  in parallel: the item of a key;
//   write(item) serially, in the order of the keys.
// An exception from any of the three stops the loop and is rethrown here.
template <class Next, class Make, class Write>
void RunOrderedPipeline(int threads, Next&& next, Make&& make, Write&& write) {
  using Key = typename std::invoke_result_t<Next&>::value_type;
  using Item = std::invoke_result_t<Make&, Key>;
  const int n = threads > 0 ? threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(n);
  arena.execute([&] {
    tbb::parallel_pipeline(static_cast<size_t>(4 * n),
                           tbb::make_filter<void, Key>(tbb::filter_mode::serial_in_order,
                                                       [&](tbb::flow_control& fc) -> Key {
                                                         std::optional<Key> key = next();
                                                         if (!key) {
                                                           fc.stop();
                                                           return Key{};
                                                         }
                                                         return std::move(*key);
                                                       }) &
                               tbb::make_filter<Key, Item>(tbb::filter_mode::parallel, make) &
                               tbb::make_filter<Item, void>(tbb::filter_mode::serial_in_order, write));
  });
}

}  // namespace armfault
