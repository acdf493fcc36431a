// What the glTF JSON needs before tinygltf 2.7 (Debian's, built without Draco) parses it:
//  - a required extension pxf does not support is refused by name first, not after tinygltf has
//    failed on what the extension changes (a Draco primitive's index accessor has no bufferView,
//    which tinygltf rejects as "accessor[0] invalid bufferView");
//  - a Draco primitive's index accessor is lent the extension's bufferView so tinygltf accepts it
//    (restore_draco_index_accessors gives it back no bufferView after parsing);
//  - an EXT_meshopt_compression fallback buffer (byteLength but no uri, its data only ever
//    decompressed) becomes a 1-byte data uri: tinygltf would read it from the GLB's BIN chunk, or
//    fail on a .gltf. The decoded views get buffers of their own (gltf_meshopt.h).
// Files that mention neither extensionsRequired nor a compression extension are passed through
// untouched and unparsed.
#pragma once
#include <cstddef>
#include <set>
#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

namespace pxf::gltf {

struct PreparedJson {
  bool rewritten = false;
  std::vector<unsigned char> bytes;          // the file with its JSON rewritten, when `rewritten`
  std::vector<int> draco_index_accessors;    // accessors lent a bufferView for tinygltf
};

// `data`: a .gltf's text or a GLB (binary = true). Throws pxf::Error("<file>: ...") for a required
// extension not in `supported`, naming it (and, for KHR_texture_basisu, why it cannot be).
PreparedJson prepare_json(const unsigned char* data, size_t size, bool binary, const std::string& file,
                          const std::set<std::string>& supported);

// After tinygltf has parsed the prepared file: the lent bufferViews are taken back.
void restore_draco_index_accessors(tinygltf::Model& model, const PreparedJson& prepared);

}  // namespace pxf::gltf
