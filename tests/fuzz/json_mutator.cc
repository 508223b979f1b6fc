// A JSON-aware mutator for libFuzzer (LLVMFuzzerCustomMutator), linked into every target.
//
// Byte-level mutation of a JSON file mostly breaks its syntax, so the parsers' checks deep
// inside a valid document (a link mass, a trajectory period, a monitor window) are rarely
// reached: two minutes of plain libFuzzer on the robot target did not find the tiny-mass abort
// at ODE's step. Three times in four this mutator parses the input (the whole text, else one
// line of it, as in a JSON Lines file), changes one value of the document and writes it back:
// a number becomes an edge value (0, -0, the smallest subnormal, 1e300, the largest double, 2^31 ...),
// is scaled by a power of ten or negated; a string becomes another string of the document or
// an edge string; a key or array element is dropped or an element repeated; any value may be
// replaced by one of another type or by a copy of another value of the document. Otherwise,
// and whenever the input does not parse, libFuzzer's own byte mutation (LLVMFuzzerMutate).
#include <cstddef>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t max_size);

namespace {

using nlohmann::json;

void Collect(json& value, std::vector<json*>* all) {
  all->push_back(&value);
  if (value.is_object() || value.is_array()) {
    for (json& item : value) Collect(item, all);
  }
}

void CollectStrings(const json& value, std::vector<std::string>* out) {
  if (value.is_string()) out->push_back(value.get<std::string>());
  if (value.is_object()) {
    for (const auto& [key, item] : value.items()) {
      out->push_back(key);
      CollectStrings(item, out);
    }
  } else if (value.is_array()) {
    for (const json& item : value) CollectStrings(item, out);
  }
}

const double kEdgeNumbers[] = {0.0,     -0.0,   5e-324, -5e-324, 1e-300, 1e-12,      1e-6,       0.5,
                               1.0,     2.0,    -1.0,   1e6,     1e12,   1e300,      -1e300,     1.7976931348623157e308,
                               -1.7976931348623157e308, 2147483647.0, 2147483648.0, -2147483649.0, 4294967296.0, 9.3e18, 1e19, 3.5};
const char* const kEdgeStrings[] = {"", " ", "x", "mrr-config1", "pendulum", "MRR1", "MRR2", "-", "/", "\x01",
                                    "../x", "csv", "hold", "sine_pair", "cosine_ramp", "min_jerk", "unknown"};

// Changes one value of `doc` in place.
void MutateDocument(json* doc, std::minstd_rand& rng) {
  std::vector<json*> nodes;
  Collect(*doc, &nodes);
  json& v = *nodes[rng() % nodes.size()];
  const unsigned op = rng() % 10;
  if (op == 0) {  // another type
    const json others[] = {nullptr, 0, "", json::array(), json::object(), true, 1e300};
    v = others[rng() % (sizeof(others) / sizeof(others[0]))];
    return;
  }
  if (op == 1) {  // a copy of another value of the document
    v = json(*nodes[rng() % nodes.size()]);
    return;
  }
  if (v.is_number()) {
    const double x = v.get<double>();
    switch (rng() % 4) {
      case 0: v = -x; break;
      case 1: v = x * std::pow(10.0, static_cast<int>(rng() % 41) - 20); break;
      case 2: v = static_cast<double>(static_cast<int>(rng() % 2001) - 1000) / 10.0; break;
      default: v = kEdgeNumbers[rng() % (sizeof(kEdgeNumbers) / sizeof(kEdgeNumbers[0]))]; break;
    }
  } else if (v.is_string()) {
    if (rng() % 2) {
      std::vector<std::string> strings;
      CollectStrings(*doc, &strings);
      v = strings[rng() % strings.size()];
    } else {
      v = kEdgeStrings[rng() % (sizeof(kEdgeStrings) / sizeof(kEdgeStrings[0]))];
    }
  } else if (v.is_boolean()) {
    v = !v.get<bool>();
  } else if (v.is_object() && !v.empty()) {
    auto it = v.begin();
    std::advance(it, rng() % v.size());
    if (rng() % 2) v.erase(it);
    else v[it.key() + "_"] = it.value();  // a misspelt key beside the real one
  } else if (v.is_array() && !v.empty()) {
    const size_t k = rng() % v.size();
    if (rng() % 2) v.erase(v.begin() + static_cast<std::ptrdiff_t>(k));
    else v.push_back(json(v[k]));
  } else {
    v = kEdgeNumbers[rng() % (sizeof(kEdgeNumbers) / sizeof(kEdgeNumbers[0]))];
  }
}

bool Parse(const std::string& text, json* out) {
  try {
    *out = json::parse(text, nullptr, /*allow_exceptions=*/false);
  } catch (const std::exception&) {
    return false;
  }
  return !out->is_discarded();
}

}  // namespace

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t max_size, unsigned int seed) {
  std::minstd_rand rng(seed);
  if (rng() % 4 != 0) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    std::string result;
    json doc;
    if (Parse(text, &doc)) {
      MutateDocument(&doc, rng);
      result = doc.dump(rng() % 2 ? -1 : 1);
    } else {
      // JSON Lines: one line that parses, changed, the others as they are.
      std::vector<std::string> lines;
      std::istringstream in(text);
      for (std::string line; std::getline(in, line);) lines.push_back(line);
      if (!lines.empty()) {
        const size_t k = rng() % lines.size();
        if (Parse(lines[k], &doc)) {
          MutateDocument(&doc, rng);
          lines[k] = doc.dump();
          for (const std::string& line : lines) result += line + "\n";
        }
      }
    }
    if (!result.empty() && result.size() <= max_size) {
      std::memcpy(data, result.data(), result.size());
      return result.size();
    }
  }
  return LLVMFuzzerMutate(data, size, max_size);
}
