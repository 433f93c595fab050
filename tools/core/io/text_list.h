// A list of names as a message or --help states it: "a, b or c" (last = " or "), "a, b, c"
// (last = ", "), "a|b|c" (last = sep = "|").
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace skybake {

template <typename Names>
std::string TextList(const Names& names, std::string_view last = " or ", std::string_view sep = ", ") {
  std::string s;
  size_t i = 0;
  for (const auto& n : names) {
    if (i > 0) s += i + 1 == std::size(names) ? std::string(last) : std::string(sep);
    s += n;
    ++i;
  }
  return s;
}

}  // namespace skybake
