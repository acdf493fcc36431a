// EXR (OpenEXR, multi-layer, 32-bit or half float) and PNG/JPEG/HDR (stb) input and output.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfOutputFile.h>
#include <Imath/half.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>

#include "image/image.h"
#include "core/memory.h"
#include "image/input_file.h"

namespace pxf {

namespace {

std::string exr_channel_name(const std::string& layer, const std::string& channel) {
  return layer.empty() ? channel : layer + "." + channel;
}

// EXR stores channels sorted by name; put the familiar ones first so RGB(A) stays RGB(A).
int channel_rank(const std::string& name) {
  static const std::vector<std::string> order = {"R", "G", "B", "A", "Y"};
  auto it = std::find(order.begin(), order.end(), name);
  return it == order.end() ? static_cast<int>(order.size()) : static_cast<int>(it - order.begin());
}

// OpenEXR's own file stream flushes in a destructor that ignores errors (a full disk): encode into
// memory instead and write the bytes with every write checked.
class MemoryOStream : public Imf::OStream {
 public:
  MemoryOStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    const size_t end = position_ + static_cast<size_t>(n);
    if (end > bytes.size()) bytes.resize(end);
    std::copy(c, c + n, bytes.begin() + static_cast<ptrdiff_t>(position_));
    position_ = end;
  }
  uint64_t tellp() override { return position_; }
  void seekp(uint64_t pos) override { position_ = static_cast<size_t>(pos); }
  std::vector<char> bytes;

 private:
  size_t position_ = 0;
};

// OpenEXR reads from this, so a file and a buffer in memory take the same path.
class MemoryIStream : public Imf::IStream {
 public:
  MemoryIStream(const char* data, size_t size, const std::string& name)
      : Imf::IStream(name.c_str()), data_(data), size_(size) {}
  bool read(char c[], int n) override {
    if (n < 0 || static_cast<uint64_t>(n) > size_ - position_) throw Error(std::string(fileName()) + ": file is truncated");
    std::copy(data_ + position_, data_ + position_ + n, c);
    position_ += static_cast<size_t>(n);
    return position_ < size_;
  }
  uint64_t tellg() override { return position_; }
  void seekg(uint64_t pos) override {
    if (pos > size_) throw Error(std::string(fileName()) + ": file is truncated");
    position_ = static_cast<size_t>(pos);
  }

 private:
  const char* data_;
  size_t size_;
  size_t position_ = 0;
};

// Refuses, before allocating, an image whose header asks for more than `max_samples` floats.
void check_sample_count(const std::string& path, int64_t width, int64_t height, size_t channels, size_t max_samples) {
  const double samples = static_cast<double>(width) * static_cast<double>(height) * static_cast<double>(channels);
  if (samples > static_cast<double>(max_samples))
    throw Error(path + ": " + std::to_string(width) + "x" + std::to_string(height) + " pixels with " +
                std::to_string(channels) + " channels exceed the readable " + std::to_string(max_samples) +
                " samples (a corrupt header, or an image too large to load)");
  // The pixels are allocated from the header before any data is read, so a tiny file can declare
  // gigabytes. Stated and checked first, like the scene loader's estimate.
  // (A negative size from a corrupt header is the decoder's to refuse.)
  if (!(samples > 0)) return;
  const uint64_t bytes = static_cast<uint64_t>(samples) * sizeof(float), available = available_memory_bytes();
  if (available > 0 && bytes > available)
    throw Error(path + ": " + std::to_string(width) + "x" + std::to_string(height) + " pixels with " +
                std::to_string(channels) + " channels need " + std::to_string(bytes >> 20) + " MiB, more than the " +
                std::to_string(available >> 20) + " MiB of memory available");
}

void check_layers(const std::string& path, const std::vector<Layer>& layers) {
  if (layers.empty()) throw Error(path + ": no layer to write");
  const Image& first = layers.front().image;
  if (first.empty()) throw Error(path + ": empty image");
  for (const Layer& layer : layers)
    if (layer.image.width != first.width || layer.image.height != first.height)
      throw Error(path + ": layer '" + layer.name + "' has a different size than the others");
}

}  // namespace

