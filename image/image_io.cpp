// EXR (OpenEXR, multi-layer, 32-bit float) and PNG/JPEG/HDR (stb) input and output.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfOutputFile.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "image/image.h"

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

void check_layers(const std::string& path, const std::vector<Layer>& layers) {
  if (layers.empty()) throw Error(path + ": no layer to write");
  const Image& first = layers.front().image;
  if (first.empty()) throw Error(path + ": empty image");
  for (const Layer& layer : layers)
    if (layer.image.width != first.width || layer.image.height != first.height)
      throw Error(path + ": layer '" + layer.name + "' has a different size than the others");
}

}  // namespace

void write_exr(const std::string& path, const Image& image) { write_exr(path, std::vector<Layer>{{"", image}}); }

void write_exr(const std::string& path, const std::vector<Layer>& layers) {
  check_layers(path, layers);
  const int width = layers.front().image.width, height = layers.front().image.height;
  write_file_atomically(path, [&](const std::string& tmp) {
    try {
      Imf::Header header(width, height);
      header.compression() = Imf::ZIP_COMPRESSION;
      Imf::FrameBuffer frame;
      for (const Layer& layer : layers) {
        const Image& img = layer.image;
        const size_t x_stride = sizeof(float) * img.channels.size();
        for (int c = 0; c < img.num_channels(); ++c) {
          const std::string name = exr_channel_name(layer.name, img.channels[c]);
          header.channels().insert(name, Imf::Channel(Imf::FLOAT));
          char* base = reinterpret_cast<char*>(const_cast<float*>(img.pixels.data() + c));
          frame.insert(name, Imf::Slice(Imf::FLOAT, base, x_stride, x_stride * width));
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
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    const int width = window.max.x - window.min.x + 1, height = window.max.y - window.min.y + 1;
    if (width <= 0 || height <= 0) throw Error(path + ": empty data window");

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
        // The slice base is shifted so that data-window pixel (min.x, min.y) lands at index 0.
        char* base = reinterpret_cast<char*>(img.pixels.data() + c) -
                     static_cast<ptrdiff_t>(window.min.x) * x_stride -
                     static_cast<ptrdiff_t>(window.min.y) * x_stride * width;
        frame.insert(exr_channel_name(layer.name, img.channels[c]),
                     Imf::Slice(Imf::FLOAT, base, x_stride, x_stride * width, 1, 1, 0.0));
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
  int w = 0, h = 0, n = 0;
  static const std::vector<std::vector<std::string>> names = {{}, {"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  auto make = [&](auto* data, float scale) {
    if (!data) throw Error(path + ": cannot read image: " + (stbi_failure_reason() ? stbi_failure_reason() : "unknown"));
    Image img(w, h, names.at(n));
    for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = static_cast<float>(data[i]) * scale;
    stbi_image_free(data);
    return img;
  };
  if (stbi_is_hdr(path.c_str())) return make(stbi_loadf(path.c_str(), &w, &h, &n, 0), 1.0f);
  if (stbi_is_16_bit(path.c_str())) return make(stbi_load_16(path.c_str(), &w, &h, &n, 0), 1.0f / 65535.0f);
  return make(stbi_load(path.c_str(), &w, &h, &n, 0), 1.0f / 255.0f);
}

}  // namespace pxf
