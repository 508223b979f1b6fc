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

// The id nearest to `id` among `ids` (run_ids: long, many, and alike but for a value or a
// repetition near the end): among the ids sharing the longest prefix with it, the one with the
// fewest edits (ties: the first). Always one of `ids` ("" only when there are none), however
// far: a wrong id is named with its nearest. Bounded work for millions of ids: one prefix
// comparison each, then edit distances to at most 1000 of them.
std::string NearestId(const std::string& id, const std::vector<std::string>& ids);

}  // namespace armfault