// stb's Radiance decoder (Debian's 2022 copy) loops forever on a run-length scanline that holds a
// zero-length literal run, which is what a file cut inside its pixel data reads as (stb returns 0 past
// the end), and fills other truncated scanlines with zeros. This walks the run-length scanlines the
// same way first and refuses both.
static void check_radiance_data(const unsigned char* data, size_t size, const std::string& path) {
  size_t pos = 0;
  // Past the end stb reads zeros; `pos` counts on, so that a truncation shows as pos > size.
  auto get = [&]() -> unsigned { return pos < size ? data[pos++] : (++pos, 0u); };
  // stb's header tokens: up to a newline or the end (the last byte of a file without a newline is
  // not part of the token), at most 1023 characters, a NUL ends the token as a string.
  auto token = [&]() {
    std::string text;
    char c = static_cast<char>(get());
    while (pos < size && c != '\n') {
      text += c;
      if (text.size() == 1023) {
        while (pos < size && get() != '\n') {
        }
        break;
      }
      c = static_cast<char>(get());
    }
    return std::string(text.c_str());
  };
  token();  // the signature, checked by stb
  while (!token().empty()) {
  }
  const std::string resolution = token();
  if (resolution.compare(0, 3, "-Y ") != 0) return;
  char* rest = nullptr;
  const long height = std::strtol(resolution.c_str() + 3, &rest, 10);
  while (*rest == ' ') ++rest;
  if (std::strncmp(rest, "+X ", 3) != 0) return;
  const long width = std::strtol(rest + 3, nullptr, 10);
  if (width <= 0 || height <= 0 || width > (1 << 24) || height > (1 << 24)) return;  // stb refuses it
  // Flat pixels: 4 bytes each. Where a scanline turns out not to be run-length encoded, stb reads
  // the whole image flat from there (starting over at the first row), so all of it must be there.
  auto check_flat_rest = [&](size_t start) {
    if (static_cast<double>(size - std::min(start, size)) < 4.0 * static_cast<double>(width) * static_cast<double>(height))
      throw Error(path + ": cannot read image: file is truncated in its flat pixel data");
  };
  if (width < 8 || width >= 32768) return check_flat_rest(pos);  // stb reads these flat
  for (long y = 0; y < height; ++y) {
    const size_t start = pos;
    const unsigned c1 = get(), c2 = get(), hi = get();
    if (c1 != 2 || c2 != 2 || (hi & 0x80)) return check_flat_rest(start);
    if (((hi << 8) | get()) != static_cast<unsigned long>(width)) return;  // stb refuses it
    for (int k = 0; k < 4; ++k)
      for (long x = 0; x < width;) {
        const unsigned count = get();
        if (count > 128) {
          if (count - 128 > static_cast<unsigned long>(width - x)) return;  // stb refuses it
          x += count - 128;
          get();
        } else if (count == 0) {
          throw Error(path + ": cannot read image: truncated or corrupt run-length data in scanline " + std::to_string(y));
        } else {
          if (count > static_cast<unsigned long>(width - x)) return;  // stb refuses it
          x += count;
          pos += count;
        }
      }
    if (pos > size)
      throw Error(path + ": cannot read image: file is truncated in the run-length data of scanline " + std::to_string(y));
  }
}

