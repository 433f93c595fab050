#include "io/yaml.h"
#include "io/fileio.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

namespace skybake {

struct YamlDocState {
  std::string display_name;
  std::filesystem::path base_dir;
  YAML::Node root;
  Diagnostics diags;
};

// ---------------------------------------------------------------------------- NumberSpec

namespace {
std::string WithUnit(const std::string& text, const std::string& unit) {
  return unit.empty() ? text : text + " in " + unit;
}
}  // namespace

bool NumberSpec::Accepts(double v) const {
  if (!std::isfinite(v)) return false;
  if (min_inclusive ? v < min : v <= min) return false;
  if (max_inclusive ? v > max : v >= max) return false;
  return true;
}

NumberSpec NumberSpec::Any(const std::string& unit) {
  NumberSpec s;
  s.description = WithUnit("a number", unit);
  return s;
}
NumberSpec NumberSpec::Positive(const std::string& unit) {
  NumberSpec s;
  s.min = 0.0;
  s.min_inclusive = false;
  s.description = WithUnit("a positive number", unit);
  return s;
}
NumberSpec NumberSpec::NonNegative(const std::string& unit) {
  NumberSpec s;
  s.min = 0.0;
  s.description = WithUnit("a non-negative number", unit);
  return s;
}
NumberSpec NumberSpec::Range(double lo, double hi, const std::string& unit) {
  NumberSpec s;
  s.min = lo;
  s.max = hi;
  s.description = WithUnit(fmt::format("a number from {} to {}", FormatExact(lo), FormatExact(hi)), unit);
  return s;
}
NumberSpec NumberSpec::Above(double lo, const std::string& unit) {
  NumberSpec s;
  s.min = lo;
  s.min_inclusive = false;
  s.description = WithUnit(fmt::format("a number greater than {}", FormatExact(lo)), unit);
  return s;
}

// ---------------------------------------------------------------------------- helpers

size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string ClosestMatch(std::string_view word, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_d = std::numeric_limits<size_t>::max();
  for (const std::string& c : candidates) {
    size_t d = EditDistance(word, c);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  // A plausible typo: at most a third of the word changed (and at least 2 edits allowed).
  size_t limit = std::max<size_t>(2, word.size() / 3);
  return best_d <= limit ? best : std::string();
}

std::string FormatExact(double v) {
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, res.ptr);
}

namespace {
std::string Trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

// Strict number parsing: the whole text must be a finite decimal number.
std::optional<double> ParseDouble(const std::string& text) {
  std::string t = Trim(text);
  if (t.empty()) return std::nullopt;
  const char* begin = t.data();
  if (*begin == '+') ++begin;
  double v = 0.0;
  auto res = std::from_chars(begin, t.data() + t.size(), v, std::chars_format::general);
  if (res.ec != std::errc() || res.ptr != t.data() + t.size()) return std::nullopt;
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}
}  // namespace

// ---------------------------------------------------------------------------- YamlNode

YamlNode::YamlNode(std::shared_ptr<YamlDocState> doc, YAML::Node node, std::string path,
                   int fallback_line)
    : doc_(std::move(doc)), node_(std::move(node)), path_(std::move(path)),
      fallback_line_(fallback_line) {}

YamlNode YamlNode::Child(YAML::Node node, std::string path, int fallback_line) const {
  return YamlNode(doc_, std::move(node), std::move(path), fallback_line);
}

int YamlNode::line() const {
  if (node_) {
    const YAML::Mark m = node_.Mark();
    if (m.line >= 0 && !node_.IsNull()) return m.line + 1;
  }
  return fallback_line_ > 0 ? fallback_line_ : (node_ && node_.Mark().line >= 0 ? node_.Mark().line + 1 : 0);
}

FileLoc YamlNode::loc() const { return FileLoc{doc_->display_name, line()}; }
Diagnostics& YamlNode::diags() const { return doc_->diags; }

void YamlNode::Error(const std::string& message) const {
  if (path_.empty()) {
    doc_->diags.Add(loc(), message);
  } else {
    doc_->diags.Add(loc(), "key '" + path_ + "': " + message);
  }
}

std::string YamlNode::Describe() const {
  if (IsNull()) return "nothing";
  if (node_.IsSequence()) return "a list";
  if (node_.IsMap()) return "a mapping";
  return "\"" + node_.Scalar() + "\"";
}

void YamlNode::ErrorExpected(const std::string& expected) const {
  Error("expected " + expected + ", got " + Describe());
}

std::optional<double> YamlNode::ToNumber(const NumberSpec& spec) const {
  if (!node_.IsScalar()) {
    ErrorExpected(spec.description);
    return std::nullopt;
  }
  std::optional<double> v = ParseDouble(node_.Scalar());
  if (!v || !spec.Accepts(*v)) {
    ErrorExpected(spec.description);
    return std::nullopt;
  }
  return v;
}

std::optional<int64_t> YamlNode::ToInteger(int64_t min, int64_t max,
                                           const std::string& description) const {
  if (node_.IsScalar()) {
    std::string t = Trim(node_.Scalar());
    int64_t v = 0;
    auto res = std::from_chars(t.data(), t.data() + t.size(), v);
    if (!t.empty() && res.ec == std::errc() && res.ptr == t.data() + t.size() && v >= min && v <= max) {
      return v;
    }
  }
  ErrorExpected(description);
  return std::nullopt;
}

std::optional<std::string> YamlNode::ToString(const std::string& expected) const {
  if (!node_.IsScalar() || node_.Scalar().empty()) {
    ErrorExpected(expected);
    return std::nullopt;
  }
  return node_.Scalar();
}

std::optional<bool> YamlNode::ToBool() const {
  if (node_.IsScalar()) {
    const std::string& s = node_.Scalar();
    if (s == "true") return true;
    if (s == "false") return false;
  }
  ErrorExpected("true or false");
  return std::nullopt;
}

std::optional<std::string> YamlNode::ToChoice(const std::vector<std::string>& choices) const {
  std::string expected = "one of ";
  for (size_t i = 0; i < choices.size(); ++i) {
    if (i) expected += i + 1 == choices.size() ? " or " : ", ";
    expected += "'" + choices[i] + "'";
  }
  if (node_.IsScalar()) {
    const std::string& s = node_.Scalar();
    if (std::find(choices.begin(), choices.end(), s) != choices.end()) return s;
    std::string close = ClosestMatch(s, choices);
    if (!close.empty()) {
      Error("expected " + expected + ", got " + Describe() + " (did you mean '" + close + "'?)");
      return std::nullopt;
    }
  }
  ErrorExpected(expected);
  return std::nullopt;
}

std::optional<std::filesystem::path> YamlNode::ToPath(bool must_exist) const {
  std::optional<std::string> s = ToString("a file path");
  if (!s) return std::nullopt;
  std::filesystem::path p(*s);
  if (p.is_relative()) p = doc_->base_dir / p;
  p = p.lexically_normal();
  if (must_exist) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(p, ec)) {
      Error("file not found: " + p.string());
      return std::nullopt;
    }
  }
  return p;
}

