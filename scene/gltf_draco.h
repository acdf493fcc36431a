// KHR_draco_mesh_compression with libdraco (Debian's tinygltf is built without it). Each Draco
// primitive is decoded once, into accessors of new buffers laid out as an uncompressed file
// would be (the accessor's own component type), so the rest of the loader reads it unchanged.
#pragma once
#include <string>

namespace tinygltf {
class Model;
}

namespace pxf::gltf {

// Decodes every Draco primitive of `model` in place: its compressed attributes and its indices
// then name new accessors, and its mode is TRIANGLES. The decoded counts must match the
// accessors' (the triangle cap and the memory estimate were checked against those). Malformed
// data throws pxf::Error("<file>: mesh M primitive P: ...").
void decode_draco_primitives(tinygltf::Model& model, const std::string& file);

}  // namespace pxf::gltf
