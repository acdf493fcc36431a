// The state file (docs/state-format.md): exact round trip, every truncation and every corrupted
// byte refused with a one-line error, and merging of disjoint frame ranges equal to one sequential
// accumulation (Chan's combination of the Welford state).
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <random>

#include "pathtracer/accumulation_state.h"
#include "pathtracer/integrator.h"

using namespace pxf;

namespace {

constexpr int kW = 5, kH = 3;

// A deterministic stand-in for frame `frame` of pixel `p`: what the path tracer guarantees too.
void sample_of(size_t p, uint32_t frame, glm::vec3& lv, glm::vec3& hv) {
  std::mt19937 rng(static_cast<uint32_t>(p * 7919u + frame * 104729u + 17u));
  std::exponential_distribution<float> radiance(2.0f);
  lv = glm::vec3(radiance(rng), radiance(rng), radiance(rng));
  hv = glm::vec3(radiance(rng), radiance(rng), radiance(rng)) * (frame % 5 == 0 ? 20.0f : 1.0f);
}

// The frames' accumulation; with replicates (Sobol), frame f goes to replicate f mod K as in the
// renderer. With the split decision's halves unless `halves` is false, so that every merge and
// round trip below covers them.
AccumulationState render_frames(FrameRange range, int replicates = 1, bool halves = true) {
  AccumulationState state;
  TraceParams params;
  params.replicates = replicates;
  params.split_halves = halves;
  state.settings = sample_settings(0x1234, kW, kH, params);
  state.frames = {range};
  state.traced.assign(static_cast<size_t>(kW) * kH, range.count());
  resize_accumulation(state.acc, kW, kH, replicates, halves);
  for (uint32_t f = range.begin; f < range.end; ++f)
    for (size_t p = 0; p < state.acc.samples.size(); ++p) {
      if ((p + f) % 11 == 3) continue;  // a dropped (non-finite) sample: counts differ per pixel
      glm::vec3 lv, hv;
      sample_of(p, f, lv, hv);
      // The albedo of a textured pixel varies with the sample's position in the pixel.
      const glm::vec3 albedo(0.1f + 0.05f * static_cast<float>((p * 7 + f) % 13), 0.5f, (f % 3) * 0.4f);
      accumulate_sample(state.acc, p, lv, hv, f, albedo);
    }
  return state;
}

std::string decode_error(const std::vector<uint8_t>& bytes) {
  try {
    decode_state(bytes.data(), bytes.size());
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Relative tolerance of a merged float mean against the sequential running mean: both round at
// each step, the running mean n times in float; 64 frames stay well inside 1e-5.
constexpr float kMeanTolerance = 1e-5f;

void expect_same_accumulation(const Accumulation& a, const Accumulation& b) {
  ASSERT_EQ(a.samples, b.samples);
  for (size_t i = 0; i < a.samples.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(a.lv_mean[i][c], b.lv_mean[i][c], kMeanTolerance * std::abs(b.lv_mean[i][c])) << i;
      EXPECT_NEAR(a.hv_mean[i][c], b.hv_mean[i][c], kMeanTolerance * std::abs(b.hv_mean[i][c])) << i;
      EXPECT_NEAR(a.albedo_mean[i][c], b.albedo_mean[i][c], kMeanTolerance * std::abs(b.albedo_mean[i][c])) << i;
    }
    EXPECT_NEAR(a.hv_lum_mean[i], b.hv_lum_mean[i], 1e-12 * std::abs(b.hv_lum_mean[i])) << i;
    EXPECT_NEAR(a.hv_lum_m2[i], b.hv_lum_m2[i], 1e-12 * std::abs(b.hv_lum_m2[i])) << i;
    EXPECT_NEAR(a.lv_lum_mean[i], b.lv_lum_mean[i], 1e-12 * std::abs(b.lv_lum_mean[i])) << i;
    EXPECT_NEAR(a.lv_lum_m2[i], b.lv_lum_m2[i], 1e-12 * std::abs(b.lv_lum_m2[i])) << i;
    ASSERT_EQ(a.split_halves, b.split_halves);
    if (!a.split_halves) continue;
    EXPECT_EQ(a.even_samples[i], b.even_samples[i]) << i;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(a.even_hv_mean[i][c], b.even_hv_mean[i][c], kMeanTolerance * std::abs(b.even_hv_mean[i][c])) << i;
    EXPECT_NEAR(a.even_lum_mean[i], b.even_lum_mean[i], 1e-12 * std::abs(b.even_lum_mean[i])) << i;
    EXPECT_NEAR(a.even_lum_m2[i], b.even_lum_m2[i], 1e-12 * std::abs(b.even_lum_m2[i])) << i;
  }
}

}  // namespace

TEST(AccumulationState, RoundTripIsExact) {
  const AccumulationState state = render_frames({4, 20});
  const std::vector<uint8_t> bytes = encode_state(state);
  const AccumulationState back = decode_state(bytes.data(), bytes.size());
  EXPECT_EQ(back.settings.difference(state.settings), "");
  ASSERT_EQ(back.frames.size(), 1u);
  EXPECT_EQ(back.frames[0], (FrameRange{4, 20}));
  EXPECT_EQ(encode_state(back), bytes);  // every array bit for bit
}

TEST(AccumulationState, EveryTruncationIsRefused) {
  for (const int replicates : {1, 3}) {
    const std::vector<uint8_t> bytes = encode_state(render_frames({0, 3}, replicates));
    for (size_t size = 0; size < bytes.size(); ++size) {
      const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + size);
      const std::string error = decode_error(cut);
      EXPECT_FALSE(error.empty()) << "a state cut to " << size << " bytes was accepted";
      EXPECT_EQ(error.find('\n'), std::string::npos);
    }
    std::vector<uint8_t> longer = bytes;
    longer.push_back(0);
    EXPECT_FALSE(decode_error(longer).empty());
  }
}

