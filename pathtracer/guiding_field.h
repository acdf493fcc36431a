// The guiding field of path guiding (Müller, Gross and Novák 2017, "Practical Path Guiding for
// Efficient Light-Transport Simulation"): an SD-tree that learns, per region of the scene, the
// directions incident radiance comes from, so that paths can be sent there.
//
// Spatial part: a binary tree over the scene's box (made a cube, as the paper's implementation
// does, so that cyclic x, y, z splits at the midpoint give near-cubic cells). Directional part:
// in each spatial leaf a quadtree over the cylindrical map of the sphere, (cos theta, phi) ->
// ((cos theta + 1) / 2, phi / 2 pi) in [0,1)^2, which preserves area: a density over the square
// divided by 4 pi is the solid-angle density. With settings.parallax_lobes > 0 a leaf samples
// parallax-aware vMF lobes instead (guiding_lobes.h), fitted at the end of each iteration to a
// reservoir of its records, with a guided share learned per leaf; the quadtrees are still built.
//
// Learning runs in iterations of doubling length: iteration k lasts 2^k frames (frames
// [2^k - 1, 2^(k+1) - 1) of the render; iteration_ends_after() says when to call end_iteration()).
// During an iteration, sample() and pdf() read the sampling trees (what the previous iterations
// learned) and record() collects into the building trees. end_iteration() makes what was collected
// the sampling distribution (a leaf that collected no energy keeps the one it had), splits the
// spatial leaves that received more than c * sqrt(2^k) records, refines the directional trees where
// energy concentrates (a quadrant is subdivided while it holds more than rho of its leaf's energy,
// down to max_directional_depth levels), and clears the building trees. Whether to stop learning at some point and which iterations' images to keep
// (the paper keeps only the last) is the caller's choice: not calling end_iteration() again just
// keeps the field as it is.
//
// Records go to the spatial leaf holding their position (no box-filter splatting) and to the
// directional quadrant holding their direction (no bilinear splatting).
//
// Determinism: record() only appends to a per-thread buffer. apply_records() (also called by
// end_iteration()) sorts the buffered records into a total order (spatial leaf, the caller's key,
// then the record's own bits) and adds them in that order, so the trees depend on the records and on
// where the caller calls apply_records(), never on threads or call order. The caller flushes at
// fixed points (after each frame) to keep the buffers to one frame's records (24 bytes each).
//
// Memory: the trees never take more than settings.max_bytes between calls (memory_bytes(), counted
// from the allocations). When a refinement would exceed it, the directional trees are refined with
// a coarser rho (doubled until they fit) and then spatial leaves split only while the budget lasts,
// breadth-first. The record buffers are not counted (see above).
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "pathtracer/guiding_lobes.h"

