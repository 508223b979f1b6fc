// "Did you mean": the nearest known word to a mistyped one, for command-line errors.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace armfault {

// Levenshtein distance (insertions, deletions, substitutions).
size_t EditDistance(const std::string& a, const std::string& b);

// The candidate nearest to `word`, if it is close enough to be a typo of it (at most a third
// of the word's letters edited); "" otherwise.
std::string NearestWord(const std::string& word, const std::vector<std::string>& candidates);

// After a parse error: "did you mean ..." for an unknown subcommand or option in argv, or "".
std::string SuggestForParseError(CLI::App& app, int argc, char** argv);

}  // namespace armfault
