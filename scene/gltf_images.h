// Image decoding for the glTF loader. tinygltf hands us encoded bytes (external files and data
// URIs), which the store keeps; images stored in buffer views are read after the loader has
// validated the view, because tinygltf does not bounds-check them. Only the images a material
// uses are decoded, after their headers have been checked against the limits, and in parallel.
// Decoding failures become warnings, never errors.
#pragma once
#include <string>
#include <vector>

#include "scene/gltf_accessor.h"

namespace tinygltf {
class Model;
class TinyGLTF;
}

namespace pxf::gltf {

struct DecodedImage {
  int width = 0, height = 0, channels = 0;
  int bits = 8;                       // 8, 16 or 32 (HDR float)
  std::vector<unsigned char> bytes;   // 8-bit images: the codes as stored, expanded to RGBA
  std::vector<float> values;          // 16-bit scaled to [0,1], HDR as linear floats
  bool decoded = false;
  std::string failure;                // why decoding failed (empty when decoded)
};

// What an image's header says, without decoding it.
struct ImageHeader {
  int width = 0, height = 0, channels = 0;
  int bits = 8;     // 8, 16 or 32 (HDR float)
  bool ok = false;  // false: not an image stb can read
};

// The encoded bytes of the model's images, by glTF image index.
class ImageStore {
 public:
  // Installs the callback that keeps uri/data-URI images' bytes in this store.
  void install(tinygltf::TinyGLTF& loader);
  // Image `index`'s encoded bytes: those tinygltf read for a uri, or its validated buffer view
  // (throws pxf::Error for an invalid view); empty when the file was missing.
  ByteRange bytes(const tinygltf::Model& model, int index, const std::string& file) const;

 private:
  friend bool keep_image_bytes(ImageStore& store, int index, const unsigned char* bytes, int size);
  std::vector<std::vector<unsigned char>> encoded_;
};

// Reads the header of PNG/JPEG/HDR/... (stb) or WebP (libwebp) bytes.
ImageHeader probe_image(const unsigned char* bytes, size_t size);

// Decodes PNG/JPEG/HDR/... bytes with stb, WebP with libwebp; false (and `failure` set) on error.
bool decode_image(const unsigned char* bytes, size_t size, DecodedImage& out);

}  // namespace pxf::gltf
