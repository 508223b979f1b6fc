// Shared by the libFuzzer targets of tests/fuzz (docs/fuzzing.md). Each target takes arbitrary
// bytes as the text of one input file, parses it as armfault does, and returns 0 when the
// input is rejected with an InputError (the clean rejection a user sees as exit status 2).
// Anything else that escapes (another exception, an abort inside ODE, a sanitizer report) is a
// crash for libFuzzer: the bug class this fuzzing is for.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "core/base/json_input.h"

namespace armfault::fuzz {

// The source name every target gives its input (errors read "fuzz-input: /pointer: ...").
inline const char* const kSource = "fuzz-input";
// A base directory no file can be under (/dev/null is not a directory), so a relative path in
// an input (a csv trajectory, a monitor file) names nothing; absolute paths are still read.
inline const char* const kNoDir = "/dev/null/fuzz";

inline std::string Text(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// True when any key or string in `value` mentions "plugin": such an input may name a shared
// library, and a monitor of type "plugin" loads it (dlopen runs its constructors). The
// targets skip these inputs, so the fuzzer never runs code it found on the disk.
inline bool MentionsPlugin(const nlohmann::json& value) {
  if (value.is_string()) return value.get_ref<const std::string&>().find("plugin") != std::string::npos;
  if (value.is_object()) {
    for (const auto& [key, item] : value.items()) {
      if (key.find("plugin") != std::string::npos || MentionsPlugin(item)) return true;
    }
  }
  if (value.is_array()) {
    for (const auto& item : value) {
      if (MentionsPlugin(item)) return true;
    }
  }
  return false;
}

// Runs `body`; an InputError is the desired rejection and ends the input quietly.
template <class F>
int RejectCleanly(F&& body) {
  try {
    body();
  } catch (const InputError&) {
  }
  return 0;
}

// Where a target's input file "is": relative paths in it name nothing (kNoDir).
inline InputContext Context() {
  InputContext input;
  input.source = kSource;
  input.base_dir = kNoDir;
  return input;
}

}  // namespace armfault::fuzz
