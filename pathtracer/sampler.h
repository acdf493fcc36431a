// The random numbers of a path: an Owen-scrambled Sobol sampler (the default) or independent PCG32
// draws (the old path, kept for comparison). Either way a path's numbers depend only on
// (seed, pixel, frame) and the dimension asked for, never on threads or tiles, so frame k of pixel
// p can be recomputed anywhere (progressive accumulation, checkpoints, shards).
//
// Sobol: shuffled, Owen-scrambled 4D Sobol padded per group of dimensions (Burley 2020, "Practical
// Hash-based Owen Scrambling", JCGT 9(4)). Each group below is its own 4D Sobol sequence whose
// index is shuffled by a nested uniform scramble (a permutation of every prefix of 2^m indices, so
// every power-of-two prefix keeps its stratification) and whose coordinates are Owen scrambled
// with hashes seeded by (seed, pixel, replicate, group). Per-pixel seeds decorrelate pixels; the
// per-group shuffles decorrelate groups (padding). The 2D sample pairs always take Sobol
// dimensions 0 and 1, which form a (0,2)-sequence: every 2^m-prefix is a (0,m,2)-net.
//
// Dimension table (group: Sobol dimension -> use):
//   camera            : 0,1 pixel jitter (box filter; the pinhole camera has no lens)
//   vertex v, light   : 0,1 light selection and point on the light (2D: 0 picks the light and,
//                       rescaled, is the point's first coordinate; dimension 2 is unused)
//   vertex v, bsdf    : 0,1 BSDF direction (2D) | 2 BSDF lobe | 3 Russian roulette
//   vertex v, specular: 0,1 direction in the chosen object's cone (2D) | 2 object selection
//   (with TraceParams::specular_sampling, or where TraceParams::specular_chains plans a chain;
//   the chain's delta choices: one group per bounce b)
//   vertex v, guiding : 0,1 guided direction (2D) | 2 guided-vs-BSDF choice (TraceParams::guiding,
//                       only at non-delta vertices once the field is trained: docs/guiding.md)
// Group ids: camera = 0, light of vertex v = 2v, bsdf of vertex v = 2v + 1 (v >= 2); specular
// sampling of vertex v = 4096 + v, its chain bounce b = 8192 + 1024 v + b (v, b < 1024: --max-vertices caps both);
// guiding of vertex v = kGuidingGroup + v (above every chain group).
// Only the coordinates a vertex uses are computed (no lobe with one lobe, no roulette before
// --rr-start, no light sample on a delta surface).
// The path leaves the Sobol sequences after its first non-delta bounce (leave_qmc): the vertices
// after it draw PCG32 numbers. The light that reaches the eye directly or through delta surfaces
// (LV), the first bounce's direction and everything before keep their low-discrepancy numbers;
// the deeper vertices gained nothing measurable from them (docs/sampling.md) and cost the most.
//
// Replicates (for honest variance estimates under QMC): frame k belongs to replicate k mod K and is
// point k div K of that replicate's independently scrambled sequence. The K replicate means are
// i.i.d., so their spread estimates the variance of the pixel mean (see Accumulation).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "pathtracer/rng.h"

