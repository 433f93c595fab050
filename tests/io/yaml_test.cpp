// YAML loading: typed accessors, word-for-word error messages with file:line, unknown keys with
// "did you mean", every problem reported at once.
#include <gtest/gtest.h>

#include "io/yaml.h"

using namespace skybake;

namespace {
// Runs a loader over text and returns the error text (one line per diagnostic), "" if none.
template <typename F>
std::string Errors(const std::string& text, F loader) {
  YamlDocument doc = YamlDocument::Parse(text, "a.yaml");
  try {
    YamlMap root = doc.RootMap();
    loader(root);
    root.Finish();
    doc.ThrowIfErrors();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Yaml, ReadsTypedValues) {
  YamlDocument doc = YamlDocument::Parse("planet:\n  radius_km: 6371\n  top_km: 1e2\nname: clear\n", "a.yaml");
  YamlMap root = doc.RootMap();
  YamlMap planet = root.Map("planet");
  EXPECT_DOUBLE_EQ(planet.Number("radius_km", NumberSpec::Positive("km")), 6371.0);
  EXPECT_DOUBLE_EQ(planet.Number("top_km", NumberSpec::Positive("km")), 100.0);
  EXPECT_EQ(root.String("name"), "clear");
  planet.Finish();
  root.Finish();
  EXPECT_TRUE(doc.diags().empty());
}

TEST(Yaml, BadNumberMessageIsExact) {
  EXPECT_EQ(Errors("planet:\n  radius_km: abc\n",
                   [](YamlMap& r) {
                     YamlMap p = r.Map("planet");
                     p.Number("radius_km", NumberSpec::Positive("km"));
                     p.Finish();
                   }),
            "a.yaml:2: key 'planet.radius_km': expected a positive number in km, got \"abc\"");
}

TEST(Yaml, NanInfAndOutOfRangeAreRejected) {
  auto load = [](YamlMap& r) { r.Number("x_km", NumberSpec::Positive("km")); };
  EXPECT_EQ(Errors("x_km: .nan\n", load), "a.yaml:1: key 'x_km': expected a positive number in km, got \".nan\"");
  EXPECT_EQ(Errors("x_km: nan\n", load), "a.yaml:1: key 'x_km': expected a positive number in km, got \"nan\"");
  EXPECT_EQ(Errors("x_km: inf\n", load), "a.yaml:1: key 'x_km': expected a positive number in km, got \"inf\"");
  EXPECT_EQ(Errors("x_km: -3\n", load), "a.yaml:1: key 'x_km': expected a positive number in km, got \"-3\"");
  EXPECT_EQ(Errors("x_km: 0\n", load), "a.yaml:1: key 'x_km': expected a positive number in km, got \"0\"");
  EXPECT_EQ(Errors("x_km:\n", load), "a.yaml:1: key 'x_km': expected a positive number in km, got nothing");
  EXPECT_EQ(Errors("x_km: [1, 2]\n", load), "a.yaml:1: key 'x_km': expected a positive number in km, got a list");
}

TEST(Yaml, MissingKey) {
  EXPECT_EQ(Errors("planet:\n  top_km: 100\n",
                   [](YamlMap& r) {
                     YamlMap p = r.Map("planet");
                     p.Number("radius_km", NumberSpec::Positive("km"));
                     p.Number("top_km", NumberSpec::Positive("km"));
                     p.Finish();
                   }),
            "a.yaml:2: missing key 'planet.radius_km': expected a positive number in km");
}

TEST(Yaml, UnknownKeyWithSuggestion) {
  EXPECT_EQ(Errors("planet:\n  radius_kn: 6371\n  top_km: 100\n",
                   [](YamlMap& r) {
                     YamlMap p = r.Map("planet");
                     p.OptionalNumber("radius_km", NumberSpec::Positive("km"));
                     p.Number("top_km", NumberSpec::Positive("km"));
                     p.Finish();
                   }),
            "a.yaml:2: unknown key 'planet.radius_kn' (did you mean 'radius_km'?)");
  // No suggestion when nothing is close.
  EXPECT_EQ(Errors("zzzzzz: 1\n", [](YamlMap& r) { r.Has("planet"); }), "a.yaml:1: unknown key 'zzzzzz'");
}

TEST(Yaml, EveryProblemIsReported) {
  std::string e = Errors("a_km: x\nb_km: -1\nc: 3\n", [](YamlMap& r) {
    r.Number("a_km", NumberSpec::Positive("km"));
    r.Number("b_km", NumberSpec::Positive("km"));
    r.Number("d_km", NumberSpec::Positive("km"));
  });
  EXPECT_EQ(e,
            "a.yaml:1: key 'a_km': expected a positive number in km, got \"x\"\n"
            "a.yaml:1: missing key 'd_km': expected a positive number in km\n"
            "a.yaml:2: key 'b_km': expected a positive number in km, got \"-1\"\n"
            "a.yaml:3: unknown key 'c'");
}

TEST(Yaml, DuplicateKey) {
  EXPECT_EQ(Errors("a: 1\na: 2\n", [](YamlMap& r) { r.Has("a"); }),
            "a.yaml:2: duplicate key 'a' (first given on line 1)");
}

TEST(Yaml, ChoiceSuggests) {
  EXPECT_EQ(Errors("method: pth\n", [](YamlMap& r) { r.Choice("method", {"path", "orders"}); }),
            "a.yaml:1: key 'method': expected one of 'path' or 'orders', got \"pth\" (did you mean 'path'?)");
}

TEST(Yaml, ExactlyOneOf) {
  EXPECT_EQ(Errors("scale:\n  a: 1\n  b: 2\n",
                   [](YamlMap& r) {
                     YamlMap s = r.Map("scale");
                     s.ExactlyOneOf({"a", "b"});
                   }),
            "a.yaml:2: 'scale' needs exactly one of 'a' or 'b', got a and b");
}

TEST(Yaml, SyntaxErrorHasLine) {
  try {
    YamlDocument::Parse("a: 1\nb: [1, 2\nc: 3\n", "bad.yaml");
    FAIL() << "expected a syntax error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.diagnostics().at(0).loc.file, "bad.yaml");
    EXPECT_GE(e.diagnostics().at(0).loc.line, 2);
    EXPECT_NE(std::string(e.what()).find("YAML syntax error"), std::string::npos);
  }
}

TEST(Yaml, MissingFile) {
  try {
    YamlDocument::Load("/nonexistent/x.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/x.yaml: cannot open file");
  }
}

TEST(Yaml, FormatExactRoundTrips) {
  for (double v : {0.1, 1.0 / 3.0, 6371.0, 1e-300, 2.54697e25}) {
    EXPECT_EQ(std::stod(FormatExact(v)), v);
  }
}

TEST(Yaml, ClosestMatch) {
  EXPECT_EQ(ClosestMatch("radius_kn", {"radius_km", "top_km"}), "radius_km");
  EXPECT_EQ(ClosestMatch("qqqq", {"radius_km", "top_km"}), "");
}
