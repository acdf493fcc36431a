#include "pathtracer/gltf_images.h"

#include <stb_image.h>
#include <tiny_gltf.h>

#include <climits>

#include "pathtracer/gltf_accessor.h"

namespace pxf::gltf {

bool decode_image(const unsigned char* bytes, size_t size, DecodedImage& out) {
  out = DecodedImage{};
  if (size == 0 || size > static_cast<size_t>(INT_MAX)) {
    out.failure = "empty or oversized image data";
    return false;
  }
  int len = static_cast<int>(size);
  int w = 0, h = 0, c = 0;
  size_t n = 0;
  if (stbi_is_hdr_from_memory(bytes, len)) {
    float* data = stbi_loadf_from_memory(bytes, len, &w, &h, &c, 0);
    out.bits = 32;
    if (data) {
      n = static_cast<size_t>(w) * h * c;
      out.values.assign(data, data + n);
      stbi_image_free(data);
    }
  } else if (stbi_is_16_bit_from_memory(bytes, len)) {
    stbi_us* data = stbi_load_16_from_memory(bytes, len, &w, &h, &c, 0);
    out.bits = 16;
    if (data) {
      n = static_cast<size_t>(w) * h * c;
      out.values.resize(n);
      for (size_t i = 0; i < n; ++i) out.values[i] = data[i] / 65535.0f;
      stbi_image_free(data);
    }
  } else {
    stbi_uc* data = stbi_load_from_memory(bytes, len, &w, &h, &c, 0);
    if (data) {
      n = static_cast<size_t>(w) * h * c;
      out.values.resize(n);
      for (size_t i = 0; i < n; ++i) out.values[i] = data[i] / 255.0f;
      stbi_image_free(data);
    }
  }
  if (n == 0 || c < 1 || c > 4) {
    const char* reason = stbi_failure_reason();
    out = DecodedImage{};
    out.failure = reason ? reason : "unsupported image format";
    return false;
  }
  out.width = w;
  out.height = h;
  out.channels = c;
  out.decoded = true;
  return true;
}

namespace {

// tinygltf's image callback. Images in buffer views are skipped here (their bytes are not yet
// validated); everything else is decoded now. Always returns true so a bad texture never fails the
// whole load.
bool load_image_callback(tinygltf::Image* image, const int image_index, std::string*, std::string*, int, int,
                         const unsigned char* bytes, int size, void* user) {
  auto* store = static_cast<ImageStore*>(user);
  if (image_index < 0) return true;
  if (store->images.size() <= static_cast<size_t>(image_index)) store->images.resize(image_index + 1);
  if (image->bufferView >= 0) return true;
  decode_image(bytes, size > 0 ? static_cast<size_t>(size) : 0, store->images[image_index]);
  image->width = store->images[image_index].width;
  image->height = store->images[image_index].height;
  return true;
}

}  // namespace

void ImageStore::install(tinygltf::TinyGLTF& loader) { loader.SetImageLoader(load_image_callback, this); }

void ImageStore::decode_buffer_view_images(const tinygltf::Model& model, const std::string& file) {
  images.resize(model.images.size());
  for (size_t i = 0; i < model.images.size(); ++i) {
    const tinygltf::Image& image = model.images[i];
    if (image.bufferView < 0) continue;
    ByteRange bytes = buffer_view_bytes(model, image.bufferView, file, "image " + std::to_string(i));
    decode_image(bytes.data, bytes.size, images[i]);
  }
}

}  // namespace pxf::gltf
