// Suggestions for mistyped names: command-line commands, YAML keys.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace throng {

// Optimal string alignment distance: insertions, deletions, substitutions
// and swaps of neighbours each count 1 ("rnu" is one step from "run").
std::size_t edit_distance(std::string_view a, std::string_view b);

// The name closest to `word` when close enough to suggest (at most two edits
// and fewer than half the name's letters), else empty; ties go to the first.
template <class Names>
std::string closest_name(std::string_view word, const Names& names) {
  std::string best;
  std::size_t best_distance = 3;
  for (const auto& name : names) {
    const std::string_view n(name);
    const std::size_t d = edit_distance(word, n);
    if (d < best_distance && 2 * d < n.size()) {
      best = std::string(n);
      best_distance = d;
    }
  }
  return best;
}

}  // namespace throng
