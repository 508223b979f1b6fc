// The writer of an imported run's signals: a gzip CSV formatted and deflated in blocks by
// worker threads while the log is parsed (RunWriter).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace armfault::import_detail {

// A gzip CSV of a run's signals written into the temporary directory. The parse hands over
// ticks as numbers, kBlockTicks at a time; each block is formatted and deflated on its own, as
// one gzip member, by one of kWorkers threads while the next blocks are parsed, and the members
// are written in order (a gzip file of several members is one stream to zlib's gzread,
// Python's gzip and pandas). Formatting and deflate are about two thirds of an import's CPU
// time; so the parse and the workers share the cores. Deflate by ISA-L's igzip at its level 2:
// on these digits 4x zlib's Huffman-only speed and 1.8x libdeflate's level 1, files within
// 2 % of theirs (docs/import.md, "Speed"). Any error of a worker is thrown by the next Submit()
// or by Close().
class RunWriter {
 public:
  // `columns` numbers a tick: t_s (written exact), then the signals (NaN: an empty cell).
  RunWriter(const std::filesystem::path& path, std::string header, size_t columns);
  ~RunWriter();
  // Room for one tick's numbers at the end of the block.
  double* AddTick() {
    block_.resize(block_.size() + columns_);
    return block_.data() + block_.size() - columns_;
  }
  void MaybeFlush() {
    if (block_.size() >= kBlockTicks * columns_) Submit();
  }
  void Close();

 private:
  static constexpr size_t kBlockTicks = 4096;  // about 1 MB of text for three joints
  static constexpr int kWorkers = 2;
  static constexpr size_t kQueued = 6;  // blocks queued or deflated, not yet written: bounded memory
  struct Job {
    long index = 0;
    std::vector<double> ticks;
  };
  void Submit();
  void Stop();
  // One block's CSV text (the header first, in the first block) into `text`, grown as needed
  // and never zero-filled; returns its length.
  size_t Format(const Job& job, std::unique_ptr<char[]>* text, size_t* capacity) const;
  // `size` bytes of `text` as one gzip member into `out` (grown as needed); its length, or 0 if
  // ISA-L fails.
  static size_t Deflate(const char* text, size_t size, std::vector<uint8_t>* level_buffer, std::unique_ptr<uint8_t[]>* out,
                        size_t* capacity);
  // A worker thread: formats and deflates blocks, and writes the members that are next in order.
  void Work();

  std::filesystem::path path_;
  size_t columns_;
  std::string header_;
  std::FILE* file_ = nullptr;
  std::vector<double> block_;
  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<Job> queue_;
  std::vector<std::vector<double>> spare_;  // blocks formatted, their memory kept
  std::map<long, std::string> deflated_;
  long submitted_ = 0, written_ = 0;
  size_t in_flight_ = 0;
  bool done_ = false;
  std::exception_ptr error_;
  std::vector<std::thread> threads_;
};

}  // namespace armfault::import_detail