TEST(AccumulationState, EveryCorruptedByteIsRefused) {
  for (const int replicates : {1, 3}) {
    const std::vector<uint8_t> bytes = encode_state(render_frames({0, 3}, replicates));
    for (size_t i = 0; i < bytes.size(); ++i) {
      std::vector<uint8_t> bad = bytes;
      bad[i] ^= 0x5a;
      EXPECT_FALSE(decode_error(bad).empty()) << "byte " << i << ", " << replicates << " replicates";
    }
  }
}

TEST(AccumulationState, OtherVersionIsRefusedByName) {
  std::vector<uint8_t> bytes = encode_state(render_frames({0, 2}));
  bytes[8] = 4;  // the version follows the 8-byte magic; version 4 (no LV luminance state) is refused
  EXPECT_NE(decode_error(bytes).find("version 4 is not supported"), std::string::npos) << decode_error(bytes);
  bytes[0] = 'Q';
  EXPECT_NE(decode_error(bytes).find("not a pxf state file"), std::string::npos);
}

TEST(AccumulationState, HeaderWithHugeCountsIsRefusedWithoutAllocating) {
  // A valid checksum over a header claiming 2^15 x 2^15 pixels and a 5x3 image's arrays: the size
  // is patched into an encoded state (the writer refuses arrays of another size) after the magic,
  // the version and the scene hash, and the checksum recomputed.
  std::vector<uint8_t> bytes = encode_state(render_frames({0, 1}));
  const uint32_t huge = 1u << 15;
  std::memcpy(&bytes[20], &huge, sizeof(huge));
  std::memcpy(&bytes[24], &huge, sizeof(huge));
  const uint64_t checksum = fnv1a64(bytes.data(), bytes.size() - sizeof(uint64_t));
  std::memcpy(&bytes[bytes.size() - sizeof(uint64_t)], &checksum, sizeof(checksum));
  EXPECT_NE(decode_error(bytes).find("truncated"), std::string::npos) << decode_error(bytes);
}

TEST(AccumulationState, MergedUnevenShardsEqualOneAccumulation) {
  const AccumulationState whole = render_frames({0, 64});
  for (const std::vector<uint32_t>& cuts :
       {std::vector<uint32_t>{0, 41, 64}, {0, 1, 30, 64}, {0, 3, 4, 20, 21, 50, 63, 64}}) {
    std::vector<AccumulationState> shards;
    for (size_t i = 0; i + 1 < cuts.size(); ++i) shards.push_back(render_frames({cuts[i], cuts[i + 1]}));
    std::reverse(shards.begin(), shards.end());  // the order of the states does not matter
    const AccumulationState merged = merge_states(shards);
    SCOPED_TRACE(cuts.size() - 1);
    ASSERT_EQ(merged.frames.size(), 1u);
    EXPECT_EQ(merged.frames[0], (FrameRange{0, 64}));
    expect_same_accumulation(merged.acc, whole.acc);
  }
}

