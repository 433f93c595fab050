// Looking up what a decoded EXR part carries besides its pixels: a string or double attribute by
// key (nullptr where the file has none), and the number in a part name of the form
// "<prefix>NN.<rest>", the slices of sky-render's renders ("sky.slice_NN.sza_...",
// transport/sky_scene.cpp) and fog renders ("fog.slice_NN....", fog/fog_render_file.cpp).
#pragma once

#include <charconv>
#include <string>
#include <system_error>

#include "io/exr.h"

namespace skybake {

inline const std::string* FindStringAttribute(const ExrImage& img, const std::string& key) {
  auto it = img.strings.find(key);
  return it == img.strings.end() ? nullptr : &it->second;
}

inline const double* FindDoubleAttribute(const ExrImage& img, const std::string& key) {
  auto it = img.doubles.find(key);
  return it == img.doubles.end() ? nullptr : &it->second;
}

// NN of a part named "<prefix>NN.<rest>" (NN a decimal integer followed by '.'), or -1.
inline int NumberedPartIndex(const std::string& name, const std::string& prefix) {
  if (name.rfind(prefix, 0) != 0) return -1;
  int i = -1;
  const char* b = name.data() + prefix.size();
  const char* e = name.data() + name.size();
  auto res = std::from_chars(b, e, i);
  if (res.ec != std::errc() || res.ptr == b || res.ptr == e || *res.ptr != '.') return -1;
  return i;
}

}  // namespace skybake