namespace pxf {

enum class SamplerType { Sobol, Independent };
// Names of SamplerType (index = value): "sobol", "independent".
inline const std::vector<std::string>& sampler_type_names() {
  static const std::vector<std::string> names = {"sobol", "independent"};
  return names;
}

namespace sobol {

constexpr int kDimensions = 4;

// Sobol generator matrices, one 32-bit column per index bit, most significant output bit first.
// Dimension 0 is the van der Corput sequence; dimensions 1..3 come from the primitive polynomials
// and initial direction numbers of Joe and Kuo's table new-joe-kuo-6.21201 (its dimensions 2..4):
//   d  s  a  m_1..m_s
//   2  1  0  1
//   3  2  1  1 3
//   4  3  1  1 3 1
struct JoeKuoEntry {
  int s;
  uint32_t a;
  uint32_t m[3];
};
constexpr JoeKuoEntry kJoeKuo[kDimensions - 1] = {{1, 0, {1, 0, 0}}, {2, 1, {1, 3, 0}}, {3, 1, {1, 3, 1}}};

using Matrices = std::array<std::array<uint32_t, 32>, kDimensions>;

// Bratley and Fox's recurrence: v_k = a_1 v_{k-1} ^ ... ^ a_{s-1} v_{k-s+1} ^ v_{k-s} ^ (v_{k-s} >> s).
constexpr Matrices make_matrices() {
  Matrices c{};
  for (int k = 0; k < 32; ++k) c[0][k] = 1u << (31 - k);
  for (int d = 1; d < kDimensions; ++d) {
    const JoeKuoEntry& e = kJoeKuo[d - 1];
    for (int k = 0; k < 32; ++k) {
      if (k < e.s) {
        c[d][k] = e.m[k] << (31 - k);
        continue;
      }
      uint32_t v = c[d][k - e.s] ^ (c[d][k - e.s] >> e.s);
      for (int j = 1; j < e.s; ++j)
        if ((e.a >> (e.s - 1 - j)) & 1u) v ^= c[d][k - j];
      c[d][k] = v;
    }
  }
  return c;
}
inline constexpr Matrices kMatrices = make_matrices();

inline uint32_t reverse_bits(uint32_t x) {
  x = __builtin_bswap32(x);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
}

// Coordinate `dim` of Sobol point `index` as a 32-bit fixed-point fraction (bit 31 = 1/2).
inline uint32_t sample_bits(uint32_t index, int dim) {
  uint32_t x = 0;
  for (int k = 0; index != 0; index >>= 1, ++k)
    if (index & 1u) x ^= kMatrices[dim][k];
  return x;
}

// The same products in the bit-reversed domain where the Owen scrambles work, one table per byte:
// kReversedProducts[dim][b][v] = reverse(C_dim x reverse(v << 8b)). A shuffled index has all 32
// bits set at random, so four lookups beat a loop over its bits, and no reversal is needed
// between the index shuffle and the coordinate scramble.
using ByteProducts = std::array<std::array<std::array<uint32_t, 256>, 4>, kDimensions>;
constexpr uint32_t constexpr_reverse(uint32_t x) {
  uint32_t r = 0;
  for (int i = 0; i < 32; ++i) r |= ((x >> i) & 1u) << (31 - i);
  return r;
}
constexpr ByteProducts make_reversed_products() {
  ByteProducts t{};
  for (int d = 0; d < kDimensions; ++d)
    for (int b = 0; b < 4; ++b)
      for (uint32_t v = 0; v < 256; ++v) {
        const uint32_t index = constexpr_reverse(v << (8 * b));
        uint32_t x = 0;
        for (int k = 0; k < 32; ++k)
          if ((index >> k) & 1u) x ^= kMatrices[d][k];
        t[d][b][v] = constexpr_reverse(x);
      }
  return t;
}
inline constexpr ByteProducts kReversedProducts = make_reversed_products();

inline uint32_t reversed_sample_bits(uint32_t reversed_index, int dim) {
  const auto& t = kReversedProducts[dim];
  const uint32_t r = reversed_index;
  return t[0][r & 0xffu] ^ t[1][(r >> 8) & 0xffu] ^ t[2][(r >> 16) & 0xffu] ^ t[3][r >> 24];
}

// Laine-Karras style hash on bit-reversed values (Burley 2020, with Vegdahl's constants): each bit
// is flipped by a function of the bits below it only, i.e. of the more significant bits of the
// unreversed value, which is an Owen scramble: a bijection on every level of the binary tree.
inline uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

inline float to_unit_float(uint32_t x) { return static_cast<float>(x >> 8) * 0x1p-24f; }

// to_unit_float(reverse_bits(y)) with three byte look-ups instead of the full reversal: only the
// 24 bits a float keeps are reversed.
constexpr std::array<uint8_t, 256> make_byte_reversal() {
  std::array<uint8_t, 256> t{};
  for (uint32_t v = 0; v < 256; ++v)
    for (int i = 0; i < 8; ++i) t[v] |= static_cast<uint8_t>(((v >> i) & 1u) << (7 - i));
  return t;
}
inline constexpr std::array<uint8_t, 256> kByteReversal = make_byte_reversal();
inline float reversed_to_unit_float(uint32_t y) {
  const uint32_t top24 = (static_cast<uint32_t>(kByteReversal[y & 0xffu]) << 16) |
                         (static_cast<uint32_t>(kByteReversal[(y >> 8) & 0xffu]) << 8) |
                         kByteReversal[(y >> 16) & 0xffu];
  return static_cast<float>(top24) * 0x1p-24f;
}

// The Owen scramble seed of dimension `dim` of a group: the group's seed with a fixed random salt
// per dimension (no hash: the group seed is already the output of a 64-bit mix, and the scramble
// hashes its seed).
inline uint32_t dimension_seed(uint32_t group_seed, int dim) {
  constexpr uint32_t kSalt[kDimensions] = {0x68bc21ebu, 0x02e5be93u, 0x967a889bu, 0xb5f7b4c1u};
  return group_seed ^ kSalt[dim];
}

// One group of dimensions of one path: its shuffled index and its scramble seeds, derived from
// a 64-bit key once. Everything stays bit-reversed until the coordinate leaves bits().
struct ScrambledGroup {
  uint32_t reversed_shuffled_index;
  uint32_t seed;
  ScrambledGroup(uint32_t reversed_index, uint64_t key)
      : reversed_shuffled_index(laine_karras_permutation(reversed_index, static_cast<uint32_t>(key))),
        seed(static_cast<uint32_t>(key >> 32)) {}
  uint32_t reversed_bits(int dim) const {
    return laine_karras_permutation(reversed_sample_bits(reversed_shuffled_index, dim), dimension_seed(seed, dim));
  }
  uint32_t bits(int dim) const { return reverse_bits(reversed_bits(dim)); }
  float unit(int dim) const { return reversed_to_unit_float(reversed_bits(dim)); }  // = to_unit_float(bits(dim))
  glm::vec2 unit_pair() const { return glm::vec2(unit(0), unit(1)); }  // dimensions 0 and 1: a (0,2)-sequence
};

// Point `index` of the shuffled, Owen-scrambled sequence with scramble key `key`, dimension `dim`:
// nested_uniform_scramble(sample_bits(nested_uniform_scramble(index, s0), dim), s_dim).
inline uint32_t scrambled_bits(uint32_t index, int dim, uint64_t key) {
  return ScrambledGroup(reverse_bits(index), key).bits(dim);
}

}  // namespace sobol

// What the samplers derive from the frame alone, once per batch instead of once per path.
struct FrameSampling {
  FrameSampling(uint64_t seed, uint32_t frame, int replicates) : seed(seed), frame(frame) {
    // One replicate (the default): no integer division.
    const uint32_t k = replicates > 1 ? static_cast<uint32_t>(replicates) : 1u;
    const uint32_t index = k == 1 ? frame : frame / k, replicate = k == 1 ? 0u : frame % k;
    reversed_index = sobol::reverse_bits(index);
    replicate_mix = mix64(replicate + 0xd6e8feb86659fd93ULL);
    frame_mix = mix64(frame + 0x2545f4914f6cdd1dULL);
  }
  uint64_t seed;
  uint32_t frame;
  uint32_t reversed_index;  // the frame's index in its replicate, bit-reversed
  uint64_t replicate_mix, frame_mix;
};

// The sampler of one path (one pixel, one frame). Calls follow the dimension table above; the
// independent sampler ignores the dimension and draws in call order, as the integrator always did.
class PathSampler {
 public:
  PathSampler() = default;  // a placeholder: assign a seeded sampler before drawing
  PathSampler(SamplerType type, uint64_t seed, uint64_t pixel, uint32_t frame, int replicates)
      : PathSampler(type, FrameSampling(seed, frame, replicates), pixel) {}
  PathSampler(SamplerType type, const FrameSampling& f, uint64_t pixel) : type_(type) {
    if (type == SamplerType::Independent) {
      // The pixel stream's first two draws are the jitter; the path has a second stream.
      camera_rng_ = Rng(f.seed, pixel, f.frame);
      rng_ = Rng(f.seed ^ 0x5bd1e9955bd1e995ULL, pixel, f.frame);
      return;
    }
    frame_mix_ = f.frame_mix;
    reversed_index_ = f.reversed_index;
    key_ = mix64(f.seed * 0x9e3779b97f4a7c15ULL + mix64(pixel + 0x632be59bd9b4e019ULL));
    key_ = mix64(key_ ^ f.replicate_mix);
  }

