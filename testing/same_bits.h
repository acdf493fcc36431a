// Bit-for-bit equality of two arrays, for the tests that check a render is exactly another.
#pragma once
#include <cstring>
#include <vector>

namespace pxf {

// The same size and the same bytes. (memcmp of an empty vector's data(), which may be null, would
// be undefined even with a size of 0.)
template <typename T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

}  // namespace pxf