TEST(AccumulationState, OverlapAndMismatchAreRefused) {
  EXPECT_THROW(merge_states({render_frames({0, 10}), render_frames({9, 12})}), Error);
  AccumulationState other_seed = render_frames({10, 12});
  other_seed.settings.seed = 7;
  try {
    merge_states({render_frames({0, 10}), other_seed});
    FAIL() << "states of another seed were merged";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("seed"), std::string::npos) << e.what();
  }
  AccumulationState other_scene = render_frames({10, 12});
  other_scene.settings.scene_hash ^= 1;
  EXPECT_THROW(merge_states({render_frames({0, 10}), other_scene}), Error);
}

// Sampler, replicates and specular sampling (none, everywhere, near) decide the samples too: they round-trip, a state of
// another value is refused by name, and a corrupt value is a clear error.
TEST(AccumulationState, SamplerSettingsRoundTripAndAreChecked) {
  TraceParams params;
  params.sampler = SamplerType::Independent;
  params.replicates = 4;
  params.specular_sampling = true;
  params.split_halves = true;
  AccumulationState state = render_frames({0, 4});
  state.settings = sample_settings(0x1234, kW, kH, params);
  const std::vector<uint8_t> bytes = encode_state(state);
  const AccumulationState back = decode_state(bytes.data(), bytes.size());
  EXPECT_EQ(back.settings.sampler, 1u);
  EXPECT_EQ(back.settings.replicates, 4u);
  EXPECT_EQ(back.settings.specular_sampling, 1u);
  const SampleSettings plain = sample_settings(0x1234, kW, kH, TraceParams{});
  SampleSettings a = plain;
  a.sampler = 1;
  EXPECT_EQ(a.difference(plain), "sampler independent vs sobol");
  a = plain;
  a.replicates = 4;
  EXPECT_EQ(a.difference(plain), "replicates 4 vs 1");
  // The default is the specular chains (2); without them 0; --specular-sampling wins over them (1).
  EXPECT_EQ(plain.specular_sampling, 2u);
  TraceParams none;
  none.specular_chains = false;
  EXPECT_EQ(sample_settings(0x1234, kW, kH, none).specular_sampling, 0u);
  a = plain;
  a.specular_sampling = 1;
  EXPECT_EQ(a.difference(plain), "specular sampling 1 vs 2");
  a.specular_sampling = 0;
  EXPECT_EQ(a.difference(plain), "specular sampling 0 vs 2");
  // A corrupt flag with a valid checksum: the header check names it.
  AccumulationState bad = render_frames({0, 1});
  bad.settings.specular_sampling = 7;
  const std::vector<uint8_t> bad_bytes = encode_state(bad);
  EXPECT_NE(decode_error(bad_bytes).find("invalid setting flag"), std::string::npos) << decode_error(bad_bytes);
  bad.settings.specular_sampling = 0;
  bad.settings.replicates = 0;
  const std::vector<uint8_t> bad_replicates = encode_state(bad);
  EXPECT_NE(decode_error(bad_replicates).find("replicate count 0"), std::string::npos);
}

// Found by the state_reader fuzzer (fuzz/crashers/state_reader/): ranges [0,1) and [1,N) decoded,
// and merging the state with nothing joined them. Writers always join adjacent ranges.
TEST(AccumulationState, AdjacentUnjoinedRangesAreRefused) {
  AccumulationState state = render_frames({0, 4});
  state.frames = {{0, 2}, {2, 4}};
  const std::vector<uint8_t> bytes = encode_state(state);
  EXPECT_NE(decode_error(bytes).find("unjoined adjacent frame ranges"), std::string::npos) << decode_error(bytes);
  state.frames = {{0, 2}, {3, 5}};
  const std::vector<uint8_t> gap = encode_state(state);
  EXPECT_EQ(decode_error(gap), "");
}

