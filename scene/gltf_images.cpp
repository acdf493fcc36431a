#include "scene/gltf_images.h"

#include <stb_image.h>
#include <tiny_gltf.h>
#include <webp/decode.h>

#include <climits>
#include <cstdint>
#include <cstring>

#include "image/image.h"
#include "scene/gltf_accessor.h"

namespace pxf::gltf {

namespace {

// EXT_texture_webp's images: "RIFF", a length, "WEBP".
bool is_webp(const unsigned char* bytes, size_t size) {
  return size >= 12 && std::memcmp(bytes, "RIFF", 4) == 0 && std::memcmp(bytes + 8, "WEBP", 4) == 0;
}

ImageHeader probe_webp(const unsigned char* bytes, size_t size) {
  ImageHeader header;
  WebPBitstreamFeatures features;
  if (WebPGetFeatures(bytes, size, &features) != VP8_STATUS_OK) return header;
  header.width = features.width;
  header.height = features.height;
  header.channels = features.has_alpha ? 4 : 3;
  header.ok = header.width > 0 && header.height > 0;
  return header;
}

// 8-bit RGBA like stb's 8-bit images (a missing alpha becomes 255).
bool decode_webp(const unsigned char* bytes, size_t size, DecodedImage& out) {
  const ImageHeader header = probe_webp(bytes, size);
  int width = 0, height = 0;
  uint8_t* rgba = header.ok ? WebPDecodeRGBA(bytes, size, &width, &height) : nullptr;
  if (!rgba) {
    out.failure = "malformed WebP data";
    return false;
  }
  out.bytes.assign(rgba, rgba + static_cast<size_t>(width) * height * 4);
  WebPFree(rgba);
  out.width = width;
  out.height = height;
  out.channels = header.channels;
  out.decoded = true;
  return true;
}

}  // namespace

ImageHeader probe_image(const unsigned char* bytes, size_t size) {
  ImageHeader header;
  if (size == 0 || size > static_cast<size_t>(INT_MAX)) return header;
  if (is_webp(bytes, size)) return probe_webp(bytes, size);
  int len = static_cast<int>(size);
  if (!stbi_info_from_memory(bytes, len, &header.width, &header.height, &header.channels)) {
    // stb refuses PNG headers whose image would exceed 1 GiB; the size is still worth reporting.
    static const unsigned char kPng[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
    if (size < 26 || std::memcmp(bytes, kPng, sizeof kPng) != 0) return ImageHeader{};
    auto u32 = [&](size_t at) {
      return (uint32_t(bytes[at]) << 24) | (uint32_t(bytes[at + 1]) << 16) | (uint32_t(bytes[at + 2]) << 8) | bytes[at + 3];
    };
    const uint32_t w = u32(16), h = u32(20);
    if (w == 0 || h == 0 || w > INT_MAX || h > INT_MAX) return ImageHeader{};
    header.width = static_cast<int>(w);
    header.height = static_cast<int>(h);
    header.channels = 4;
    header.bits = bytes[24] == 16 ? 16 : 8;
    header.ok = true;
    return header;
  }
  header.bits = stbi_is_hdr_from_memory(bytes, len) ? 32 : stbi_is_16_bit_from_memory(bytes, len) ? 16 : 8;
  header.ok = header.width > 0 && header.height > 0;
  return header;
}

bool decode_image(const unsigned char* bytes, size_t size, DecodedImage& out) {
  out = DecodedImage{};
  if (size == 0 || size > static_cast<size_t>(INT_MAX)) {
    out.failure = "empty or oversized image data";
    return false;
  }
  if (is_webp(bytes, size)) return decode_webp(bytes, size, out);
  int len = static_cast<int>(size);
  int w = 0, h = 0, c = 0;
  size_t n = 0;
  try {
    check_image_data(bytes, size, "image");
  } catch (const Error&) {
    out.failure = "truncated or corrupt image data";
    return false;
  }
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
    // Expanded to RGBA by stb: gray to (g, g, g), a missing alpha to 255.
    stbi_uc* data = stbi_load_from_memory(bytes, len, &w, &h, &c, 4);
    if (data) {
      n = static_cast<size_t>(w) * h * 4;
      out.bytes.assign(data, data + n);
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

bool keep_image_bytes(ImageStore& store, int index, const unsigned char* bytes, int size) {
  if (index < 0) return true;
  if (store.encoded_.size() <= static_cast<size_t>(index)) store.encoded_.resize(index + 1);
  if (bytes && size > 0) store.encoded_[index].assign(bytes, bytes + size);
  return true;
}

namespace {

// tinygltf's image callback. Images in buffer views are skipped here (their bytes are not yet
// validated); the others' bytes are kept for decoding once the loader knows which are used.
// Always returns true so a bad texture never fails the whole load.
bool load_image_callback(tinygltf::Image* image, const int image_index, std::string*, std::string*, int, int,
                         const unsigned char* bytes, int size, void* user) {
  if (image->bufferView >= 0) return true;
  return keep_image_bytes(*static_cast<ImageStore*>(user), image_index, bytes, size);
}

}  // namespace

void ImageStore::install(tinygltf::TinyGLTF& loader) { loader.SetImageLoader(load_image_callback, this); }

ByteRange ImageStore::bytes(const tinygltf::Model& model, int index, const std::string& file) const {
  if (index < 0 || index >= static_cast<int>(model.images.size())) return {};
  const tinygltf::Image& image = model.images[index];
  if (image.bufferView >= 0) return buffer_view_bytes(model, image.bufferView, file, "image " + std::to_string(index));
  if (index >= static_cast<int>(encoded_.size()) || encoded_[index].empty()) return {};
  return {encoded_[index].data(), encoded_[index].size()};
}

}  // namespace pxf::gltf
