// GLSL sources embedded at build time from shaders/ (gl/embed_shaders.cmake), and the
// `#include "x.glsl"` expansion shared by every pass.
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace pxf {

struct EmbeddedShader {
  const char* name;    // file name in shaders/, e.g. "blend.frag"
  const char* source;
};
extern const EmbeddedShader kEmbeddedShaders[];  // terminated by {nullptr, nullptr}

// Source of an embedded shader file; throws pxf::Error when there is none by that name.
std::string embedded_shader(const std::string& name);

// Returns the source text of an included file (throws pxf::Error when missing).
using IncludeResolver = std::function<std::string(const std::string& name)>;

// A shader after include expansion: the text handed to the GL, and the files it was made of
// (files[0] is the main file). Its `#line` directives encode file i's line L as i * 100000 + L.
struct ExpandedShader {
  std::string text;
  std::vector<std::string> files;
};
// Expands `#include "x"` lines recursively (each file once), inserting `#line` directives so
// that the compiler's log can be mapped back to file names and lines.
ExpandedShader expand_includes(const std::string& name, const std::string& source, const IncludeResolver& resolve);

// Rewrites a compiler log's locations ("0:12(3): error" on Mesa, "0(12) : error" elsewhere) to
// "file:line: error" and returns its first error as one line ("" when none is found).
std::string first_error_line(const std::string& log, const std::vector<std::string>& files);

}  // namespace pxf