TEST(AccumulationState, NonContiguousRangesStaySeparate) {
  const AccumulationState merged = merge_states({render_frames({8, 10}), render_frames({0, 4})});
  EXPECT_EQ(frame_ranges_text(merged.frames), "0:4,8:10");
  EXPECT_EQ(merged.frame_count(), 6u);
}

// With replicates the per-replicate sums are part of the state: a resumed or merged accumulation
// estimates Var[L_u] from the same replicate means as one uninterrupted render (before format 4,
// they were dropped and resumed renders of --replicates K > 1 had other variances and images).
TEST(AccumulationState, ReplicateSumsRoundTripAndMerge) {
  constexpr int kReplicates = 4;
  const AccumulationState whole = render_frames({0, 40}, kReplicates);
  ASSERT_EQ(whole.acc.replicate_samples.size(), static_cast<size_t>(kW * kH * kReplicates));
  const std::vector<uint8_t> bytes = encode_state(whole);
  EXPECT_EQ(bytes.size(), encode_state(render_frames({0, 40})).size() + kW * kH * kReplicates * (8 + 4));
  const AccumulationState back = decode_state(bytes.data(), bytes.size());
  EXPECT_EQ(back.acc.replicates, kReplicates);
  EXPECT_EQ(back.acc.replicate_lum_sum, whole.acc.replicate_lum_sum);
  EXPECT_EQ(back.acc.replicate_samples, whole.acc.replicate_samples);
  EXPECT_EQ(back.acc.variance_of_mean_image(), whole.acc.variance_of_mean_image());

  // Shards that cut replicates mid-cycle merge into the whole render's replicate sums.
  const AccumulationState merged = merge_states({render_frames({27, 40}, kReplicates), render_frames({0, 9}, kReplicates),
                                                 render_frames({9, 27}, kReplicates)});
  expect_same_accumulation(merged.acc, whole.acc);
  EXPECT_EQ(merged.acc.replicate_samples, whole.acc.replicate_samples);
  const std::vector<float> merged_var = merged.acc.variance_of_mean_image(), whole_var = whole.acc.variance_of_mean_image();
  for (size_t p = 0; p < whole_var.size(); ++p) {
    EXPECT_GT(whole.acc.replicate_variance_of_mean(p), 0.0f);
    EXPECT_NEAR(merged.acc.replicate_variance_of_mean(p), whole.acc.replicate_variance_of_mean(p),
                1e-5f * whole.acc.replicate_variance_of_mean(p)) << p;
    EXPECT_NEAR(merged_var[p], whole_var[p], 1e-5f * whole_var[p]) << p;
  }

  // The independent sampler keeps no replicate sums, whatever --replicates says.
  TraceParams independent;
  independent.sampler = SamplerType::Independent;
  independent.replicates = kReplicates;
  independent.split_halves = true;
  AccumulationState plain = render_frames({0, 4});
  plain.settings = sample_settings(0x1234, kW, kH, independent);
  EXPECT_EQ(decode_state(encode_state(plain).data(), encode_state(plain).size()).acc.replicates, 1);
  // A state whose arrays do not match its settings is not written.
  AccumulationState mismatched = render_frames({0, 4});
  mismatched.settings.replicates = kReplicates;
  EXPECT_THROW(encode_state(mismatched), Error);
}

TEST(AccumulationState, ReplicateCountsThatDoNotAddUpAreRefused) {
  AccumulationState state = render_frames({0, 8}, 2);
  state.acc.replicate_samples[3] += 1;  // pixel 1 now claims one more replicate sample than samples
  const std::vector<uint8_t> bytes = encode_state(state);
  EXPECT_NE(decode_error(bytes).find("replicate sample counts do not add up to the samples at pixel 1"),
            std::string::npos) << decode_error(bytes);
  state = render_frames({0, 8}, 2);
  state.acc.replicate_lum_sum[0] = std::numeric_limits<double>::infinity();
  const std::vector<uint8_t> inf_bytes = encode_state(state);
  EXPECT_NE(decode_error(inf_bytes).find("non-finite replicate sum at pixel 0"), std::string::npos);
}

