// EXT_meshopt_compression with meshoptimizer's decoders (gltfpack's output). A compressed
// bufferView names its compressed bytes in the extension; it is decoded once, before any accessor
// is read, into a buffer of its own that the view then points at (the file's fallback buffer
// holds nothing: gltf_prepass.h).
#pragma once
#include <cstddef>
#include <string>

namespace tinygltf {
class Model;
}

namespace pxf::gltf {

// meshoptimizer's codecs expand at most 64-fold (an attribute byte channel of 16 equal vertices
// costs 2 header bits; an index at least a code byte): a view that claims more than this many
// times its compressed bytes is refused before anything is allocated.
constexpr size_t kMaxMeshoptExpansion = 64;

// Decodes every EXT_meshopt_compression bufferView of `model` in place (modes ATTRIBUTES,
// TRIANGLES, INDICES; filters NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL). Malformed data throws
// pxf::Error("<file>: bufferView V: ...").
void decode_meshopt_views(tinygltf::Model& model, const std::string& file);

}  // namespace pxf::gltf
