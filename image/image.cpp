#include "image/image.h"

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image/input_file.h"
#include "shaders/tonemap_formulas.h"

namespace pxf {

Image::Image(int w, int h, std::vector<std::string> channel_names, float fill)
    : width(w), height(h), channels(std::move(channel_names)) {
  if (w < 0 || h < 0) throw Error("image size must not be negative");
  pixels.assign(static_cast<size_t>(w) * h * channels.size(), fill);
}

Image Image::rgb(int w, int h, float fill) { return Image(w, h, {"R", "G", "B"}, fill); }
Image Image::rgba(int w, int h, float fill) { return Image(w, h, {"R", "G", "B", "A"}, fill); }
Image Image::gray(int w, int h, const std::string& name, float fill) { return Image(w, h, {name}, fill); }

int Image::channel_index(const std::string& name) const {
  auto it = std::find(channels.begin(), channels.end(), name);
  return it == channels.end() ? -1 : static_cast<int>(it - channels.begin());
}

Image sum_of(Image a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels)
    throw Error("sum_of: the images differ in size or channels");
  for (size_t i = 0; i < a.pixels.size(); ++i) a.pixels[i] += b.pixels[i];
  return a;
}

Image Image::select(const std::vector<std::string>& names) const {
  std::vector<int> source;
  for (const auto& name : names) {
    int index = channel_index(name);
    if (index < 0) throw Error("image has no channel '" + name + "'");
    source.push_back(index);
  }
  Image out(width, height, names);
  const size_t in_stride = channels.size(), out_stride = names.size();
  for (size_t p = 0; p < pixel_count(); ++p)
    for (size_t c = 0; c < out_stride; ++c) out.pixels[p * out_stride + c] = pixels[p * in_stride + source[c]];
  return out;
}

void write_file_completely(const std::string& path, const void* data, size_t size) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(path + ": cannot create: " + std::strerror(errno));
  const char* p = static_cast<const char*>(data);
  size_t left = size;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : ENOSPC;
      ::close(fd);
      throw Error(path + ": cannot write: " + std::strerror(error));
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  // fsync: a full disk or an I/O error may only show when the data reaches the device.
  const bool synced = ::fsync(fd) == 0;
  const int sync_error = errno;
  if (::close(fd) != 0 || !synced) throw Error(path + ": cannot write: " + std::strerror(synced ? errno : sync_error));
}

void sync_folder(const std::string& folder) {
  const int fd = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // best effort: the renames themselves already happened
  ::fsync(fd);
  ::close(fd);
}

void write_file_atomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  // The rename would replace whatever the name holds: /dev/null given as an output (as root) would
  // become a regular file. Only a regular file (or a link, which is replaced, not followed) is.
  struct stat status;
  if (::lstat(path.c_str(), &status) == 0 && !S_ISREG(status.st_mode) && !S_ISLNK(status.st_mode))
    throw Error(path + ": not a regular file (" + file_kind_name(status.st_mode) + "), which pxf does not replace");
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
  try {
    write(tmp);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int error = errno;
    std::remove(tmp.c_str());
    throw Error(path + ": cannot rename temporary file into place: " + std::strerror(error));
  }
  const size_t slash = path.rfind('/');
  sync_folder(slash == std::string::npos ? "" : path.substr(0, slash));
}

float srgb_from_linear(float v) { return shared::srgb_encode(v); }

float linear_from_srgb(float v) {
  if (!(v > 0.0f)) return 0.0f;
  if (v <= 0.04045f) return v / 12.92f;
  return std::pow((v + 0.055f) / 1.055f, 2.4f);
}

const Image& layer_image(const std::vector<Layer>& layers, const std::string& name) {
  for (const Layer& l : layers)
    if (l.name == name) return l.image;
  throw Error("no buffer named '" + name + "'");
}

}  // namespace pxf
