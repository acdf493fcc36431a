// Light through openings (docs/sampling.md#light-through-openings): next event estimation samples
// an environment by its radiance, the same from every point. In a room lit through a window most
// of those directions (the sun's above all) are blocked by the walls, and the few that leave by
// the window carry all the light, so the estimate is a field of speckles. EnvironmentVisibility
// learns, per region of the scene and side of its surfaces, how much light each part of the sky
// brought through the shadow rays that reached it, and a vertex there draws up to half of its
// environment directions from what its region learned (VisibleSky), the rest by radiance as before.
// The two are combined as one mixture pdf, so every sample stays unbiased whatever was learned.
//
// Regions: a uniform grid of at most kMaxCells cells over the scene's box, each cell split by the
// side its surfaces face (the axis nearest the normal, with its sign: the two sides of a wall, or
// of a thin object, see different skies). Directions: kBinsU x kBinsV bins of the equirect map,
// uniform inside a bin (on the map): a sun is found by the other half of the samples, drawn by
// radiance, and a learned region sees little of it anyway.
//
// Learning: every unblocked environment sample of NEE adds luminance(L) / pdf to its region's bin,
// an unbiased estimate of the light the bin brings to the region's points; so does the sky a BSDF
// sample reaches. Sums are fixed-point integers added atomically, so they do not depend on the
// thread count or the order of the adds. After the field's frames 1, 2, 4, ..., kLearningFrames
// (end_frame) each region with at least kMinRecords unblocked records samples its bins in
// proportion to its sums (each bin lent a share of its neighbours'); then learning stops.
//
// A scene that sees most of its sky does not need any of this: when at the field's frame
// kDormantCheckFrame more than kOpenSkyFraction of all NEE's environment light got through, the
// field goes dormant (dormant()): the renderer stops asking it and the scene is sampled by radiance
// alone, at no cost (an object under a sky, a landscape).
//
// How much a region draws from what it learned follows the share of NEE's environment light that
// its shadow rays found unblocked (learned_share): where most of the sky is visible, sampling by
// radiance already finds it, and a region's average visibility would only mislead its points whose
// own sky differs (the sunlit and the shaded strands of a wicker chair share a region).
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "pathtracer/sampling.h"
#include "scene/scene.h"

namespace pxf {

class EnvironmentVisibility;

// One region's learned distribution over the bins, flat (a sample reads about three cache lines):
// the rows' CDF over v, each row's CDF over u, and the share of the region's samples drawn from it.
struct LearnedBins {
  static constexpr int kU = 32, kV = 16;
  float share;  // first: read with the rows' CDF, in the same cache line
  float row_cdf[kV + 1];
  float cdf[kV][kU + 1];
  float pmf(int x, int y) const { return (row_cdf[y + 1] - row_cdf[y]) * (cdf[y][x + 1] - cdf[y][x]); }
};

// One region's learned sky, as a vertex there samples it: the light sampler mixes it with the
// environment's own distribution (LightSampler::sample's `sky`).
class VisibleSky {
 public:
  VisibleSky() = default;  // none: the environment is sampled by radiance alone
  bool learned() const { return bins_ != nullptr; }
  // A unit direction from the region's distribution and its solid-angle density (= pdf(direction));
  // `uv`: its place on the equirect map.
  glm::vec3 sample(glm::vec2 u, float* pdf, glm::vec2* uv = nullptr) const;
  float pdf(const glm::vec3& direction) const;
  // The same at a direction whose place on the map is known.
  float density(glm::vec2 uv, const glm::vec3& direction) const;
  // The region it belongs to (EnvironmentVisibility::kNoRegion: none), learned or not: where
  // the vertex's environment samples are recorded.
  uint32_t region() const { return region_; }
  // The share of the region's environment samples drawn from what it learned (the rest by radiance).
  float share() const { return share_; }

