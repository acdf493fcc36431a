// Byte buffers of the binary formats (state files, the guiding field): a writer that appends
// values, and a reader whose every read is bounds-checked, so that a truncated or fuzzed buffer
// ends in one pxf::Error line ("<what the buffer is> truncated in <part>"), never in a read past it.
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"

namespace pxf {

// 64-bit FNV-1a, continuing from `hash` (the formats' checksums).
inline uint64_t fnv1a64(const void* data, size_t size, uint64_t hash = 0xcbf29ce484222325ull) {
  const uint8_t* b = static_cast<const uint8_t*>(data);
  for (size_t i = 0; i < size; ++i) hash = (hash ^ b[i]) * 0x100000001b3ull;
  return hash;
}

class ByteReader;

// A checksummed blob: an 8-byte magic first, the FNV-1a of everything before it last. Checks the
// size and the magic (one pxf::Error line naming `name`) and returns a reader over what lies
// between, after the magic; *checksum_ok says whether the checksum matches (checked by the
// caller after its version, so that another version is named as such, not as corrupt).
inline ByteReader open_checksummed(const uint8_t* data, size_t size, const char (&magic)[8], const char* name,
                                   bool* checksum_ok);

class ByteWriter {
 public:
  template <class T>
  void put(const T& v) { put_bytes(&v, sizeof(T)); }
  template <class T>
  void put_array(const std::vector<T>& v) { put_bytes(v.data(), v.size() * sizeof(T)); }
  void put_bytes(const void* p, size_t n) {
    const uint8_t* b = static_cast<const uint8_t*>(p);
    bytes.insert(bytes.end(), b, b + n);
  }
  std::vector<uint8_t> bytes;
};

class ByteReader {
 public:
  // `name`: what the buffer is, for the messages ("state file").
  ByteReader(const uint8_t* data, size_t size, const char* name) : data_(data), size_(size), name_(name) {}
  template <class T>
  T get(const char* what) {
    T v;
    get_bytes(&v, sizeof(T), what);
    return v;
  }
  template <class T>
  void get_array(std::vector<T>& v, size_t count, const char* what) {
    if (count > remaining() / sizeof(T)) truncated(what);
    v.resize(count);
    get_bytes(v.data(), count * sizeof(T), what);
  }
  // A u64 count of items of at least `item_bytes` bytes each, checked against what is left before
  // anything is allocated for them.
  size_t get_count(size_t item_bytes, const char* what) {
    const uint64_t count = get<uint64_t>(what);
    if (count > remaining() / item_bytes) truncated(what);
    return static_cast<size_t>(count);
  }
  void get_bytes(void* out, size_t n, const char* what) {
    if (n > remaining()) truncated(what);
    if (n == 0) return;  // an empty array: its data() may be null, which memcpy must not get
    std::memcpy(out, data_ + pos_, n);
    pos_ += n;
  }
  size_t remaining() const { return size_ - pos_; }
  size_t pos() const { return pos_; }

 private:
  [[noreturn]] void truncated(const char* what) const {
    throw Error(std::string(name_) + " truncated in " + what);
  }
  const uint8_t* data_;
  size_t size_, pos_ = 0;
  const char* name_;
};

inline ByteReader open_checksummed(const uint8_t* data, size_t size, const char (&magic)[8], const char* name,
                                   bool* checksum_ok) {
  if (data == nullptr || size < sizeof(magic) + sizeof(uint64_t))
    throw Error(std::string(name) + " truncated (" + std::to_string(size) + " bytes)");
  uint64_t checksum;
  std::memcpy(&checksum, data + size - sizeof checksum, sizeof checksum);
  ByteReader r(data, size - sizeof checksum, name);
  for (char c : magic)
    if (r.get<char>("header") != c) throw Error(std::string("not a ") + name + " (bad magic)");
  *checksum_ok = checksum == fnv1a64(data, size - sizeof checksum);
  return r;
}

}  // namespace pxf