TEST(AccumulationState, EvenHalvesThatDoNotFitTheSamplesAreRefused) {
  AccumulationState state = render_frames({0, 8});
  state.acc.even_samples[2] = state.acc.samples[2] + 1;
  EXPECT_NE(decode_error(encode_state(state)).find("more even-index samples than samples at pixel 2"),
            std::string::npos);
  state = render_frames({0, 8});
  state.acc.even_lum_m2[1] = -1.0;
  EXPECT_NE(decode_error(encode_state(state)).find("non-finite or negative value at pixel 1"), std::string::npos);
}

// Without the split decision the even half is not kept, and not written: a render that does not
// blend by halves does not pay for them. States with and without halves do not merge.
TEST(AccumulationState, HalvesAreKeptOnlyWithTheSplitDecision) {
  const AccumulationState without = render_frames({0, 8}, 1, false);
  EXPECT_TRUE(without.acc.even_samples.empty());
  EXPECT_TRUE(without.acc.even_hv_mean.empty());
  const std::vector<uint8_t> bytes = encode_state(without);
  const size_t half_bytes = sizeof(glm::vec3) + 2 * sizeof(double) + sizeof(uint32_t);
  EXPECT_EQ(bytes.size() + kW * kH * half_bytes, encode_state(render_frames({0, 8})).size());
  const AccumulationState back = decode_state(bytes.data(), bytes.size());
  EXPECT_FALSE(back.acc.split_halves);
  EXPECT_EQ(encode_state(back), bytes);
  try {
    merge_states({render_frames({0, 4}), render_frames({4, 8}, 1, false)});
    FAIL() << "a state with halves merged with one without";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("split decision off vs on"), std::string::npos) << e.what();
  }
  AccumulationState mismatched = without;
  mismatched.settings.split_halves = 1;  // arrays that the flag says are there, but are not
  EXPECT_THROW(encode_state(mismatched), Error);
  std::vector<float> rgba(4 * kW * kH), halves(4 * kW * kH), variances(2 * kW * kH);
  EXPECT_THROW(without.acc.hv_halves(rgba.data(), halves.data(), variances.data()), Error);
}

namespace {

// An adaptive state of the frames `range` in which pixel p was traced in only some frames: its
// k-th path is sample index range.begin + k (as the renderer's per-pixel count gives it).
AccumulationState render_adaptive(FrameRange range) {
  AccumulationState state = render_frames(range);
  state.settings.adaptive = 1;
  resize_accumulation(state.acc, kW, kH, 1, state.acc.split_halves);
  const size_t pixels = state.acc.samples.size();
  state.traced.assign(pixels, 0);
  state.rate.assign(pixels, 0.0f);
  state.credit.assign(pixels, 0.0f);
  state.next_active.assign(pixels, 0);
  for (size_t p = 0; p < pixels; ++p) {
    state.traced[p] = 1 + static_cast<uint32_t>(p % range.count());  // 1..frames paths
    for (uint32_t k = 0; k < state.traced[p]; ++k) {
      glm::vec3 lv, hv;
      sample_of(p, range.begin + k, lv, hv);
      accumulate_sample(state.acc, p, lv, hv, 0, glm::vec3(0.5f));
    }
    state.rate[p] = 1.0f / static_cast<float>(1 + p % 16);
    state.credit[p] = 0.125f * static_cast<float>(p % 8);
    state.next_active[p] = p % 3 == 0;
  }
  return state;
}

}  // namespace

// Format 6: an adaptive state carries each pixel's traced count and the allocation (credits and
// the next frame's mask), exactly, so that a resumed adaptive render continues the same allocation.
TEST(AccumulationState, AdaptiveAllocationRoundTripsExactly) {
  const AccumulationState state = render_adaptive({3, 11});
  const std::vector<uint8_t> bytes = encode_state(state);
  const AccumulationState back = decode_state(bytes.data(), bytes.size());
  EXPECT_EQ(back.settings.adaptive, 1u);
  EXPECT_EQ(back.traced, state.traced);
  EXPECT_EQ(back.rate, state.rate);
  EXPECT_EQ(back.credit, state.credit);
  EXPECT_EQ(back.next_active, state.next_active);
  EXPECT_EQ(back.acc.samples, state.acc.samples);
  EXPECT_EQ(encode_state(back), bytes);
  // A uniform state has no allocation arrays: two floats and one byte per pixel fewer.
  const AccumulationState uniform = render_frames({3, 11});
  EXPECT_EQ(encode_state(uniform).size() + uniform.acc.samples.size() * (2 * sizeof(float) + 1), bytes.size());
}

