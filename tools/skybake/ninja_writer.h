// Writes Ninja syntax (ninja manual, "Lexical syntax"): escaping of $, space and colon in paths,
// rules, build statements with implicit (|) and order-only (||) inputs, pools, variables.
#pragma once

#include <string>
#include <vector>

namespace skybake {

struct NinjaRule {
  std::string name;
  std::string command;
  std::string description;
  std::string depfile;      // e.g. "$out.d"
  std::string deps;         // "gcc" with a depfile
  std::string pool;         // "", "console" or a declared pool
  bool restat = false;
  bool generator = false;
};

struct NinjaBuild {
  std::vector<std::string> outputs;
  std::vector<std::string> implicit_outputs;
  std::string rule;
  std::vector<std::string> inputs;
  std::vector<std::string> implicit_inputs;
  std::vector<std::string> order_only;
  std::vector<std::pair<std::string, std::string>> variables;
};

class NinjaWriter {
 public:
  void Comment(const std::string& text);
  void Variable(const std::string& key, const std::string& value, int indent = 0);
  void Pool(const std::string& name, int depth);
  void Rule(const NinjaRule& rule);
  void Build(const NinjaBuild& build);
  void Default(const std::vector<std::string>& targets);
  void Newline() { out_ += "\n"; }
  const std::string& str() const { return out_; }

  // Escapes a path for use in a build line ($ -> $$, ' ' -> '$ ', ':' -> '$:').
  static std::string EscapePath(const std::string& path);
  // Escapes a value for use in a variable (only $ -> $$ ... the caller's $vars stay).
  static std::string EscapeShellArg(const std::string& arg);

 private:
  std::string out_;
};

}  // namespace skybake
