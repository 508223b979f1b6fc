#include "reports/statistics_csv.h"

#include <charconv>
#include <cmath>

#include "core/base/csv.h"

namespace armfault {

namespace {

// Shortest text that reads back to the same double.
void AppendNumber(std::string* line, double x) {
  char buffer[32];
  auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
  line->append(buffer, result.ptr);
}

}  // namespace

std::vector<std::string> StatisticsCsvColumns() {
  return {"t_s", "joint", "statistic", "family", "value", "threshold", "above"};
}

StatisticsCsvWriter::StatisticsCsvWriter(std::function<void(std::string_view)> sink) : sink_(std::move(sink)) {}

void StatisticsCsvWriter::Declare(const std::vector<PublishedStatistic>& statistics, int joints) {
  statistics_ = statistics;
  joints_ = joints;
  fixed_.clear();
  thresholds_.clear();
  for (const PublishedStatistic& s : statistics_) {
    fixed_.push_back("," + CsvText(s.name) + "," + CsvText(s.family) + ",");
    std::string t;
    AppendNumber(&t, s.threshold);
    thresholds_.push_back(std::move(t));
  }
  if (!header_written_) {
    std::string header;
    for (const std::string& c : StatisticsCsvColumns()) header += (header.empty() ? "" : ",") + c;
    sink_(header + "\n");
    header_written_ = true;
  }
}

void StatisticsCsvWriter::Values(double t_s, const double* values) {
  if (statistics_.empty()) return;
  std::string time;
  AppendNumber(&time, t_s);
  line_.clear();
  const size_t count = statistics_.size();
  for (int j = 0; j < joints_; ++j) {
    for (size_t s = 0; s < count; ++s) {
      const double v = values[static_cast<size_t>(j) * count + s];
      line_ += time;
      line_ += ',';
      line_ += std::to_string(j + 1);
      line_ += fixed_[s];
      const bool has = !std::isnan(v);
      if (has) AppendNumber(&line_, v);
      line_ += ',';
      line_ += thresholds_[s];
      line_ += ',';
      if (has) {
        const double t = statistics_[s].threshold;
        line_ += (statistics_[s].inclusive ? v >= t : v > t) ? '1' : '0';
      }
      line_ += '\n';
    }
  }
  sink_(line_);
}

}  // namespace armfault
