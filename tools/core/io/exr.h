// OpenEXR images and tables with provenance (OpenEXR 3.1).
//
// Every numeric product of skybake is an EXR file:
//  - float32 channels, ZIP compression (lossless; never DWA/B44 for data), one scanline part;
//  - `skybake.*` attributes: tool, version, the resolved parameters (YAML text), the inputs and
//    their content hashes, and a description of each table axis (name, unit, meaning, exact
//    coordinates);
//  - the standard `chromaticities` attribute where the channels are colours (XYZ in R,G,B with
//    primaries (1,0),(0,1),(0,0) and white (1/3,1/3), as OpenEXR's XYZ test image does).
// Files are encoded in memory and written with WriteFileIfChanged, so identical content keeps
// the old file (and its mtime) and the bytes depend only on the content (no timestamps).
//
// Tables (1-D to 3-D) are images of width n0 and height n1*n2 (axis 0 fastest, then 1, then
// 2), recorded in `skybake.layout = "table"` and `skybake.axisK.*`; ExrTable converts both ways.
#pragma once

#include <ImfChromaticities.h>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace skybake {

struct ExrImage {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;
  // Channel-interleaved, row-major: pixels[((y * width) + x) * channels.size() + c].
  std::vector<float> pixels;

  std::map<std::string, std::string> strings;
  std::map<std::string, double> doubles;
  std::map<std::string, int> ints;
  std::map<std::string, std::vector<float>> float_vectors;
  std::optional<Imf::Chromaticities> chromaticities;

  void Resize(int w, int h, std::vector<std::string> channel_names);
  int ChannelIndex(const std::string& name) const;  // -1 if absent
  float& At(int x, int y, int c) { return pixels[(static_cast<size_t>(y) * width + x) * channels.size() + c]; }
  float At(int x, int y, int c) const {
    return pixels[(static_cast<size_t>(y) * width + x) * channels.size() + c];
  }
};

// One axis of a table: what it is and its exact coordinates.
struct ExrAxis {
  std::string name;         // e.g. "altitude"
  std::string unit;         // e.g. "m"
  std::string description;  // e.g. "geometric altitude above the ground, uniform grid"
  std::vector<double> values;
};

struct ExrTable {
  std::vector<ExrAxis> axes;  // 1 to 3 axes, fastest first
  std::vector<std::string> channels;
  std::vector<std::string> channel_units;  // same length as channels ("m^-3", "K", "1", ...)
  std::vector<float> values;               // channel-interleaved, axis 0 fastest

  size_t Count() const;  // number of table points (product of the axis sizes)
  float& At(size_t point, size_t channel) { return values[point * channels.size() + channel]; }
  float At(size_t point, size_t channel) const { return values[point * channels.size() + channel]; }
  int ChannelIndex(const std::string& name) const;
};

// What produced a file.
struct Provenance {
  std::string tool;        // e.g. "profile-import"
  std::string parameters;  // resolved parameters as YAML text
  // Inputs as given (normalised), with their content hash.
  std::vector<std::pair<std::string, std::string>> inputs;

  void AddInput(const std::filesystem::path& path);  // hashes the file
};

// Adds skybake.tool / skybake.version / skybake.parameters / skybake.inputs.
void SetProvenance(ExrImage& image, const Provenance& provenance);

// XYZ colour in R,G,B (see above).
Imf::Chromaticities XyzChromaticities();

ExrImage TableToImage(const ExrTable& table);
// Throws InputError(path) if the image is not a skybake table.
ExrTable ImageToTable(const ExrImage& image, const std::string& display_name);

// Encodes to bytes (deterministic).
std::string EncodeExr(const ExrImage& image);
// Encodes and writes with WriteFileIfChanged; returns true if the file changed.
bool WriteExr(const std::filesystem::path& path, const ExrImage& image);
// Reads every channel as float plus the attributes above. Throws InputError(path) for a missing,
// truncated or malformed file.
ExrImage ReadExr(const std::filesystem::path& path);
ExrImage DecodeExr(const std::string& bytes, const std::string& display_name);

// Multi-part files: one ExrImage per part, each with a unique part name (stored as the part's
// `name`). Used where one product holds several tables of different shapes (e.g. per-wavelength
// scalars beside a phase-function table). Same determinism and atomicity as single-part files.
struct ExrPart {
  std::string name;
  ExrImage image;
};
std::string EncodeExrParts(const std::vector<ExrPart>& parts);
bool WriteExrParts(const std::filesystem::path& path, const std::vector<ExrPart>& parts);
// Reads every part (a single-part file gives one part named after its `name` attribute or "").
std::vector<ExrPart> ReadExrParts(const std::filesystem::path& path);
std::vector<ExrPart> DecodeExrParts(const std::string& bytes, const std::string& display_name);
// The part called `name`; throws InputError(display_name) if absent.
const ExrImage& FindPart(const std::vector<ExrPart>& parts, const std::string& name,
                         const std::string& display_name);

}  // namespace skybake