std::vector<YamlNode> YamlNode::Elements(const std::string& expected) const {
  std::vector<YamlNode> out;
  if (!node_.IsSequence()) {
    ErrorExpected(expected);
    return out;
  }
  for (size_t i = 0; i < node_.size(); ++i) {
    out.push_back(Child(node_[i], path_ + "[" + std::to_string(i) + "]", line()));
  }
  return out;
}

std::optional<std::vector<double>> YamlNode::ToNumberList(const NumberSpec& element) const {
  if (!node_.IsSequence() || node_.size() == 0) {
    ErrorExpected("a non-empty list of " + element.description.substr(element.description.find(' ') + 1) +
                  "s");
    return std::nullopt;
  }
  std::vector<double> out;
  bool ok = true;
  for (const YamlNode& e : Elements()) {
    std::optional<double> v = e.ToNumber(element);
    if (v) out.push_back(*v);
    else ok = false;
  }
  if (!ok) return std::nullopt;
  return out;
}

YamlMap YamlNode::ToMap(const std::string& expected) const {
  if (!node_.IsMap()) {
    ErrorExpected(expected);
    return YamlMap(*this, false);
  }
  // Duplicate keys: yaml-cpp keeps them; we report them.
  std::map<std::string, int> first_line;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    if (!it->first.IsScalar()) continue;
    const std::string key = it->first.Scalar();
    int line = it->first.Mark().line + 1;
    auto [pos, inserted] = first_line.emplace(key, line);
    if (!inserted) {
      std::string p = path_.empty() ? key : path_ + "." + key;
      doc_->diags.Add(FileLoc{doc_->display_name, line},
                      fmt::format("duplicate key '{}' (first given on line {})", p, pos->second));
    }
  }
  return YamlMap(*this, true);
}

// ---------------------------------------------------------------------------- YamlMap

YamlMap::YamlMap(YamlNode node, bool valid) : node_(std::move(node)), valid_(valid) {}

std::string YamlMap::ChildPath(std::string_view key) const {
  return node_.path().empty() ? std::string(key) : node_.path() + "." + std::string(key);
}

bool YamlMap::Has(std::string_view key) {
  known_.emplace(key);
  if (!valid_) return false;
  for (auto it = node_.raw().begin(); it != node_.raw().end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key) return true;
  }
  return false;
}