// OpenEXR sizes buffers from the header while it opens a file, before a caller sees the header: an
// attribute's declared length, a line offset per scanline block, a buffer per tile. So the first
// header's attribute lengths, data window and tile size are checked here, on the raw bytes, first.
// Anything this does not understand is left to OpenEXR, which refuses it.
void check_exr_header_sizes(const unsigned char* data, size_t size, const std::string& path, size_t max_samples) {
  size_t pos = 8;  // magic number and version
  auto read_string = [&](std::string& out) {
    out.clear();
    while (pos < size && data[pos] != 0 && out.size() < 256) out += static_cast<char>(data[pos++]);
    if (pos >= size || data[pos] != 0) return false;
    ++pos;
    return true;
  };
  auto int32_at = [&](size_t at) {
    int32_t v;
    std::memcpy(&v, data + at, sizeof v);
    return v;
  };
  if (size < 8) return;
  const bool multi_part = (int32_at(4) & 0x1000) != 0;  // then headers follow each other up to an empty one
  std::string name, type;
  while (true) {
    if (!read_string(name)) return;
    if (name.empty()) {
      if (multi_part && pos < size && data[pos] != 0) continue;
      return;
    }
    if (!read_string(type) || pos + 4 > size) return;
    const int32_t length = int32_at(pos);
    pos += 4;
    // OpenEXR allocates an unknown attribute's declared size before it reads a byte of it.
    if (length < 0 || static_cast<size_t>(length) > size - pos)
      throw Error(path + ": cannot read EXR: header attribute '" + name + "' of " + std::to_string(length) +
                  " bytes runs past the end of the file (" + std::to_string(size) + " bytes)");
    // OpenEXR reads a known type by its own layout, whatever length the file declares: a length
    // that does not match the layout would leave OpenEXR reading elsewhere than this check.
    static const std::map<std::string, int> fixed_sizes = {
        {"box2i", 16}, {"box2f", 16}, {"chromaticities", 32}, {"compression", 1}, {"double", 8}, {"envmap", 1},
        {"float", 4},  {"int", 4},    {"keycode", 28},        {"lineOrder", 1},   {"m33f", 36},   {"m33d", 72},
        {"m44f", 64},  {"m44d", 128}, {"rational", 8},        {"tiledesc", 9},    {"timecode", 8}, {"v2i", 8},
        {"v2f", 8},    {"v2d", 16},   {"v3i", 12},            {"v3f", 12},        {"v3d", 24},    {"deepImageState", 1}};
    const auto fixed = fixed_sizes.find(type);
    bool consistent = fixed == fixed_sizes.end() || fixed->second == length;
    if (type == "chlist") {  // entries of a name and 16 bytes, up to an empty name
      size_t at = pos;
      const size_t end = pos + static_cast<size_t>(length);
      while (at < end && data[at] != 0) {
        while (at < end && data[at] != 0) ++at;
        at += 1 + 16;
      }
      consistent = at + 1 == end;
    } else if (type == "preview") {  // width, height, then 4 bytes per pixel
      uint32_t w = 0, h = 0;
      if (length >= 8) {
        std::memcpy(&w, data + pos, 4);
        std::memcpy(&h, data + pos + 4, 4);
      }
      consistent = length >= 8 && 8.0 + 4.0 * w * h == static_cast<double>(length);
    }
    if (!consistent)
      throw Error(path + ": cannot read EXR: header attribute '" + name + "' of type '" + type + "' has an invalid length " +
                  std::to_string(length));
    if (type == "box2i" && name == "dataWindow") {
      const int64_t width = int64_t{int32_at(pos + 8)} - int32_at(pos) + 1;
      const int64_t height = int64_t{int32_at(pos + 12)} - int32_at(pos + 4) + 1;
      if (width > 0 && height > 0) check_sample_count(path, width, height, 1, max_samples);
    } else if (type == "tiledesc" && name == "tiles") {
      uint32_t tile_width, tile_height;
      std::memcpy(&tile_width, data + pos, 4);
      std::memcpy(&tile_height, data + pos + 4, 4);
      if (static_cast<double>(tile_width) * tile_height > static_cast<double>(max_samples))
        throw Error(path + ": tiles of " + std::to_string(tile_width) + "x" + std::to_string(tile_height) +
                    " pixels exceed the readable " + std::to_string(max_samples) + " samples");
    }
    pos += static_cast<size_t>(length);
  }
}

// stb grows its PNG data buffer to each IDAT chunk's declared length before it reads the chunk, so
// a few bytes declaring a 2 GiB chunk allocate 2 GiB. Chunks are checked against the file first.
static void check_png_chunks(const unsigned char* data, size_t size, const std::string& path) {
  static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || std::memcmp(data, signature, 8) != 0) return;
  for (size_t pos = 8; pos + 8 <= size;) {
    const uint32_t length = uint32_t{data[pos]} << 24 | uint32_t{data[pos + 1]} << 16 | uint32_t{data[pos + 2]} << 8 | data[pos + 3];
    const std::string type(reinterpret_cast<const char*>(data + pos + 4), 4);
    if (length > size - pos - 8 || size - pos - 8 - length < 4)
      throw Error(path + ": cannot read image: PNG chunk '" + type + "' of " + std::to_string(length) +
                  " bytes runs past the end of the file (truncated or corrupt)");
    if (type == "IEND") return;
    pos += 12 + static_cast<size_t>(length);
  }
}

