#include "core/base/suggest.h"

#include <algorithm>

namespace armfault {

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string NearestWord(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_distance = 0;
  for (const std::string& c : candidates) {
    const size_t d = EditDistance(word, c);
    if (best.empty() || d < best_distance) best = c, best_distance = d;
  }
  const size_t allowed = std::max<size_t>(1, (word.size() + 2) / 3);
  return !best.empty() && best_distance <= allowed ? best : std::string();
}

std::string NearestId(const std::string& id, const std::vector<std::string>& ids) {
  size_t best_prefix = 0;
  std::vector<const std::string*> candidates;
  for (const std::string& c : ids) {
    const size_t prefix = static_cast<size_t>(std::mismatch(id.begin(), id.end(), c.begin(), c.end()).first - id.begin());
    if (prefix > best_prefix) {
      best_prefix = prefix;
      candidates.clear();
    }
    if (prefix == best_prefix && candidates.size() < 1000) candidates.push_back(&c);
  }
  const std::string* best = nullptr;
  size_t best_distance = 0;
  for (const std::string* c : candidates) {
    const size_t d = EditDistance(id, *c);
    if (!best || d < best_distance) best = c, best_distance = d;
  }
  return best ? *best : std::string();
}

}  // namespace armfault
