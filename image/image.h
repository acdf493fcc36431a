// pxf::Image — the one image type used by the path tracer, the GL passes, the tools and the tests.
// Float pixels with named, interleaved channels ("R","G","B","A", or "Y", ...), top row first.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/error.h"

namespace pxf {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;
  std::vector<float> pixels;  // width * height * channels.size()

  Image() = default;
  Image(int width, int height, std::vector<std::string> channel_names, float fill = 0.0f);
  static Image rgb(int width, int height, float fill = 0.0f);
  static Image rgba(int width, int height, float fill = 0.0f);
  static Image gray(int width, int height, const std::string& name = "Y", float fill = 0.0f);

  bool empty() const { return width == 0 || height == 0; }
  int num_channels() const { return static_cast<int>(channels.size()); }
  size_t pixel_count() const { return static_cast<size_t>(width) * height; }
  int channel_index(const std::string& name) const;  // -1 when absent
  float& at(int x, int y, int c) { return pixels[(static_cast<size_t>(y) * width + x) * channels.size() + c]; }
  float at(int x, int y, int c) const { return pixels[(static_cast<size_t>(y) * width + x) * channels.size() + c]; }
  // A copy holding only the named channels, in that order; throws pxf::Error when one is missing.
  Image select(const std::vector<std::string>& names) const;
};

// a + b, sample by sample (LV + HV = the unfiltered image); throws pxf::Error unless both have the
// same size and channels.
Image sum_of(Image a, const Image& b);

// A named layer of a multi-layer EXR; channels are stored as "<layer>.<channel>" ("" = no prefix).
struct Layer {
  std::string name;
  Image image;
};
// The layer called `name`; throws pxf::Error naming it when there is none.
const Image& layer_image(const std::vector<Layer>& layers, const std::string& name);

// Writes go to "<path>.tmp-<pid>" and are renamed, so an interrupted run never leaves a truncated file.
// A `path` that exists and is not a regular file or a symbolic link (a device such as /dev/null, a
// FIFO, a directory) is refused with one line before anything is written: the rename would replace it.
void write_file_atomically(const std::string& path, const std::function<void(const std::string& tmp_path)>& write);
// Writes `size` bytes to `path`, checking every write, the fsync and the close; throws pxf::Error
// naming the file (a full disk included).
void write_file_completely(const std::string& path, const void* data, size_t size);
// fsync of a folder, so that renames into it survive a crash (best effort).
void sync_folder(const std::string& folder);

// The readers refuse images of more float samples (width x height x channels) than this: 8 GiB of
// pixels, from a header that is corrupt far more often than it is real.
constexpr size_t kMaxImageSamples = size_t{1} << 31;
// The image files the readers open (image/input_file.h checks the size before a byte is read).
// stb takes the length of its input as an int: 2 GiB - 1. An EXR at the sample cap, stored raw at
// 4 bytes a sample (FLOAT or UINT; the compressors store a chunk raw rather than let it grow), is
// 8 GiB of pixels; the same again leaves room for the header, the offset tables and the chunk
// framing, so the bound is 16 GiB.
constexpr uint64_t kMaxStbImageFileBytes = 0x7fffffff;
constexpr uint64_t kMaxExrFileBytes = 2 * 4 * uint64_t{kMaxImageSamples};

// ZIP-compressed. Samples are stored as 32-bit floats, or with `half_float` as 16-bit half floats (about
// 3 decimal digits; magnitudes beyond 65504 become infinite, so a caller clamps first where that matters).
void write_exr(const std::string& path, const Image& image, bool half_float = false);
void write_exr(const std::string& path, const std::vector<Layer>& layers, bool half_float = false);
std::vector<Layer> read_exr_layers(const std::string& path);
// The same from a file image in memory (the file reader reads the bytes and calls this); `name`
// prefixes error messages.
// `max_samples` bounds width x height x channels; a larger image is refused before anything is allocated.
std::vector<Layer> read_exr_layers_from_memory(const void* data, size_t size, const std::string& name,
                                               size_t max_samples = kMaxImageSamples);
// The named layer, or with "" the unprefixed channels (else a layer named "final", else the first).
Image read_exr(const std::string& path, const std::string& layer = "");

// 8-bit PNG of display values already in [0,1] display (sRGB-encoded) space; clamps; NaN -> 0.
void write_png(const std::string& path, const Image& display);
// Loads PNG/JPEG/HDR through stb; 8-bit data is returned as stored (no transfer curve applied),
// 16-bit data is scaled to [0,1], HDR as linear floats. Channels named R,G,B,A (or Y, YA).
Image read_ldr_or_hdr(const std::string& path);
Image read_ldr_or_hdr_from_memory(const void* data, size_t size, const std::string& name,
                                  size_t max_samples = kMaxImageSamples);
// Throws pxf::Error for image data that stb mishandles: Radiance HDR with a zero-length run (stb
// loops forever) or cut short (stb fills zeros), a PNG chunk longer than the data (stb allocates the
// declared length first, up to 2 GiB). Call it before any stbi_load*_from_memory
// (read_ldr_or_hdr_from_memory does).
void check_image_data(const void* data, size_t size, const std::string& name);

// Rec. 709 luminance of linear RGB.
inline float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }
float srgb_from_linear(float linear);
float linear_from_srgb(float encoded);

// Error metrics (docs/metrics.md), one implementation for tests, bench and `pxf diff`.
struct ImageMetrics {
  double rmse = 0;           // over finite pixels of the compared channels
  double nrmse_percent = 0;  // 100 * rmse / mean(reference)
  double rel_mse = 0;        // mean((t - r)^2 / (r^2 + 1e-2))
  double max_abs_diff = 0;
  double reference_mean = 0;
  double test_mean = 0;  // over the same samples: test_mean / reference_mean is the image's bias
  size_t nan_count = 0;  // samples of the test image (not pixels) that are NaN
  size_t inf_count = 0;  // ... or +-Inf
  size_t samples = 0;    // compared finite samples
  size_t reference_nonfinite = 0;  // samples of the reference that are NaN or +-Inf (skipped)
};
// Compares the channels the two images share by name, ignoring "A". With a mask (channel 0, same
// size), pixels whose mask is > 0 are left out. Throws pxf::Error on a size mismatch, when they
// share no channel, or when the reference has no finite sample to compare against.
ImageMetrics compare_images(const Image& test, const Image& reference, const Image* mask = nullptr);
size_t count_nonfinite(const Image& image);
// What every command that takes a reference (pxf diff, pxf bench --reference) checks before it
// compares: no NaN or Inf sample in any channel. Throws pxf::Error naming `path` and the count.
void check_reference(const Image& reference, const std::string& path);
std::string format_metrics(const ImageMetrics& m);

}  // namespace pxf