void check_image_data(const void* bytes, size_t size, const std::string& name) {
  const auto* data = static_cast<const unsigned char*>(bytes);
  check_png_chunks(data, size, name);
  if (size <= static_cast<size_t>(INT_MAX) && stbi_is_hdr_from_memory(data, static_cast<int>(size)))
    check_radiance_data(data, size, name);
}

void write_exr(const std::string& path, const Image& image, bool half_float) {
  write_exr(path, std::vector<Layer>{{"", image}}, half_float);
}

void write_exr(const std::string& path, const std::vector<Layer>& layers, bool half_float) {
  check_layers(path, layers);
  const int width = layers.front().image.width, height = layers.front().image.height;
  write_file_atomically(path, [&](const std::string& tmp) {
    try {
      Imf::Header header(width, height);
      header.compression() = Imf::ZIP_COMPRESSION;
      Imf::FrameBuffer frame;
      // OpenEXR writes a channel from a slice of its own type: half floats are converted here first.
      std::vector<std::vector<half>> halves;
      for (const Layer& layer : layers) {
        const Image& img = layer.image;
        const Imf::PixelType type = half_float ? Imf::HALF : Imf::FLOAT;
        const size_t x_stride = (half_float ? sizeof(half) : sizeof(float)) * img.channels.size();
        char* pixels = reinterpret_cast<char*>(const_cast<float*>(img.pixels.data()));
        if (half_float) {
          halves.emplace_back(img.pixels.begin(), img.pixels.end());
          pixels = reinterpret_cast<char*>(halves.back().data());
        }
        for (int c = 0; c < img.num_channels(); ++c) {
          const std::string name = exr_channel_name(layer.name, img.channels[c]);
          header.channels().insert(name, Imf::Channel(type));
          const size_t offset = (half_float ? sizeof(half) : sizeof(float)) * static_cast<size_t>(c);
          frame.insert(name, Imf::Slice(type, pixels + offset, x_stride, x_stride * width));
        }
      }
      MemoryOStream stream;
      {
        Imf::OutputFile file(stream, header);
        file.setFrameBuffer(frame);
        file.writePixels(height);
      }  // the destructor writes the line offset table
      write_file_completely(tmp, stream.bytes.data(), stream.bytes.size());
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      throw Error(path + ": cannot write EXR: " + e.what());
    }
  });
}

std::vector<Layer> read_exr_layers(const std::string& path) {
  const std::vector<unsigned char> bytes = read_input_file(path, kMaxExrFileBytes);
  return read_exr_layers_from_memory(bytes.data(), bytes.size(), path);
}

std::vector<Layer> read_exr_layers_from_memory(const void* data, size_t size, const std::string& name,
                                               size_t max_samples) {
  const std::string& path = name;
  try {
    check_exr_header_sizes(static_cast<const unsigned char*>(data), size, path, max_samples);
    MemoryIStream stream(static_cast<const char*>(data), size, name);
    Imf::InputFile file(stream);
    const Imath::Box2i window = file.header().dataWindow();
    // In 64 bits: a data window from INT_MIN to INT_MAX overflows int.
    const int64_t width64 = int64_t{window.max.x} - window.min.x + 1, height64 = int64_t{window.max.y} - window.min.y + 1;
    if (width64 <= 0 || height64 <= 0) throw Error(path + ": empty data window");
    size_t channel_count = 0;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) ++channel_count;
    check_sample_count(path, width64, height64, std::max<size_t>(channel_count, 1), max_samples);
    const int width = static_cast<int>(width64), height = static_cast<int>(height64);

    // Group "layer.channel" names by layer (the text before the last dot).
    std::map<std::string, std::vector<std::string>> by_layer;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
      const std::string name = it.name();
      const size_t dot = name.rfind('.');
      const std::string layer = dot == std::string::npos ? "" : name.substr(0, dot);
      by_layer[layer].push_back(dot == std::string::npos ? name : name.substr(dot + 1));
    }

    std::vector<Layer> layers;
    for (auto& [layer_name, names] : by_layer) {
      std::stable_sort(names.begin(), names.end(),
                       [](const std::string& a, const std::string& b) { return channel_rank(a) < channel_rank(b); });
      layers.push_back({layer_name, Image(width, height, names)});
    }
    Imf::FrameBuffer frame;
    for (Layer& layer : layers) {
      Image& img = layer.image;
      const size_t x_stride = sizeof(float) * img.channels.size();
      for (int c = 0; c < img.num_channels(); ++c) {
        // Slice::Make places data-window pixel (min.x, min.y) at the first float without forming an
        // out-of-bounds pointer (the offset goes through integer arithmetic).
        frame.insert(exr_channel_name(layer.name, img.channels[c]),
                     Imf::Slice::Make(Imf::FLOAT, img.pixels.data() + c, window, x_stride, x_stride * width, 1, 1, 0.0));
      }
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return layers;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(path + ": cannot read EXR: " + e.what());
  }
}

