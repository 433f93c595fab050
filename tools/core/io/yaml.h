// YAML loading with typed, validating accessors (yaml-cpp underneath).
//
// Every accessor knows where its value came from, so errors read
//   file.yaml:12: key 'planet.radius_km': expected a positive number in km, got "abc"
//   file.yaml:3: missing key 'planet.radius_km': expected a positive number in km
//   file.yaml:7: unknown key 'planet.radius_kn' (did you mean 'radius_km'?)
//   file.yaml:9: duplicate key 'planet.top_km' (first given on line 8)
// Problems are collected in the document's Diagnostics and reported together (docs/developing.md "Rules", 4):
// a loader reads everything, falling back to neutral values where a value is bad, and calls
// YamlDocument::ThrowIfErrors() once at the end.
//
// Unknown keys: every key a loader asks about (Get/Has/Number/...) is "known" to that map;
// YamlMap::Finish() reports the rest, suggesting the closest known key.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "io/error.h"

namespace skybake {

// What a number must be. `description` completes "expected ...", e.g. "a positive number in km".
struct NumberSpec {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_inclusive = true;
  bool max_inclusive = true;
  std::string description;

  bool Accepts(double v) const;

  // `unit` is appended as " in <unit>" when not empty.
  static NumberSpec Any(const std::string& unit = "");
  static NumberSpec Positive(const std::string& unit = "");
  static NumberSpec NonNegative(const std::string& unit = "");
  // Closed interval [lo, hi].
  static NumberSpec Range(double lo, double hi, const std::string& unit = "");
  // Open lower bound: v > lo.
  static NumberSpec Above(double lo, const std::string& unit = "");
};

class YamlMap;
struct YamlDocState;

// One node of a loaded document, with its location and dotted key path for messages.
class YamlNode {
 public:
  YamlNode(std::shared_ptr<YamlDocState> doc, YAML::Node node, std::string path,
           int fallback_line = 0);
  // A node of the same document (used by YamlMap for its values).
  YamlNode Child(YAML::Node node, std::string path, int fallback_line) const;

  FileLoc loc() const;
  int line() const;
  const std::string& path() const { return path_; }
  const YAML::Node& raw() const { return node_; }
  Diagnostics& diags() const;

  bool IsMap() const { return node_.IsMap(); }
  bool IsSeq() const { return node_.IsSequence(); }
  bool IsScalar() const { return node_.IsScalar(); }
  bool IsNull() const { return !node_ || node_.IsNull(); }

  // Reports "file:line: key 'path': <message>".
  void Error(const std::string& message) const;
  // Reports "file:line: key 'path': expected <expected>, got <what this node is>".
  void ErrorExpected(const std::string& expected) const;

  // Conversions: on a wrong kind or value they report ErrorExpected and return nullopt.
  std::optional<double> ToNumber(const NumberSpec& spec) const;
  std::optional<int64_t> ToInteger(int64_t min, int64_t max, const std::string& description) const;
  std::optional<std::string> ToString(const std::string& expected = "a string") const;
  std::optional<bool> ToBool() const;
  // One of `choices`; the message lists them.
  std::optional<std::string> ToChoice(const std::vector<std::string>& choices) const;
  // A path relative to the YAML file's folder (absolute paths kept), lexically normalised.
  // With must_exist, a missing file is reported here.
  std::optional<std::filesystem::path> ToPath(bool must_exist = true) const;
  // Sequence elements; reports if this is not a sequence.
  std::vector<YamlNode> Elements(const std::string& expected = "a list") const;
  std::optional<std::vector<double>> ToNumberList(const NumberSpec& element) const;
  // A mapping view; reports (and returns an empty view) if this is not a mapping.
  YamlMap ToMap(const std::string& expected = "a mapping") const;

  // Short human text of what the node holds: "\"abc\"", "a list", "a mapping", "nothing".
  std::string Describe() const;

 private:
  std::shared_ptr<YamlDocState> doc_;
  YAML::Node node_;
  std::string path_;
  int fallback_line_ = 0;
};

// A mapping node with key tracking.
class YamlMap {
 public:
  YamlMap(YamlNode node, bool valid);

  const YamlNode& node() const { return node_; }
  bool valid() const { return valid_; }

  bool Has(std::string_view key);
  std::optional<YamlNode> Get(std::string_view key);
  // Marks keys as known without reading them (e.g. handled elsewhere).
  void Known(std::initializer_list<std::string_view> keys);

  // Required values report "missing key" when absent and return the fallback.
  double Number(std::string_view key, const NumberSpec& spec, double fallback = 0.0);
  std::optional<double> OptionalNumber(std::string_view key, const NumberSpec& spec);
  double NumberOr(std::string_view key, const NumberSpec& spec, double default_value);
  int64_t Integer(std::string_view key, int64_t min, int64_t max, const std::string& description,
                  int64_t fallback = 0);
  int64_t IntegerOr(std::string_view key, int64_t min, int64_t max, const std::string& description,
                    int64_t default_value);
  std::string String(std::string_view key, const std::string& expected = "a string");
  std::optional<std::string> OptionalString(std::string_view key,
                                            const std::string& expected = "a string");
  std::string Choice(std::string_view key, const std::vector<std::string>& choices);
  std::string ChoiceOr(std::string_view key, const std::vector<std::string>& choices,
                       const std::string& default_value);
  bool BoolOr(std::string_view key, bool default_value);
  std::optional<std::filesystem::path> Path(std::string_view key, bool must_exist = true);
  std::optional<std::filesystem::path> OptionalPath(std::string_view key, bool must_exist = true);
  std::vector<double> NumberList(std::string_view key, const NumberSpec& element);
  YamlMap Map(std::string_view key);
  std::optional<YamlMap> OptionalMap(std::string_view key);
  std::vector<YamlNode> Seq(std::string_view key);
  std::optional<std::vector<YamlNode>> OptionalSeq(std::string_view key);

  // Exactly one of `keys` must be present; returns it, or "" after reporting.
  std::string ExactlyOneOf(std::initializer_list<std::string_view> keys);
  // At most one of `keys`; returns it or "" when none is present.
  std::string AtMostOneOf(std::initializer_list<std::string_view> keys);

  // Reports every key of this mapping that no accessor asked about.
  void Finish();

  // Reports "missing key 'path.key': expected <expected>" at this map's line.
  void ErrorMissing(std::string_view key, const std::string& expected);

 private:
  std::string ChildPath(std::string_view key) const;

  YamlNode node_;
  bool valid_;
  std::set<std::string, std::less<>> known_;
};

class YamlDocument {
 public:
  // Reads and parses a file; a missing file or a syntax error throws InputError (file:line).
  static YamlDocument Load(const std::filesystem::path& path);
  // Parses text; `display_name` appears in messages, `base_dir` resolves relative paths.
  static YamlDocument Parse(const std::string& text, const std::string& display_name,
                            const std::filesystem::path& base_dir = ".");

  YamlNode root() const;
  YamlMap RootMap() const;
  Diagnostics& diags() const;
  void ThrowIfErrors() const;
  const std::string& display_name() const;
  const std::filesystem::path& base_dir() const;

 private:
  std::shared_ptr<YamlDocState> state_;
};

// Levenshtein distance, for "did you mean" suggestions.
size_t EditDistance(std::string_view a, std::string_view b);
// The candidate closest to `word` if it is close enough to be a plausible typo, else "".
std::string ClosestMatch(std::string_view word, const std::vector<std::string>& candidates);

// Formats a double so that it reads back exactly (shortest round-trip form), for canonical files.
std::string FormatExact(double v);

}  // namespace skybake