namespace pxf {

struct GuidingSettings {
  // c: a spatial leaf splits when it received more than c * sqrt(2^k) records in iteration k.
  float spatial_threshold = 12000.0f;
  // rho: a directional quadrant is subdivided while it holds more than this fraction of its leaf's energy.
  float energy_threshold = 0.01f;
  // Levels of the directional quadtrees (the paper's 20: quadrants down to 2^-20 of the square).
  int max_directional_depth = 20;
  // Both trees of every leaf together, and the spatial tree.
  uint64_t max_bytes = uint64_t(16) << 20;
  // The part of sample() that is uniform over the sphere: pdf() is never below this / (4 pi), so a
  // direction the records missed (a light no path found yet) keeps a density and no sample ever
  // gets pdf 0. In (0, 1).
  float uniform_fraction = 0.01f;
  // The directional distribution a leaf samples: 0, its quadtree (the paper's); 1 to
  // kMaxGuidingLobes, at most that many parallax-aware vMF lobes (guiding_lobes.h) fitted to
  // lobe_records photon records per leaf and iteration (the quadtrees are still built: leaves split
  // by their record counts either way).
  int parallax_lobes = 0;
  uint32_t lobe_records = 128;
  // Lobes wider than this concentration (kappa 10: about 18 degrees) are not sampled: BSDF sampling
  // serves such light about as well, so the guided samples go to concentrated light only, and the
  // renderer scales its guided share by the lobes' share that is left (Distribution::share()).
  float min_lobe_kappa = 10.0f;
  // Of the parallax_lobes, how many are fitted to the records whose light came through delta
  // bounces (a mirror's or a lens's caustic), kept in a reservoir of their own of lobe_records / 2:
  // in one reservoir they are outweighed by the leaf's other light, and the leaf fits no lobe to
  // them (docs/guiding.md). Each part's lobes are weighted by its share of the leaf's energy. 0:
  // one reservoir for all. Below parallax_lobes.
  int delta_lobes = 0;
};

// The parts of a GuidingField (its internals, shown for the serialized format and for tests).

// A directional node: the four quadrants q = x + 2 y of its square (x, y: 1 for the upper half
// along u = (cos theta + 1) / 2, v = phi / 2 pi). child[q] = 0: quadrant q is a leaf (node 0 is the
// root, never a child). 16-bit indices as in the paper: rho bounds a tree to about
// max_directional_depth / rho nodes.
struct GuidingSamplingNode {
  float share[4];  // of the leaf's energy (normalized: any scale of the records fits a float)
  uint16_t child[4];
};
struct GuidingBuildingNode {
  double energy[4];  // double: a leaf sums millions of records, a float sum stops growing at 2^24 of them
  uint16_t child[4];
};
struct GuidingLeaf {
  std::vector<GuidingSamplingNode> sampling;  // never empty
  std::vector<GuidingBuildingNode> building;  // never empty
  uint64_t records = 0;                       // this iteration's, applied
  // Parallax lobes (settings.parallax_lobes > 0): the sampling lobes and this iteration's reservoir.
  std::vector<GuidingLobe> lobes;
  std::vector<GuidingLobeRecord> reservoir;
  // With delta_lobes: this iteration's records whose light came through delta bounces (the
  // reservoir then holds the others), and the energy of each kind that arrived.
  std::vector<GuidingLobeRecord> delta_reservoir;
  double energy = 0.0, delta_energy = 0.0;
  // The guided share of the leaf's vertices: Müller et al.'s fixed 0.5 until the lobes have been
  // judged, then what best_guided_share() finds for the lobes of the last iteration on the records
  // of this one (records they were not fitted to).
  float alpha = 0.5f;
};
struct GuidingSpatialNode {
  uint32_t children = 0;  // index of the first of two (lower, upper half), 0: a leaf
  uint32_t leaf = 0;      // a leaf's index in leaves_
};
struct GuidingRecord {
  uint64_t key;
  uint32_t leaf;
  float u, v;    // the direction on the square
  float energy;  // radiance * weight
  glm::vec3 position;
  glm::vec3 source;  // where the light seems to come from (see kind)
  uint32_t kind;     // GuidingSourceKind
  glm::vec3 normal;  // of the receiving surface, toward the light's side (0: unknown)
  uint32_t through_delta;  // 1: the light came through delta bounces (GuidingSettings::delta_lobes)
};

class GuidingField {
 public:
  struct Box {
    glm::vec3 lo, hi;
  };
  struct Stats {
    size_t spatial_leaves = 0;
    size_t sampling_nodes = 0, building_nodes = 0;  // directional quadtree nodes, all leaves
    int max_sampling_level = 0;  // the deepest quadrant of a sampling tree (its side is 2^-level)
  };

  // Throws pxf::Error on a box that is not finite or has lo > hi, or on settings out of range
  // (max_bytes below kMinBytes included).
  GuidingField(glm::vec3 lo, glm::vec3 hi, const GuidingSettings& settings = {});
  ~GuidingField();
  GuidingField(GuidingField&&) noexcept;
  GuidingField& operator=(GuidingField&&) noexcept;

  // --- Learning. record() may be called from many threads at once, and during sample() / pdf();
  // the other calls here and serialize() must not overlap a record() or end_iteration().

  // An estimate of the radiance arriving at `position` from `direction` (toward the light, any
  // length): `radiance` its luminance, `weight` the Monte Carlo weight of the direction, 1 / the
  // solid-angle density it was sampled with, so that radiance * weight estimates the integral of
  // incident radiance over a directional bin. `key` orders the records (determinism): unique per
  // record, e.g. (frame * pixels + pixel) * max_vertices + vertex. Records with a non-finite or
  // negative radiance or weight, a non-finite position or a zero or non-finite direction are dropped.
  // `distance`: how far along `direction` the light seems to come from (the previous vertex, or its
  // image through delta bounces), for the parallax lobes; negative: from a focus that far the
  // other way; 0 or not finite: unknown or at infinity. `normal`: of the receiving surface (either
  // side; 0: unknown), for the lobes' guided share. `through_delta`: the light came through delta
  // bounces since its last non-delta vertex (GuidingSettings::delta_lobes).
  void record(uint64_t key, const glm::vec3& position, const glm::vec3& direction, float radiance, float weight,
              float distance = 0.0f, const glm::vec3& normal = glm::vec3(0.0f), bool through_delta = false);
  // Adds the buffered records to the building trees (see the determinism note above).
  void apply_records();
  // Ends the iteration (iteration() counts the ended ones): see the notes above.
  void end_iteration();
  // True when iteration k ends with frame `frames_done` - 1, i.e. frames_done = 2^(k+1) - 1
  // (1, 3, 7, 15, ...): call end_iteration() after a frame when this says so of the frames traced.
  static bool iteration_ends_after(uint64_t frames_done) {
    return frames_done > 0 && ((frames_done + 1) & frames_done) == 0;
  }
  int iteration() const { return iteration_; }
  // False until the first iteration ended: sample() is then uniform and guiding is of no use.
  bool trained() const { return iteration_ > 0; }
  size_t pending_records() const;