Image read_exr(const std::string& path, const std::string& layer) {
  std::vector<Layer> layers = read_exr_layers(path);
  for (Layer& l : layers)
    if (l.name == layer) return std::move(l.image);
  if (layer.empty()) {
    // A pxf buffers.exr has no unnamed layer: its "final" layer is what a reader wants.
    for (Layer& l : layers)
      if (l.name == "final") return std::move(l.image);
  } else {
    std::string names;
    for (const Layer& l : layers) names += (names.empty() ? "" : ", ") + (l.name.empty() ? "<default>" : l.name);
    throw Error(path + ": no layer '" + layer + "' (layers: " + names + ")");
  }
  return std::move(layers.front().image);
}

void write_png(const std::string& path, const Image& display) {
  if (display.empty()) throw Error(path + ": empty image");
  const int n = std::min(display.num_channels(), 4);
  std::vector<unsigned char> bytes(display.pixel_count() * n);
  for (size_t p = 0; p < display.pixel_count(); ++p)
    for (int c = 0; c < n; ++c) {
      const float v = display.pixels[p * display.channels.size() + c];
      const float clamped = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
      bytes[p * n + c] = static_cast<unsigned char>(std::lround(clamped * 255.0f));
    }
  std::vector<unsigned char> encoded;
  auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<std::vector<unsigned char>*>(context);
    out->insert(out->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
  };
  if (!stbi_write_png_to_func(append, &encoded, display.width, display.height, n, bytes.data(), display.width * n))
    throw Error(path + ": cannot encode PNG");
  write_file_atomically(path, [&](const std::string& tmp) { write_file_completely(tmp, encoded.data(), encoded.size()); });
}

Image read_ldr_or_hdr(const std::string& path) {
  const std::vector<unsigned char> bytes = read_input_file(path, kMaxStbImageFileBytes);
  return read_ldr_or_hdr_from_memory(bytes.data(), bytes.size(), path);
}

Image read_ldr_or_hdr_from_memory(const void* data, size_t size, const std::string& name, size_t max_samples) {
  const std::string& path = name;
  if (size == 0 || size > static_cast<size_t>(INT_MAX)) throw Error(path + ": cannot read image: empty or larger than 2 GiB");
  const auto* bytes = static_cast<const stbi_uc*>(data);
  const int len = static_cast<int>(size);
  int w = 0, h = 0, n = 0;
  // The header first: stb allocates the whole image before it decodes a pixel.
  if (stbi_info_from_memory(bytes, len, &w, &h, &n)) check_sample_count(path, w, h, static_cast<size_t>(n), max_samples);
  static const std::vector<std::vector<std::string>> names = {{}, {"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  auto make = [&](auto* pixels, float scale) {
    if (!pixels) throw Error(path + ": cannot read image: " + (stbi_failure_reason() ? stbi_failure_reason() : "unknown"));
    std::unique_ptr<void, void (*)(void*)> owner(pixels, stbi_image_free);
    if (w <= 0 || h <= 0 || n < 1 || n > 4) throw Error(path + ": cannot read image: unsupported layout");
    Image img(w, h, names[n]);
    for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = static_cast<float>(pixels[i]) * scale;
    return img;
  };
  check_image_data(bytes, size, path);
  if (stbi_is_hdr_from_memory(bytes, len)) {
    return make(stbi_loadf_from_memory(bytes, len, &w, &h, &n, 0), 1.0f);
  }
  if (stbi_is_16_bit_from_memory(bytes, len))
    return make(stbi_load_16_from_memory(bytes, len, &w, &h, &n, 0), 1.0f / 65535.0f);
  return make(stbi_load_from_memory(bytes, len, &w, &h, &n, 0), 1.0f / 255.0f);
}

}  // namespace pxf