TEST(AccumulationState, AdaptiveCountsAndAllocationOutOfRangeAreRefused) {
  AccumulationState state = render_adaptive({0, 8});
  state.traced[4] = 8 * kMaxPathsPerFrame + 1;  // more paths than frames can hold
  EXPECT_NE(decode_error(encode_state(state)).find("traced count that does not fit its frames at pixel 4"),
            std::string::npos);
  state = render_adaptive({0, 8});
  state.traced[2] = state.acc.samples[2] - 1;  // more accepted samples than traced paths
  EXPECT_NE(decode_error(encode_state(state)).find("more samples in a pixel than it traced"), std::string::npos);
  for (float bad : {-0.5f, 1.0f, std::numeric_limits<float>::quiet_NaN()}) {
    state = render_adaptive({0, 8});
    state.credit[6] = bad;
    EXPECT_NE(decode_error(encode_state(state)).find("invalid adaptive allocation at pixel 6"), std::string::npos)
        << bad;
  }
  state = render_adaptive({0, 8});
  state.rate[3] = kMaxPathsPerFrame + 0.5f;
  EXPECT_NE(decode_error(encode_state(state)).find("invalid adaptive allocation at pixel 3"), std::string::npos);
  state = render_adaptive({0, 8});
  state.next_active[1] = kMaxPathsPerFrame + 1;
  EXPECT_NE(decode_error(encode_state(state)).find("invalid adaptive allocation at pixel 1"), std::string::npos);
  // A uniform state's pixels were traced in every frame.
  AccumulationState uniform = render_frames({0, 8});
  uniform.traced[0] = 7;
  EXPECT_NE(decode_error(encode_state(uniform)).find("traced count that does not fit"), std::string::npos);
}

// An adaptive shard of frames A:B traces pixel p at sample indices 32 A .. 32 A + traced[p] - 1
// (ProgressiveRenderer::set_sample_stride), so shards of disjoint ranges hold disjoint samples and
// their merge is their exact sum. It is not resumed:
// adjacent ranges stay apart (one joined range would let a resume trace some indices twice), and
// the allocation is cleared. Adaptive and uniform states do not merge.
TEST(AccumulationState, AdaptiveShardsMergeAsTheirSumAndStayApart) {
  const AccumulationState a = render_adaptive({0, 6}), b = render_adaptive({6, 16});
  const AccumulationState merged = merge_states({a, b});
  EXPECT_EQ(frame_ranges_text(merged.frames), "0:6,6:16");
  EXPECT_EQ(merged.frame_count(), 16u);
  for (size_t p = 0; p < merged.traced.size(); ++p) {
    EXPECT_EQ(merged.traced[p], a.traced[p] + b.traced[p]);
    EXPECT_EQ(merged.acc.samples[p], a.acc.samples[p] + b.acc.samples[p]);
    EXPECT_EQ(merged.rate[p], 0.0f);
    EXPECT_EQ(merged.credit[p], 0.0f);
    EXPECT_EQ(merged.next_active[p], 1);
    // The merged mean is the sample-weighted mean of the shards' samples.
    const double n = static_cast<double>(a.acc.samples[p]) + b.acc.samples[p];
    EXPECT_NEAR(merged.acc.hv_lum_mean[p],
                (a.acc.hv_lum_mean[p] * a.acc.samples[p] + b.acc.hv_lum_mean[p] * b.acc.samples[p]) / n,
                1e-12 * std::abs(merged.acc.hv_lum_mean[p]));
  }
  const std::vector<uint8_t> bytes = encode_state(merged);
  EXPECT_EQ(decode_error(bytes), "");  // adjacent ranges are canonical in an adaptive state
  EXPECT_NE(std::string(decode_error(encode_state([&] {
              AccumulationState overlapping = merged;
              overlapping.frames = {{0, 6}, {5, 16}};
              return overlapping;
            }()))).find("overlapping"),
            std::string::npos);
  try {
    merge_states({a, render_frames({6, 16})});
    ADD_FAILURE() << "an adaptive and a uniform state merged";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("adaptive sampling off vs on"), std::string::npos) << e.what();
  }
}