 private:
  friend class EnvironmentVisibility;
  const EnvironmentVisibility* field_ = nullptr;
  const LearnedBins* bins_ = nullptr;
  uint32_t region_ = 0xffffffffu;  // EnvironmentVisibility::kNoRegion
  float share_ = 0.0f;
};

class EnvironmentVisibility {
 public:
  static constexpr int kBinsU = LearnedBins::kU, kBinsV = LearnedBins::kV, kBins = kBinsU * kBinsV;
  static constexpr uint32_t kMaxCells = 4096;
  static constexpr int kSides = 6;
  // A region needs this many unblocked records before its distribution is sampled.
  static constexpr uint32_t kMinRecords = 8;
  // A learned region draws learned_share(v) of its environment samples from what it learned, v the
  // share of NEE's environment light its shadow rays found unblocked: kMaxLearnedShare while at
  // most a quarter got through, none from three quarters on, linear between.
  static constexpr float kMaxLearnedShare = 0.5f;
  static float learned_share(double visible_fraction);
  static constexpr uint32_t kNoRegion = 0xffffffffu;
  static constexpr uint64_t kDormantCheckFrame = 4;
  static constexpr uint64_t kLearningFrames = 64;
  static constexpr double kOpenSkyFraction = 0.5;

  // The environment's radiance (for the fixed-point unit) and the box the regions cover. Throws pxf::Error on a box that is not finite or not ordered.
  EnvironmentVisibility(const Environment& environment, glm::vec3 lo, glm::vec3 hi);
  ~EnvironmentVisibility();

  // The region of a surface point whose side faces `normal`; kNoRegion outside the box.
  uint32_t region(const glm::vec3& position, const glm::vec3& normal) const;
  // What region `region` learned (not learned() before it has, or for kNoRegion); its region()
  // is `region` either way.
  VisibleSky sky(uint32_t region) const;
  // An environment sample at a point of `region`: luminance / (its pdf without the light's
  // selection, any constant factor), whether it reached the sky, and whether NEE drew it (else a
  // BSDF sample that escaped); thread-safe, during tracing.
  void record(uint32_t region, const glm::vec3& direction, float luminance_over_pdf, bool unblocked, bool nee);
  // After each frame (single-threaded, not during tracing): after the field's 1st, 2nd, 4th, 8th,
  // ... frame every region's distribution becomes what it has summed so far, up to frame
  // kLearningFrames; after it the distributions stay and nothing more is recorded (learning()).
  void end_frame();
  uint64_t frames() const { return frames_; }
  // Whether record() still counts: the first kLearningFrames frames. Later records would refine
  // distributions that a few hundred records per region already hold, at an atomic add each.
  bool learning() const { return frames_ < kLearningFrames; }
  // Learned nothing worth sampling and never will: see kOpenSkyFraction. Sticky; no regions learned.
  bool dormant() const { return dormant_; }
  // Whether dormant() has been decided (after the field's frame kDormantCheckFrame).
  bool judged() const { return frames_ >= kDormantCheckFrame; }

  size_t learned_regions() const;
  size_t memory_bytes() const;
  uint32_t region_count() const { return static_cast<uint32_t>(cells_) * kSides; }

  // The learned state (sums, record counts and the distributions sampled now) for a state file;
  // deserialize() restores it into a field made for the same environment and box, so a resumed
  // render continues exactly. Throws pxf::Error (one line) on anything else.
  std::vector<uint8_t> serialize() const;
  void deserialize(const uint8_t* data, size_t size);

 private:
  friend class VisibleSky;
  struct Sums;  // one region's fixed-point sums and record count
  Sums* sums_of(uint32_t region);
  bool sees_open_sky() const;

  glm::vec3 lo_, hi_;
  glm::ivec3 dims_{1};
  glm::vec3 cell_scale_{1.0f};  // cells per unit length along each axis
  size_t cells_ = 1;
  double unit_ = 1.0;  // the luminance / pdf of one fixed-point step
  uint64_t frames_ = 0;  // frames recorded since the field started
  bool dormant_ = false;
  std::unique_ptr<std::atomic<Sums*>[]> sums_;    // per region, allocated at its first record
  std::vector<int32_t> table_of_;                 // per region: its index in tables_, -1 none
  std::vector<float> share_of_;                   // per region: its table's share (sky() reads no table)
  std::vector<LearnedBins> tables_;               // the learned distributions over the bins
};

}  // namespace pxf