std::optional<YamlNode> YamlMap::Get(std::string_view key) {
  known_.emplace(key);
  if (!valid_) return std::nullopt;
  // Iterate rather than operator[] so that a duplicated key resolves to its first occurrence
  // and a const lookup never inserts.
  for (auto it = node_.raw().begin(); it != node_.raw().end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key) {
      // A key with no value ("key:") gives a null node without a mark: use the key's line.
      return node_.Child(it->second, ChildPath(key), it->first.Mark().line + 1);
    }
  }
  return std::nullopt;
}

void YamlMap::Known(std::initializer_list<std::string_view> keys) {
  for (std::string_view k : keys) known_.emplace(k);
}

void YamlMap::ErrorMissing(std::string_view key, const std::string& expected) {
  if (!valid_) return;  // The map itself was already reported.
  node_.diags().Add(node_.loc(), "missing key '" + ChildPath(key) + "': expected " + expected);
}

double YamlMap::Number(std::string_view key, const NumberSpec& spec, double fallback) {
  std::optional<YamlNode> n = Get(key);
  if (!n) {
    ErrorMissing(key, spec.description);
    return fallback;
  }
  return n->ToNumber(spec).value_or(fallback);
}

std::optional<double> YamlMap::OptionalNumber(std::string_view key, const NumberSpec& spec) {
  std::optional<YamlNode> n = Get(key);
  if (!n) return std::nullopt;
  return n->ToNumber(spec);
}

double YamlMap::NumberOr(std::string_view key, const NumberSpec& spec, double default_value) {
  std::optional<YamlNode> n = Get(key);
  if (!n) return default_value;
  return n->ToNumber(spec).value_or(default_value);
}

int64_t YamlMap::Integer(std::string_view key, int64_t min, int64_t max,
                         const std::string& description, int64_t fallback) {
  std::optional<YamlNode> n = Get(key);
  if (!n) {
    ErrorMissing(key, description);
    return fallback;
  }
  return n->ToInteger(min, max, description).value_or(fallback);
}

int64_t YamlMap::IntegerOr(std::string_view key, int64_t min, int64_t max,
                           const std::string& description, int64_t default_value) {
  std::optional<YamlNode> n = Get(key);
  if (!n) return default_value;
  return n->ToInteger(min, max, description).value_or(default_value);
}

std::string YamlMap::String(std::string_view key, const std::string& expected) {
  std::optional<YamlNode> n = Get(key);
  if (!n) {
    ErrorMissing(key, expected);
    return {};
  }
  return n->ToString(expected).value_or("");
}

std::optional<std::string> YamlMap::OptionalString(std::string_view key, const std::string& expected) {
  std::optional<YamlNode> n = Get(key);
  if (!n) return std::nullopt;
  return n->ToString(expected);
}

std::string YamlMap::Choice(std::string_view key, const std::vector<std::string>& choices) {
  std::optional<YamlNode> n = Get(key);
  if (!n) {
    std::string expected = "one of ";
    for (size_t i = 0; i < choices.size(); ++i) {
      if (i) expected += i + 1 == choices.size() ? " or " : ", ";
      expected += "'" + choices[i] + "'";
    }
    ErrorMissing(key, expected);
    return {};
  }
  return n->ToChoice(choices).value_or("");
}

std::string YamlMap::ChoiceOr(std::string_view key, const std::vector<std::string>& choices,
                              const std::string& default_value) {
  std::optional<YamlNode> n = Get(key);
  if (!n) return default_value;
  return n->ToChoice(choices).value_or(default_value);
}

bool YamlMap::BoolOr(std::string_view key, bool default_value) {
  std::optional<YamlNode> n = Get(key);
  if (!n) return default_value;
  return n->ToBool().value_or(default_value);
}

std::optional<std::filesystem::path> YamlMap::Path(std::string_view key, bool must_exist) {
  std::optional<YamlNode> n = Get(key);
  if (!n) {
    ErrorMissing(key, "a file path");
    return std::nullopt;
  }
  return n->ToPath(must_exist);
}

std::optional<std::filesystem::path> YamlMap::OptionalPath(std::string_view key, bool must_exist) {
  std::optional<YamlNode> n = Get(key);
  if (!n) return std::nullopt;
  return n->ToPath(must_exist);
}

std::vector<double> YamlMap::NumberList(std::string_view key, const NumberSpec& element) {
  std::optional<YamlNode> n = Get(key);
  if (!n) {
    ErrorMissing(key, "a list of numbers");
    return {};
  }
  return n->ToNumberList(element).value_or(std::vector<double>{});
}

YamlMap YamlMap::Map(std::string_view key) {
  std::optional<YamlNode> n = Get(key);
  if (!n) {
    ErrorMissing(key, "a mapping");
    return YamlMap(YamlNode(node_), false);
  }
  return n->ToMap();
}

