// The GLB container (glTF 2.0 binary: header, JSON chunk, optional BIN chunk) around a JSON text
// and a payload, both already padded to 4 bytes. For tests and seed programs only.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace pxf::test {

inline std::vector<uint8_t> glb_container(const std::string& json_text, const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> out;
  auto u32 = [&](uint32_t v) { for (int s = 0; s < 32; s += 8) out.push_back(static_cast<uint8_t>(v >> s)); };
  out.insert(out.end(), {'g', 'l', 'T', 'F'});
  u32(2);
  u32(static_cast<uint32_t>(12 + 8 + json_text.size() + (payload.empty() ? 0 : 8 + payload.size())));
  u32(static_cast<uint32_t>(json_text.size()));
  u32(0x4E4F534A);  // JSON
  out.insert(out.end(), json_text.begin(), json_text.end());
  if (!payload.empty()) {
    u32(static_cast<uint32_t>(payload.size()));
    u32(0x004E4942);  // BIN
    out.insert(out.end(), payload.begin(), payload.end());
  }
  return out;
}

}  // namespace pxf::test
