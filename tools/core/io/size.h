// Image and table sizes written "WxH" (e.g. 32x16) on command lines and in pipeline.yaml: two
// decimal integers joined by 'x', nothing before, between or after them (no sign, space or
// trailing text), each side within [min_side, max_side].
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace skybake {

struct Size2 {
  int width = 0;
  int height = 0;
};

std::optional<Size2> ParseSize(std::string_view text, int min_side, int max_side);

// "WxH with sides from <min> to <max>, e.g. <example>", the expectation a message states.
std::string SizeExpected(int min_side, int max_side, std::string_view example);

}  // namespace skybake