  // --- Sampling (thread-safe, read-only).

  // The directional distribution of the spatial leaf that holds a point: what sample() and pdf()
  // below use, found once for the several calls of a path vertex.
  class Distribution {
   public:
    Distribution() = default;  // none: call neither function
    // A unit direction and its solid-angle density, which is pdf(direction) exactly (> 0).
    // u in [0,1)^2 (values outside are clamped).
    glm::vec3 sample(glm::vec2 u, float* pdf) const;
    // The solid-angle density of sample() for a direction of any length (0 for a zero or
    // non-finite one). Uniform (1 / 4 pi) where the leaf learned no energy.
    float pdf(const glm::vec3& direction) const;
    // False where the leaf has learned no light: its distribution is uniform over the sphere,
    // which guides nowhere (the renderer then samples the BSDF alone there).
    bool learned() const;
    // The share of the learned light this point's distribution holds (1 for the quadtree).
    float share() const { return use_lobes_ ? lobes_.share() : 1.0f; }
    // The guided share its leaf learned (GuidingLeaf::alpha).
    float alpha() const { return alpha_; }

   private:
    friend class GuidingField;
    Distribution(const std::vector<GuidingSamplingNode>& tree, float uniform_fraction, float alpha)
        : tree_(&tree), uniform_fraction_(uniform_fraction), alpha_(alpha) {}
    Distribution(const LobeMixture& lobes, float alpha) : alpha_(alpha), lobes_(lobes), use_lobes_(true) {}
    const std::vector<GuidingSamplingNode>* tree_ = nullptr;
    float uniform_fraction_ = 0.0f;
    float alpha_ = 0.5f;
    LobeMixture lobes_;
    bool use_lobes_ = false;
  };
  // `normal` (unit, optional): the side of the surface the directions serve. Lobes whose mean points
  // more than about one standard deviation below it are left out of that point's distribution (a
  // leaf may hold both sides of a wall, or a corner's two walls); the quadtree ignores it.
  Distribution distribution(const glm::vec3& position, const glm::vec3& normal = glm::vec3(0.0f)) const;
  glm::vec3 sample(const glm::vec3& position, glm::vec2 u, float* pdf) const { return distribution(position).sample(u, pdf); }
  float pdf(const glm::vec3& position, const glm::vec3& direction) const { return distribution(position).pdf(direction); }

  // --- Inspection.
  static constexpr uint64_t kMinBytes = 224;  // one leaf with one node per tree
  size_t memory_bytes() const;
  Stats stats() const;
  Box bounds() const { return {box_lo_, box_hi_}; }
  Box leaf_box(const glm::vec3& position) const;  // the spatial leaf that holds the point
  // The parallax lobes of that leaf (empty with the quadtree model or before they are fitted).
  const std::vector<GuidingLobe>& lobes(const glm::vec3& position) const { return leaves_[find_leaf(position)].lobes; }
  const GuidingSettings& settings() const { return settings_; }

  // --- Save and restore (a checkpointed render resumes exactly): everything, buffered records
  // included. deserialize throws pxf::Error with a one-line message on anything that is not a
  // complete, uncorrupted field of this format (every read bounds-checked, every index validated).
  std::vector<uint8_t> serialize() const;
  static GuidingField deserialize(const uint8_t* data, size_t size);

 private:
  struct RecordBuffers;

  GuidingField();  // empty: for deserialize
  void validate_settings() const;
  uint32_t find_leaf(const glm::vec3& position, Box* leaf_box = nullptr) const;
  std::vector<GuidingRecord> sorted_pending() const;
  void end_lobe_iteration(GuidingLeaf& leaf) const;
  void refine_directions();
  void split_leaves(double threshold);
  size_t planned_bytes() const;

  GuidingSettings settings_;
  glm::vec3 box_lo_{0.0f}, box_hi_{1.0f};
  int iteration_ = 0;
  std::vector<GuidingSpatialNode> nodes_;
  std::vector<GuidingLeaf> leaves_;
  std::vector<GuidingRecord> pending_;      // taken from the buffers, or restored by deserialize
  std::unique_ptr<RecordBuffers> buffers_;  // one vector per recording thread
};

}  // namespace pxf