  // From here on the path draws independent numbers (the vertices after its first non-delta
  // bounce: see the dimension table). No effect on an independent sampler.
  void leave_qmc() {
    if (type_ != SamplerType::Sobol) return;
    type_ = SamplerType::Independent;
    rng_ = Rng(key_ ^ frame_mix_);  // key_ holds only the replicate, not the frame
  }
  bool in_qmc() const { return type_ == SamplerType::Sobol; }

  // The numbers of a vertex's light sample and BSDF sample. A Sobol sampler scrambles the group
  // once and computes only the coordinates used (`*used`; an unused one reads 0). The
  // independent sampler draws every number, used or not, in the integrator's old call order
  // (light: selection, point; BSDF: lobe, direction, roulette), so its images stay those of before.
  // Sobol: the light is picked with point.x (LightSampler::sample(position, u, out), which keeps
  // the pair's strata on every light), `shared` is true and `select` unused.
  struct LightNumbers {
    float select = 0.0f;
    glm::vec2 point{0.0f};
    bool shared = false;
  };
  LightNumbers light_numbers(int vertex, bool used) {
    LightNumbers n;
    if (type_ == SamplerType::Independent) {
      n.select = rng_.next_float();
      n.point = rng_.next_2d();
    } else if (used) {
      const sobol::ScrambledGroup g = group(2 * vertex);
      n.point = g.unit_pair();
      n.shared = true;
    }
    return n;
  }
  struct BsdfNumbers {
    float lobe = 0.0f;
    glm::vec2 direction{0.0f};
    float roulette = 0.0f;
  };
  BsdfNumbers bsdf_numbers(int vertex, bool lobe_used, bool roulette_used) {
    BsdfNumbers n;
    if (type_ == SamplerType::Independent) {
      n.lobe = rng_.next_float();
      n.direction = rng_.next_2d();
      n.roulette = rng_.next_float();
      return n;
    }
    const sobol::ScrambledGroup g = group(2 * vertex + 1);
    n.direction = g.unit_pair();
    if (lobe_used) n.lobe = g.unit(2);
    if (roulette_used) n.roulette = g.unit(3);
    return n;
  }