std::optional<YamlMap> YamlMap::OptionalMap(std::string_view key) {
  std::optional<YamlNode> n = Get(key);
  if (!n) return std::nullopt;
  return n->ToMap();
}

std::vector<YamlNode> YamlMap::Seq(std::string_view key) {
  std::optional<YamlNode> n = Get(key);
  if (!n) {
    ErrorMissing(key, "a list");
    return {};
  }
  return n->Elements();
}

std::optional<std::vector<YamlNode>> YamlMap::OptionalSeq(std::string_view key) {
  std::optional<YamlNode> n = Get(key);
  if (!n) return std::nullopt;
  return n->Elements();
}

namespace {
std::string QuotedList(std::initializer_list<std::string_view> keys) {
  std::string s;
  size_t i = 0;
  for (std::string_view k : keys) {
    if (i) s += (i + 1 == keys.size()) ? " or " : ", ";
    s += "'" + std::string(k) + "'";
    ++i;
  }
  return s;
}
}  // namespace

std::string YamlMap::ExactlyOneOf(std::initializer_list<std::string_view> keys) {
  std::vector<std::string> present;
  for (std::string_view k : keys) {
    if (Has(k)) present.emplace_back(k);
  }
  if (!valid_) return {};
  if (present.size() == 1) return present[0];
  const std::string where = node_.path().empty() ? std::string("the file") : "'" + node_.path() + "'";
  if (present.empty()) {
    node_.diags().Add(node_.loc(), fmt::format("{} needs exactly one of {}", where, QuotedList(keys)));
  } else {
    node_.diags().Add(node_.loc(), fmt::format("{} needs exactly one of {}, got {}", where,
                                               QuotedList(keys), fmt::join(present, " and ")));
  }
  return {};
}

std::string YamlMap::AtMostOneOf(std::initializer_list<std::string_view> keys) {
  std::vector<std::string> present;
  for (std::string_view k : keys) {
    if (Has(k)) present.emplace_back(k);
  }
  if (present.size() <= 1) return present.empty() ? std::string() : present[0];
  const std::string where = node_.path().empty() ? std::string("the file") : "'" + node_.path() + "'";
  node_.diags().Add(node_.loc(), fmt::format("{} takes at most one of {}, got {}", where,
                                             QuotedList(keys), fmt::join(present, " and ")));
  return {};
}

void YamlMap::Finish() {
  if (!valid_) return;
  std::vector<std::string> candidates(known_.begin(), known_.end());
  for (auto it = node_.raw().begin(); it != node_.raw().end(); ++it) {
    if (!it->first.IsScalar()) {
      node_.diags().Add(FileLoc{node_.loc().file, it->first.Mark().line + 1},
                        "keys must be plain names");
      continue;
    }
    const std::string key = it->first.Scalar();
    if (known_.count(key)) continue;
    std::string msg = "unknown key '" + ChildPath(key) + "'";
    std::string close = ClosestMatch(key, candidates);
    if (!close.empty()) msg += " (did you mean '" + close + "'?)";
    node_.diags().Add(FileLoc{node_.loc().file, it->first.Mark().line + 1}, msg);
  }
}

// ---------------------------------------------------------------------------- YamlDocument

YamlDocument YamlDocument::Load(const std::filesystem::path& path) {
  const std::string text = ReadFileBytes(path);
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  return Parse(text, path.string(), dir);
}

YamlDocument YamlDocument::Parse(const std::string& text, const std::string& display_name,
                                 const std::filesystem::path& base_dir) {
  YamlDocument doc;
  doc.state_ = std::make_shared<YamlDocState>();
  doc.state_->display_name = display_name;
  doc.state_->base_dir = base_dir;
  try {
    doc.state_->root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(FileLoc{display_name, e.mark.line >= 0 ? e.mark.line + 1 : 0},
                     "YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw InputError(FileLoc{display_name, e.mark.line >= 0 ? e.mark.line + 1 : 0},
                     "YAML error: " + e.msg);
  }
  return doc;
}

YamlNode YamlDocument::root() const { return YamlNode(state_, state_->root, ""); }

YamlMap YamlDocument::RootMap() const {
  YamlNode r = root();
  if (r.IsNull()) {
    state_->diags.Add(FileLoc{state_->display_name, 1}, "the file is empty (expected a mapping)");
    return YamlMap(r, false);
  }
  return r.ToMap("a mapping at the top of the file");
}

Diagnostics& YamlDocument::diags() const { return state_->diags; }
void YamlDocument::ThrowIfErrors() const { state_->diags.ThrowIfAny(); }
const std::string& YamlDocument::display_name() const { return state_->display_name; }
const std::filesystem::path& YamlDocument::base_dir() const { return state_->base_dir; }

}  // namespace skybake
