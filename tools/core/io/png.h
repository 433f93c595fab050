// 8-bit PNG encoding for previews (libpng), deterministic bytes (no time chunk, fixed zlib
// level), written with WriteFileIfChanged. The pixels must already be display-encoded: colour
// previews go through the OCIO display view first (color/ module); data previews (noise) are
// plain values mapped to 0-255.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace skybake {

// `channels` = 1 (gray), 3 (RGB) or 4 (RGBA); rows top to bottom, interleaved.
std::string EncodePng8(int width, int height, int channels, const std::vector<uint8_t>& pixels);
bool WritePng8(const std::filesystem::path& path, int width, int height, int channels,
               const std::vector<uint8_t>& pixels);
// Decodes an 8-bit PNG (for tests); throws InputError(display_name) on bad data.
std::vector<uint8_t> DecodePng8(const std::string& bytes, const std::string& display_name, int* width,
                                int* height, int* channels);

}  // namespace skybake
