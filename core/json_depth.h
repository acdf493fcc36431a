// The nesting depth of JSON text, bounded before a parser sees it. tinygltf turns JSON values into
// its own by recursion (an "extras" 20,000 arrays deep, a 40 KB file, overflowed the stack), and
// nlohmann::json's dump() recurses too; no glTF or stats.json pxf reads nests more than a few
// levels, so a deep one is refused with one line rather than parsed.
#pragma once
#include <cstddef>
#include <string>

#include "error.h"

namespace pxf {

constexpr size_t kMaxJsonDepth = 256;

// The deepest nesting of arrays and objects in `text` (brackets inside strings do not count),
// counted until it passes `limit`: then limit + 1. Malformed text gets a number too; the parser
// names its error.
inline size_t json_nesting_depth(const char* text, size_t size, size_t limit = kMaxJsonDepth) {
  size_t depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < size; ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;  // the escaped character, a quote included
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > deepest && (deepest = depth) > limit) return deepest;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

// Throws pxf::Error("<what>: JSON nested deeper than 256 levels") for text nested past the limit.
inline void check_json_depth(const char* text, size_t size, const std::string& what) {
  if (json_nesting_depth(text, size) > kMaxJsonDepth)
    throw Error(what + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                " levels (arrays and objects), which pxf does not read");
}

}  // namespace pxf