  // Every Sobol number of vertex `vertex`'s light and BSDF samples, used or not (an unused one is
  // never read): what light_numbers(vertex, true) and bsdf_numbers(vertex, true, roulette_used)
  // return. For a whole batch in one loop before its vertex is shaded, where many paths' hash
  // chains overlap (in shading each path's stalled the next). Sobol paths in QMC only.
  struct VertexNumbers {
    LightNumbers light;
    BsdfNumbers bsdf;
  };
  VertexNumbers vertex_numbers(int vertex, bool roulette_used) const {
    VertexNumbers n;
    n.light.point = group(2 * vertex).unit_pair();
    n.light.shared = true;
    const sobol::ScrambledGroup g = group(2 * vertex + 1);
    n.bsdf.direction = g.unit_pair();
    n.bsdf.lobe = g.unit(2);
    if (roulette_used) n.bsdf.roulette = g.unit(3);
    return n;
  }

  glm::vec2 camera_jitter() {
    if (type_ == SamplerType::Independent) return camera_rng_.next_2d();
    return group(0).unit_pair();
  }

  // Specular sampling at vertex `vertex`: which object (select) and the direction in its cone.
  struct SpecularNumbers {
    float select = 0.0f;
    glm::vec2 direction{0.0f};
  };
  SpecularNumbers specular_numbers(int vertex) {
    const NumberAndPair n = number_and_pair(4096 + vertex);
    return {n.number, n.pair};
  }

  // Path guiding at vertex `vertex`: the guided-vs-BSDF choice and the guided direction. Drawn only
  // where guiding may be chosen, so a render without guiding draws exactly what it did before.
  static constexpr int kGuidingGroup = 1 << 21;
  struct GuidingNumbers {
    float choice = 0.0f;
    glm::vec2 direction{0.0f};
  };
  GuidingNumbers guiding_numbers(int vertex) {
    const NumberAndPair n = number_and_pair(kGuidingGroup + vertex);
    return {n.number, n.pair};
  }

  // One number and a pair: with the independent sampler two draws (the number first), else the pair
  // of Sobol group `group_index` and its third dimension.
  struct NumberAndPair {
    float number = 0.0f;
    glm::vec2 pair{0.0f};
  };
  NumberAndPair number_and_pair(int group_index) {
    NumberAndPair n;
    if (type_ == SamplerType::Independent) {
      n.number = rng_.next_float();
      n.pair = rng_.next_2d();
      return n;
    }
    const sobol::ScrambledGroup g = group(group_index);
    n.pair = g.unit_pair();
    n.number = g.unit(2);
    return n;
  }

  // The delta choice (lobe, then direction numbers) of bounce `bounce` of the specular chain
  // traced from vertex `vertex` by specular sampling.
  void get_chain(int vertex, int bounce, float* u_lobe, glm::vec2* u_dir) {
    if (type_ == SamplerType::Independent) {
      *u_lobe = rng_.next_float();
      *u_dir = rng_.next_2d();
      return;
    }
    const sobol::ScrambledGroup g = group(8192 + 1024 * vertex + bounce);
    *u_dir = g.unit_pair();
    *u_lobe = g.unit(2);
  }

 private:
  sobol::ScrambledGroup group(int id) const {
    return sobol::ScrambledGroup(reversed_index_, mix64(key_ + 0xbf58476d1ce4e5b9ULL * static_cast<uint64_t>(id + 1)));
  }

  SamplerType type_ = SamplerType::Independent;
  Rng camera_rng_, rng_;
  uint32_t reversed_index_ = 0;  // the frame's index in its replicate, bit-reversed
  uint64_t key_ = 0;
  uint64_t frame_mix_ = 0;  // FrameSampling::frame_mix
};

}  // namespace pxf
