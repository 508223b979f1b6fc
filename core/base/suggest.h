// "Did you mean": the nearest known word to a mistyped one, for unknown keys in JSON input and
// for command-line errors (app/suggest.h).
#pragma once

#include <string>
#include <vector>

namespace armfault {

// Levenshtein distance (insertions, deletions, substitutions).
size_t EditDistance(const std::string& a, const std::string& b);

// The candidate nearest to `word`, if it is close enough to be a typo of it (at most a third
// of the word's letters edited); "" otherwise. Ties go to the first candidate.
std::string NearestWord(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace armfault
