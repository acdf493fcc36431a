// EXT_meshopt_compression with meshoptimizer's decoders (gltfpack's output). A compressed
// bufferView names its compressed bytes in the extension. Only the views that an image or an
// accessor uses are decoded, each once, into a buffer of its own that the view then points at (the
// file's fallback buffer holds nothing: gltf_prepass.h). Before anything is decoded the loader
// plans: every used view is checked, and the decoded bytes of all of them, which go into the
// memory estimate, are bounded by the compressed bytes they read, each byte counted once.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

namespace pxf::gltf {

// meshoptimizer's codecs expand at most 64-fold (an attribute byte channel of 16 equal vertices
// costs 2 header bits; an index at least a code byte): a view that claims more than this many
// times its compressed bytes is refused before anything is allocated.
constexpr size_t kMaxMeshoptExpansion = 64;

// The used compressed views: those an image names (decoded before the image headers are probed) and
// those only accessors name (decoded after the memory estimate), and what decoding them takes.
struct MeshoptPlan {
  std::vector<int> image_views, accessor_views;
  uint64_t decoded_bytes = 0;  // all of them together
};

// Checks every used EXT_meshopt_compression view (modes ATTRIBUTES, TRIANGLES, INDICES; filters
// NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL, by name) and bounds the decoded bytes of all of them by
// kMaxMeshoptExpansion times the distinct compressed bytes they read (plus 256 per view); decodes
// nothing. Throws pxf::Error("<file>: bufferView V: ...") or, over the bound, one line naming the
// file and both byte counts.
MeshoptPlan plan_meshopt_views(const tinygltf::Model& model, const std::string& file);

// Decodes the listed views in place (a view without the extension is skipped). Malformed data
// throws pxf::Error("<file>: bufferView V: ...").
void decode_meshopt_views(tinygltf::Model& model, const std::string& file, const std::vector<int>& views);

}  // namespace pxf::gltf
