// The accumulation of a render as a file (docs/state-format.md): what `pxf render --checkpoint`
// writes, `--resume` continues and `pxf merge` combines. Frame k of pixel p is the same sample
// wherever it is traced (counter-based random numbers), so states of disjoint frame ranges combine
// exactly into the state of their union.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "pathtracer/byte_io.h"
#include "pathtracer/pathtracer.h"

namespace pxf {

// 2: the albedo mean; 3: sampler, replicates, specular sampling; 4: replicate sums; 5: the LV luminance Welford
// state; 6: adaptive sampling (the flag, per-pixel traced counts, the allocation's credits and next mask) and path
// guiding (the flag, the serialized field); 7: adaptive frames trace up to kMaxPathsPerFrame paths per
// pixel (counts, rates above 1, a shard's sample indices from its first frame * kMaxPathsPerFrame)
// and the flag names the allocation's goal; 8: the light split of issue 57; 9: light through
// openings (the flag, the serialized EnvironmentVisibility); 10: the even half of each pixel's samples (the
// blend's split decision); 11: the halves only where the split decision is on (the flag)
constexpr uint32_t kStateFormatVersion = 11;

// Frame counts: one render traces at most kMaxRenderFrames frames (--spp, --frames, --shard); a
// state, also a merge of many shards, holds at most kMaxStateFrames in all, the most the preview's
// int sample count holds. Every count is checked against these before it is used.
constexpr uint32_t kMaxRenderFrames = 1u << 24;
constexpr uint32_t kMaxStateFrames = 0x7fffffffu;

// The frames [begin, end) of the counter-based sample sequence.
struct FrameRange {
  uint32_t begin = 0, end = 0;
  uint32_t count() const { return end - begin; }
  bool operator==(const FrameRange& o) const { return begin == o.begin && end == o.end; }
};

// Everything that decides which sample frame k of pixel p is: two states may be continued or
// combined only when these are equal. Filter, blend and tone-map settings are not here: they act
// on the accumulation afterwards and may differ between a render and a merge.
struct SampleSettings {
  uint64_t scene_hash = 0;  // scene_content_hash() of the scene file(s) and environment
  uint32_t width = 0, height = 0;
  uint64_t seed = 0;
  int32_t max_vertices = 0, rr_start_vertex = 0;
  uint32_t all_hv = 0;
  uint32_t sampler = 0;            // SamplerType: 0 sobol, 1 independent
  uint32_t replicates = 1;         // TraceParams::replicates (which scrambled sequence frame k uses)
  uint32_t specular_sampling = 0;  // 0 none, 1 at every diffuse vertex, 2 near only (the default)
  // 1: adaptive sampling (--adaptive on) for the least error, 2: for clean (--until-clean; the
  // allocation's goal, preview/adaptive.h): pixels are traced unevenly, each at its own sample index.
  // Not a property of a sample, but a resume must continue the same allocation, and a merge of
  // adaptive and uniform shards would be a render neither option describes.
  uint32_t adaptive = 0;
  // Path guiding (TraceParams::guiding, the GuidingMode: 0 off, 1 on, 2 auto): a sample depends on
  // the field learned before it, so a resume must continue the same field
  // (AccumulationState::guiding_field).
  uint32_t guiding = 0;
  // 1: light through openings (TraceParams::environment_visibility): as with guiding, a sample
  // depends on what was learned before it (AccumulationState::environment_visibility).
  uint32_t environment_visibility = 0;
  // 1: the accumulation keeps the even half of each pixel's samples (TraceParams::split_halves, the
  // blend's split decision); its arrays are in the file only then.
  uint32_t split_halves = 0;
  bool operator==(const SampleSettings& o) const;
  // "" when equal, else one phrase naming the first difference ("seed 1 vs 2").
  std::string difference(const SampleSettings& o) const;
};

struct AccumulationState {
  SampleSettings settings;
  std::vector<FrameRange> frames;  // sorted, disjoint, non-empty ranges
  Accumulation acc;
  // Paths traced into each pixel (ProgressiveRenderer::pixel_frames: dropped non-finite ones too).
  // Pixel p used the sample indices [begin, begin + traced[p]) of each range it was traced in; in a
  // uniform state every entry is frame_count().
  std::vector<uint32_t> traced;
  // Adaptive sampling's allocation (settings.adaptive only, else empty; preview/adaptive.h): each
  // pixel's rate (paths per frame) of the last recomputation, 0 before the first; its credit after
  // the last planned frame and that frame's path counts (0 = not traced next), so that a resumed render traces
  // exactly what the uninterrupted one would. A merged state keeps zeros and ones: it is not resumed
  // (its frames are not one range).
  std::vector<float> rate;
  std::vector<float> credit;
  std::vector<uint8_t> next_active;
  // Path guiding's field (settings.guiding on or auto): GuidingField::serialize() of what the render
  // had learned, so that a resumed render continues exactly; empty where auto has not started one,
  // and in a merged state (each shard learned its own field), which is therefore not resumed.
  std::vector<uint8_t> guiding_field;
  // What light through openings learned (settings.environment_visibility only, and only in a scene
  // with an environment): EnvironmentVisibility::serialize(). Empty in a merged state; a resume
  // from it starts learning anew, which stays unbiased but is not the uninterrupted render.
  std::vector<uint8_t> environment_visibility;
  uint32_t frame_count() const;
};

SampleSettings sample_settings(uint64_t scene_hash, int width, int height, const TraceParams& params);

// 64-bit FNV-1a of the scene file's bytes (a built-in's file for a built-in name; for a .gltf also
// every buffer and image file beside it is NOT included: see docs/state-format.md), the
// environment file's bytes and the environment strength.
uint64_t scene_content_hash(const std::string& scene_name_or_path, const std::string& env_path, float env_strength);

// The file image of a state, and back. decode_state throws pxf::Error with a one-line message for
// any buffer that is not a complete, uncorrupted state of this format version.
std::vector<uint8_t> encode_state(const AccumulationState& state);
AccumulationState decode_state(const uint8_t* data, size_t size);

// Atomic write (temporary name, fsync, rename) and read; errors name the file.
void write_state_file(const std::string& path, const AccumulationState& state);
AccumulationState read_state_file(const std::string& path);

// Combines states of disjoint frame ranges with equal sample settings: sample-count weighted means
// and Chan's parallel combination of the Welford M2. Throws pxf::Error when settings differ, the
// frame ranges overlap or together hold more than kMaxStateFrames frames.
AccumulationState merge_states(const std::vector<AccumulationState>& states);

// "0:16,32:48"
std::string frame_ranges_text(const std::vector<FrameRange>& ranges);

}  // namespace pxf
