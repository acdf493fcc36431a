// Counter-based random numbers: the stream of a path depends only on (seed, pixel, frame) and the
// draw index (the dimension), never on thread scheduling, so any thread count gives the same image.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>

namespace pxf {

// SplitMix64 finalizer: a strong 64-bit mix used to derive independent stream states.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// PCG32 (O'Neill, XSH-RR), seeded by hashing (seed, pixel, frame). Draw k of a path is dimension k.
class Rng {
 public:
  Rng() = default;  // a placeholder: assign a seeded stream before drawing
  Rng(uint64_t seed, uint64_t pixel, uint64_t frame)
      : Rng(mix64(mix64(seed * 0x9e3779b97f4a7c15ULL + mix64(pixel + 0x632be59bd9b4e019ULL)) ^
                  mix64(frame + 0x85ebca6b2e4f1b3bULL))) {}
  // A stream from an already mixed 64-bit key.
  explicit Rng(uint64_t key) {
    increment_ = (mix64(key + 1) << 1u) | 1u;
    state_ = 0;
    next_u32();
    state_ += key;
    next_u32();
  }

  uint32_t next_u32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + increment_;
    uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  // Uniform in [0, 1): 24 random mantissa bits, so 1.0f is never returned.
  float next_float() { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }
  glm::vec2 next_2d() {
    float a = next_float();
    return glm::vec2(a, next_float());
  }

 private:
  uint64_t state_ = 0;
  uint64_t increment_ = 1;
};

}  // namespace pxf
