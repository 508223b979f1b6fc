// "Did you mean": the nearest known word to a mistyped one, for command-line errors.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "core/base/suggest.h"  // EditDistance, NearestWord (shared with the JSON readers)

namespace armfault {

// After a parse error: "did you mean ..." for an unknown subcommand or option in argv, or "".
std::string SuggestForParseError(CLI::App& app, int argc, char** argv);

}  // namespace armfault
