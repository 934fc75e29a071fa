// The word a person probably meant: a misspelt command, option or log column is suggested
// back ("--maping": did you mean '--mapping'?).
#pragma once
#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "output/ascii.hpp"
#include "output/sinks.hpp"

namespace quadgen::output {

// Edits (insert, delete, replace) between two words, counted up to `limit`: any number above
// it reads limit + 1. Only cells within `limit` of the diagonal can stay within it, so the
// work is length x (2 limit + 1): two names of 200 kB (a log's header, a mapping's source)
// took length squared, 4e10 steps, before (a review, helper-132).
inline size_t edit_distance(const std::string& a, const std::string& b, size_t limit) {
  const size_t over = limit + 1, n = a.size(), m = b.size();
  if ((n > m ? n - m : m - n) > limit) return over;
  std::vector<size_t> row(m + 1, over), next(m + 1, over);
  for (size_t j = 0; j <= std::min(m, limit); ++j) row[j] = j;
  for (size_t i = 1; i <= n; ++i) {
    const size_t from = i > limit ? i - limit : 1, to = std::min(m, i + limit);
    std::fill(next.begin() + static_cast<long>(from > 1 ? from - 1 : 0), next.begin() + static_cast<long>(std::min(m, to + 1) + 1), over);
    if (i <= limit) next[0] = i;
    size_t best = next[0];
    for (size_t j = from; j <= to; ++j) {
      next[j] = std::min({row[j] + 1, next[j - 1] + 1, row[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1), over});
      best = std::min(best, next[j]);
    }
    if (best >= over) return over;  // every path already costs more than the limit
    std::swap(row, next);
  }
  return std::min(row[m], over);
}

// Of `candidates`, one that looks like `word` (lookalike_skeleton: an 'ay' for an 'аy' with a
// Cyrillic а, which is two bytes apart), else the one `word` differs from only in case, else the nearest within
// `max_edits` edits, and within a third of the word's length (leading dashes aside: 'w' is
// not a slip for 't', nor '--x' for '--dt'); the first of equals; "" when none is that near.
inline std::string nearest_word(const std::string& word, const std::vector<std::string>& candidates,
                                size_t max_edits = 2) {
  const size_t letters = word.size() - std::min(word.find_first_not_of('-'), word.size());
  max_edits = std::min(max_edits, letters / 3);
  const auto lower = [](const std::string& s) { return ascii_lower(s); };
  const std::string seen = lookalike_skeleton(word);
  for (const auto& c : candidates)
    if (c != word && lookalike_skeleton(c) == seen) return c;
  for (const auto& c : candidates)
    if (c != word && lower(c) == lower(word)) return c;
  std::string nearest;
  size_t best = max_edits + 1;
  for (const auto& c : candidates)
    if (const size_t d = edit_distance(word, c, max_edits); d < best) best = d, nearest = c;
  return nearest;
}

// What an error adds after refusing `word` where one of `candidates` was expected: "; did you
// mean 'near'?" as nearest_word finds it, and where the two look alike, what sets them apart
// ("; did you mean 'ay'? (they look alike, but 'аy' has U+0430 CYRILLIC SMALL LETTER A (character 1))");
// "" when no candidate is near.
inline std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates,
                                size_t max_edits = 2) {
  const std::string near = nearest_word(word, candidates, max_edits);
  if (near.empty()) return "";
  return "; did you mean '" + printable(near) + "'?" + lookalike_note(word, near);
}

}  // namespace quadgen::output
