// RunWriter (import_run_writer.h): the block formatting of a run's CSV, its deflate by ISA-L's
// igzip, the worker threads and the in-order writing of the gzip members.
#include "campaigns/data/import_run_writer.h"

#include <isa-l/igzip_lib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <new>

#include "core/base/csv.h"
#include "core/base/json_input.h"
#include "core/base/output_file.h"

namespace armfault::import_detail {

namespace fs = std::filesystem;

namespace {

// Significant digits of a resampled signal value in the runs' CSV (docs/import.md,
// "Resampling"): a relative rounding of at most 5e-10, far below any joint sensor's resolution
// (a 24-bit encoder's count is 6e-8 of a turn), where the exact 17 digits of an interpolated
// double would carry nothing of the log and cost the formatting and the deflate twice as much.
constexpr int kValueDigits = 10;

}  // namespace

RunWriter::RunWriter(const fs::path& path, std::string header, size_t columns)
    : path_(path), columns_(columns), header_(std::move(header)) {
  file_ = OpenForWriting(path_, "wb");
  block_.reserve(kBlockTicks * columns_);
  for (int i = 0; i < kWorkers; ++i) threads_.emplace_back([this] { Work(); });
}

RunWriter::~RunWriter() {
  Stop();
  if (file_) std::fclose(file_);
}

void RunWriter::Close() {
  Submit();
  Stop();
  if (error_) std::rethrow_exception(error_);
  std::FILE* f = file_;
  file_ = nullptr;
  CloseChecked(f, path_);
}

void RunWriter::Submit() {
  if (block_.empty() && submitted_ > 0) return;
  std::unique_lock<std::mutex> lock(mutex_);
  space_.wait(lock, [&] { return in_flight_ < kQueued || error_; });
  if (error_) std::rethrow_exception(error_);
  queue_.push_back(Job{submitted_++, std::move(block_)});
  ++in_flight_;
  if (!spare_.empty()) {
    block_ = std::move(spare_.back());
    spare_.pop_back();
  } else {
    block_ = std::vector<double>();
    block_.reserve(kBlockTicks * columns_);
  }
  ready_.notify_one();
}

void RunWriter::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  ready_.notify_all();
  for (std::thread& t : threads_) t.join();
  threads_.clear();
}

size_t RunWriter::Format(const Job& job, std::unique_ptr<char[]>* text, size_t* capacity) const {
  const size_t ticks = job.ticks.size() / columns_;
  const size_t bound = header_.size() + ticks * columns_ * 26;  // a number is at most 24 characters and a comma
  if (*capacity < bound) {
    text->reset(new char[bound]);
    *capacity = bound;
  }
  char* p = text->get();
  char* const end = p + bound;
  if (job.index == 0) p = std::copy(header_.begin(), header_.end(), p);
  const double* x = job.ticks.data();
  for (size_t k = 0; k < ticks; ++k) {
    p = std::to_chars(p, end, x[0]).ptr;  // t_s: the control clock, exact
    for (size_t c = 1; c < columns_; ++c) {
      *p++ = ',';
      if (!std::isnan(x[c])) p = FormatGeneral(p, end, x[c], kValueDigits);
    }
    *p++ = '\n';
    x += columns_;
  }
  return static_cast<size_t>(p - text->get());
}

size_t RunWriter::Deflate(const char* text, size_t size, std::vector<uint8_t>* level_buffer, std::unique_ptr<uint8_t[]>* out,
                          size_t* capacity) {
  isal_zstream z;
  isal_deflate_init(&z);
  z.level = 2;
  z.level_buf = level_buffer->data();
  z.level_buf_size = static_cast<uint32_t>(level_buffer->size());
  z.gzip_flag = IGZIP_GZIP;
  z.end_of_stream = 1;
  z.flush = NO_FLUSH;
  z.next_in = reinterpret_cast<uint8_t*>(const_cast<char*>(text));
  z.avail_in = static_cast<uint32_t>(size);
  const size_t want = size + size / 8 + 1024;
  if (*capacity < want) {
    out->reset(new uint8_t[want]);
    *capacity = want;
  }
  z.next_out = out->get();
  z.avail_out = static_cast<uint32_t>(*capacity);
  // Deflate's worst case (stored blocks) is 5 bytes a 64 kB block over the text: room enough.
  if (isal_deflate(&z) != COMP_OK || z.internal_state.state != ZSTATE_END) return 0;
  return *capacity - z.avail_out;
}

void RunWriter::Work() {
  std::vector<uint8_t> level_buffer;
  std::unique_ptr<char[]> text;
  std::unique_ptr<uint8_t[]> out;
  size_t text_capacity = 0, out_capacity = 0;
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      ready_.wait(lock, [&] { return !queue_.empty() || done_; });
      if (queue_.empty()) break;
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    std::exception_ptr error;
    std::string member;
    try {
      level_buffer.resize(ISAL_DEF_LVL2_DEFAULT);
      const size_t size = Format(job, &text, &text_capacity);
      const size_t deflated = Deflate(text.get(), size, &level_buffer, &out, &out_capacity);
      if (deflated == 0) throw std::bad_alloc();
      member.assign(reinterpret_cast<const char*>(out.get()), deflated);
    } catch (...) {
      error = std::make_exception_ptr(InputError(path_.string(), "", "cannot write: deflate failed (out of memory?)"));
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (error && !error_) error_ = error;
    job.ticks.clear();
    spare_.push_back(std::move(job.ticks));  // for the parse's next block: no fresh pages
    deflated_.emplace(job.index, std::move(member));
    // Whoever holds the next member in order writes it (and any that follow, ready).
    try {
      for (auto it = deflated_.find(written_); it != deflated_.end(); it = deflated_.find(written_)) {
        if (!error_) WriteChecked(file_, it->second, path_);
        deflated_.erase(it);
        ++written_;
        --in_flight_;
      }
    } catch (...) {
      if (!error_) error_ = std::current_exception();
    }
    space_.notify_all();
  }
}

}  // namespace armfault::import_detail
