#include "ninja_writer.h"

namespace skybake {

void NinjaWriter::Comment(const std::string& text) {
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    out_ += "# " + text.substr(start, end - start) + "\n";
    start = end + 1;
  }
}

void NinjaWriter::Variable(const std::string& key, const std::string& value, int indent) {
  out_ += std::string(static_cast<size_t>(indent), ' ') + key + " = " + value + "\n";
}

void NinjaWriter::Pool(const std::string& name, int depth) {
  out_ += "pool " + name + "\n";
  Variable("depth", std::to_string(depth), 2);
}

void NinjaWriter::Rule(const NinjaRule& r) {
  out_ += "rule " + r.name + "\n";
  Variable("command", r.command, 2);
  if (!r.description.empty()) Variable("description", r.description, 2);
  if (!r.depfile.empty()) Variable("depfile", r.depfile, 2);
  if (!r.deps.empty()) Variable("deps", r.deps, 2);
  if (!r.pool.empty()) Variable("pool", r.pool, 2);
  if (r.restat) Variable("restat", "1", 2);
  if (r.generator) Variable("generator", "1", 2);
}

std::string NinjaWriter::EscapePath(const std::string& path) {
  std::string out;
  for (char c : path) {
    if (c == '$' || c == ' ' || c == ':') out += '$';
    out += c;
  }
  return out;
}

std::string NinjaWriter::EscapeShellArg(const std::string& arg) {
  bool plain = !arg.empty();
  for (char c : arg) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || std::string("/._-+=,:@").find(c) != std::string::npos)) {
      plain = false;
    }
  }
  std::string quoted = plain ? arg : "'" + arg + "'";
  std::string out;
  for (char c : quoted) {
    if (c == '$') out += '$';
    out += c;
  }
  return out;
}

void NinjaWriter::Build(const NinjaBuild& b) {
  auto join = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& p : v) s += " " + EscapePath(p);
    return s;
  };
  out_ += "build" + join(b.outputs);
  if (!b.implicit_outputs.empty()) out_ += " |" + join(b.implicit_outputs);
  out_ += ": " + b.rule + join(b.inputs);
  if (!b.implicit_inputs.empty()) out_ += " |" + join(b.implicit_inputs);
  if (!b.order_only.empty()) out_ += " ||" + join(b.order_only);
  out_ += "\n";
  for (const auto& [k, v] : b.variables) Variable(k, v, 2);
}

void NinjaWriter::Default(const std::vector<std::string>& targets) {
  std::string s = "default";
  for (const auto& t : targets) s += " " + EscapePath(t);
  out_ += s + "\n";
}

}  // namespace skybake
