#include "io/size.h"

#include <charconv>

#include <fmt/format.h>

namespace skybake {

namespace {

// A side: 1-5 decimal digits (up to 99999, far above any max_side) and nothing else.
std::optional<int> Side(std::string_view s) {
  if (s.empty() || s.size() > 5) return std::nullopt;
  for (char c : s) {
    if (c < '0' || c > '9') return std::nullopt;
  }
  int v = 0;
  std::from_chars(s.data(), s.data() + s.size(), v);
  return v;
}

}  // namespace

std::optional<Size2> ParseSize(std::string_view text, int min_side, int max_side) {
  const size_t x = text.find('x');
  if (x == std::string_view::npos) return std::nullopt;
  std::optional<int> w = Side(text.substr(0, x)), h = Side(text.substr(x + 1));
  if (!w || !h || *w < min_side || *h < min_side || *w > max_side || *h > max_side) return std::nullopt;
  return Size2{*w, *h};
}

std::string SizeExpected(int min_side, int max_side, std::string_view example) {
  return fmt::format("WxH with sides from {} to {}, e.g. {}", min_side, max_side, example);
}

}  // namespace skybake
