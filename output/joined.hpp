// The one way lists become text in messages, labels and comments: "a, b, c".
#pragma once
#include <string>

namespace quadgen::output {

// The items of `items`, each as `show` gives it, with `separator` between them. Unlike
// `s += (s.empty() ? "" : ", ") + x`, an empty first item still gets its separator.
template <class Range, class Show>
std::string joined(const Range& items, const std::string& separator, Show show) {
  std::string out;
  bool first = true;
  for (const auto& item : items) {
    if (!first) out += separator;
    first = false;
    out += show(item);
  }
  return out;
}

template <class Range>
std::string joined(const Range& items, const std::string& separator = ", ") {
  return joined(items, separator, [](const auto& item) -> std::string { return item; });
}

}  // namespace quadgen::output
