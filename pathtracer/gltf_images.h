// Image decoding for the glTF loader. tinygltf hands us encoded bytes (external files and data
// URIs); images stored in buffer views are decoded after the loader has validated the view, because
// tinygltf does not bounds-check them. Decoding failures become warnings, never errors.
#pragma once
#include <string>
#include <vector>

namespace tinygltf {
class Model;
class TinyGLTF;
}

namespace pxf::gltf {

struct DecodedImage {
  int width = 0, height = 0, channels = 0;
  int bits = 8;               // 8, 16 or 32 (HDR float)
  std::vector<float> values;  // as stored, 8/16-bit scaled to [0,1], HDR as linear floats
  bool decoded = false;
  std::string failure;        // why decoding failed (empty when decoded)
};

// Holds the decoded images by glTF image index.
struct ImageStore {
  std::vector<DecodedImage> images;
  // Installs the callback that decodes uri/data-URI images into this store.
  void install(tinygltf::TinyGLTF& loader);
  // Decodes images stored in buffer views (after load); throws pxf::Error for an invalid view.
  void decode_buffer_view_images(const tinygltf::Model& model, const std::string& file);
};

// Decodes PNG/JPEG/HDR/... bytes with stb; false (and `failure` set) on error.
bool decode_image(const unsigned char* bytes, size_t size, DecodedImage& out);

}  // namespace pxf::gltf
