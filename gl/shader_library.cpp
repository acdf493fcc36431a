#include "gl/shader_library.h"

#include <regex>
#include <sstream>
#include "image/image.h"

namespace pxf {

std::string embedded_shader(const std::string& name) {
  for (const EmbeddedShader* s = kEmbeddedShaders; s->name; ++s)
    if (name == s->name) return s->source;
  throw Error("shader '" + name + "' is not embedded in this binary (shaders/ at build time)");
}

namespace {

constexpr size_t kLinesPerFile = 100000;

void expand(const std::string& name, const std::string& source, const IncludeResolver& resolve,
            ExpandedShader& out, int depth) {
  if (depth > 16) throw Error("shader " + name + ": #include nesting deeper than 16");
  int file_index = static_cast<int>(out.files.size());
  out.files.push_back(name);
  static const std::regex include_re(R"(^\s*#\s*include\s+"([^"]+)\"\s*$)");
  std::istringstream in(source);
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    std::smatch m;
    if (!std::regex_match(line, m, include_re)) {
      out.text += line + "\n";
      continue;
    }
    std::string included = m[1];
    bool seen = false;
    for (const std::string& f : out.files) seen = seen || f == included;
    if (!seen) {
      std::string text = resolve(included);
      // GLSL >= 3.30: "#line L" makes the *next* line number L. The file index is encoded in the
      // line number (Mesa does not apply #line's source-string number to every message).
      out.text += "#line " + std::to_string(out.files.size() * kLinesPerFile + 1) + "\n";
      expand(included, text, resolve, out, depth + 1);
    }
    out.text += "#line " + std::to_string(file_index * kLinesPerFile + line_number + 1) + "\n";
  }
}

}  // namespace

ExpandedShader expand_includes(const std::string& name, const std::string& source, const IncludeResolver& resolve) {
  ExpandedShader out;
  expand(name, source, resolve, out, 0);
  return out;
}

std::string first_error_line(const std::string& log, const std::vector<std::string>& files) {
  // Mesa: "0:12(3): error: ..."; NVIDIA: "0(12) : error C0000: ...".
  static const std::regex mesa_re(R"((\d+):(\d+)\((\d+)\):\s*(.*))");
  static const std::regex nv_re(R"((\d+)\((\d+)\)\s*:\s*(.*))");
  std::istringstream in(log);
  std::string line, first_any;
  // "N:L" -> "file:line" with the file index encoded in L (see expand()).
  auto locate = [&](const std::string& line_text) {
    size_t l = std::stoul(line_text), i = l / kLinesPerFile;
    std::string file = i < files.size() ? files[i] : (files.empty() ? "<source>" : files[0]);
    return file + ":" + std::to_string(l % kLinesPerFile);
  };
  while (std::getline(in, line)) {
    std::smatch m;
    std::string rewritten;
    if (std::regex_search(line, m, mesa_re))
      rewritten = locate(m[2]) + ": " + m[4].str();
    else if (std::regex_search(line, m, nv_re))
      rewritten = locate(m[2]) + ": " + m[3].str();
    else
      continue;
    if (first_any.empty()) first_any = rewritten;
    if (rewritten.find("error") != std::string::npos) return rewritten;
  }
  if (!first_any.empty()) return first_any;
  // No location found: the log's first non-empty line, unchanged.
  std::istringstream again(log);
  while (std::getline(again, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) return line;
  return "";
}

}  // namespace pxf
