// Frames that trace only some pixels (adaptive sampling): each pixel takes the next sample of its
// own sequence, so a pixel's accumulation depends only on how many paths it received, never on
// which other pixels a frame traced, the chunking or the thread count.
#include <gtest/gtest.h>

#include <memory>

#include "pathtracer/integrator.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

constexpr int kWidth = 37, kHeight = 21;  // not a multiple of the 16-pixel tiles: partial tiles too

// The per-pixel state of pixel p, as bytes: equal bytes = bit-identical accumulations.
std::vector<uint8_t> pixel_bytes(const Accumulation& acc, size_t p) {
  std::vector<uint8_t> bytes;
  auto put = [&](const void* data, size_t size) {
    const uint8_t* b = static_cast<const uint8_t*>(data);
    bytes.insert(bytes.end(), b, b + size);
  };
  put(&acc.lv_mean[p], sizeof(glm::vec3));
  put(&acc.hv_mean[p], sizeof(glm::vec3));
  put(&acc.albedo_mean[p], sizeof(glm::vec3));
  put(&acc.hv_lum_mean[p], sizeof(double));
  put(&acc.hv_lum_m2[p], sizeof(double));
  put(&acc.lv_lum_mean[p], sizeof(double));
  put(&acc.lv_lum_m2[p], sizeof(double));
  put(&acc.samples[p], sizeof(uint32_t));
  if (acc.split_halves) {
    put(&acc.even_hv_mean[p], sizeof(glm::vec3));
    put(&acc.even_lum_m2[p], sizeof(double));
    put(&acc.even_samples[p], sizeof(uint32_t));
  }
  for (int r = 0; r < acc.replicates && acc.replicates > 1; ++r) {
    put(&acc.replicate_lum_sum[p * acc.replicates + r], sizeof(double));
    put(&acc.replicate_samples[p * acc.replicates + r], sizeof(uint32_t));
  }
  return bytes;
}

void expect_same_accumulation(const Accumulation& a, const Accumulation& b) {
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (size_t p = 0; p < a.samples.size(); ++p) ASSERT_EQ(pixel_bytes(a, p), pixel_bytes(b, p)) << "pixel " << p;
}

// A mask that changes from frame to frame: pixel p is active in frame f when (p * 7 + f * 3) % 5 < 2,
// and the pixels of the first row always.
std::vector<uint8_t> varying_mask(int frame) {
  std::vector<uint8_t> mask(static_cast<size_t>(kWidth) * kHeight);
  for (size_t p = 0; p < mask.size(); ++p) mask[p] = p < kWidth || (p * 7 + static_cast<size_t>(frame) * 3) % 5 < 2;
  return mask;
}

// Path counts that change from frame to frame: the active pixels of varying_mask trace 1 to 3
// paths, so that a pixel's paths of one frame straddle the 256-path batches somewhere.
std::vector<uint8_t> varying_counts(int frame) {
  std::vector<uint8_t> counts = varying_mask(frame);
  for (size_t p = 0; p < counts.size(); ++p)
    if (counts[p]) counts[p] = static_cast<uint8_t>(1 + (p + static_cast<size_t>(frame)) % 3);
  return counts;
}

TEST(ActivePixels, EveryPixelActiveIsTheUniformFrame) {
  const Scene scene = make_cornell_box(true);
  TraceParams params;
  params.threads = 2;
  ProgressiveRenderer uniform(scene, params, kWidth, kHeight), masked(scene, params, kWidth, kHeight);
  const std::vector<uint8_t> all(static_cast<size_t>(kWidth) * kHeight, 1);
  for (int f = 0; f < 4; ++f) {
    ASSERT_TRUE(uniform.add_frame());
    ASSERT_TRUE(masked.add_frame(all));
  }
  expect_same_accumulation(uniform.accumulation(), masked.accumulation());
  EXPECT_EQ(masked.stats().paths, uniform.stats().paths);
  for (uint32_t n : masked.pixel_frames()) EXPECT_EQ(n, 4u);
}

TEST(ActivePixels, UniformFrameKIsEachPixelsSampleK) {
  // The sample index of a uniform frame is the frame: the first_frame() + frames() of before.
  const Scene scene = make_cornell_box(true);
  TraceParams params;
  params.threads = 2;
  params.split_halves = true;  // and each sample in the half of its index's parity
  ProgressiveRenderer renderer(scene, params, kWidth, kHeight);
  renderer.set_first_frame(5);
  for (int f = 0; f < 3; ++f) ASSERT_TRUE(renderer.add_frame());
  PathTracer tracer(scene);
  Accumulation expected;
  resize_accumulation(expected, kWidth, kHeight, 1, /*halves=*/true);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (uint32_t k = 5; k < 8; ++k) {
        const PathSample s = tracer.trace_pixel(scene.camera, kWidth, kHeight, x, y, k, params);
        if (s.finite()) accumulate_sample(expected, static_cast<size_t>(y) * kWidth + x, s.lv, s.hv, k, s.albedo);
      }
  expect_same_accumulation(renderer.accumulation(), expected);
}

// An adaptive shard of frames A:B starts at sample index A * kMaxPathsPerFrame (the sample stride):
// its frames trace at most kMaxPathsPerFrame paths per pixel each, so the indices of shards of
// disjoint frames never meet, whatever their allocations.
TEST(ActivePixels, AShardStartsAtItsFirstFrameTimesTheStride) {
  const Scene scene = make_cornell_box(true);
  TraceParams params;
  params.threads = 2;
  params.split_halves = true;
  ProgressiveRenderer renderer(scene, params, kWidth, kHeight);
  renderer.set_sample_stride(kMaxPathsPerFrame);
  renderer.set_first_frame(2);
  const std::vector<uint8_t> counts = varying_counts(0);
  ASSERT_TRUE(renderer.add_frame(counts));
  PathTracer tracer(scene);
  Accumulation expected;
  resize_accumulation(expected, kWidth, kHeight, 1, /*halves=*/true);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const size_t p = static_cast<size_t>(y) * kWidth + x;
      for (uint32_t k = 0; k < counts[p]; ++k) {
        const uint32_t index = 2 * kMaxPathsPerFrame + k;
        const PathSample s = tracer.trace_pixel(scene.camera, kWidth, kHeight, x, y, index, params);
        if (s.finite()) accumulate_sample(expected, p, s.lv, s.hv, index, s.albedo);
      }
    }
  expect_same_accumulation(renderer.accumulation(), expected);
  EXPECT_THROW(renderer.set_sample_stride(kMaxPathsPerFrame + 1), Error);
}

TEST(ActivePixels, APixelTracedNTimesHoldsTheFirstNSamplesOfItsSequence) {
  // Pixels tracing 0 to 3 paths a frame: each holds exactly the samples 0 .. n-1 of its own
  // sequence, i.e. what a uniform render of n frames gives it (paths of one frame or of n frames,
  // the same bits), with replicates split by its own count (sample k in replicate k mod K).
  const Scene scene = make_cornell_box(true);
  for (int replicates : {1, 3}) {
    TraceParams params;
    params.threads = 2;
    params.replicates = replicates;
    ProgressiveRenderer masked(scene, params, kWidth, kHeight);
    std::vector<uint32_t> active_frames(static_cast<size_t>(kWidth) * kHeight, 0);
    constexpr int kFrames = 5, kMostPaths = 3 * kFrames;
    for (int f = 0; f < kFrames; ++f) {
      const std::vector<uint8_t> mask = varying_counts(f);
      ASSERT_TRUE(masked.add_frame(mask));
      for (size_t p = 0; p < mask.size(); ++p) active_frames[p] += mask[p];
    }
    EXPECT_EQ(masked.pixel_frames(), active_frames);
    EXPECT_EQ(masked.frames(), kFrames);
    std::vector<std::unique_ptr<ProgressiveRenderer>> owned;  // uniform renders of n = 0 .. kMostPaths frames
    for (int n = 0; n <= kMostPaths; ++n) {
      owned.push_back(std::make_unique<ProgressiveRenderer>(scene, params, kWidth, kHeight));
      for (int f = 0; f < n; ++f) ASSERT_TRUE(owned.back()->add_frame());
    }
    bool some_pixel_skipped_frames = false, some_pixel_traced_more = false;
    for (size_t p = 0; p < active_frames.size(); ++p) {
      const uint32_t n = active_frames[p];
      some_pixel_skipped_frames |= n < kFrames;
      some_pixel_traced_more |= n > kFrames;
      ASSERT_EQ(pixel_bytes(masked.accumulation(), p), pixel_bytes(owned[n]->accumulation(), p))
          << "pixel " << p << ", " << n << " paths, " << replicates << " replicates";
    }
    EXPECT_TRUE(some_pixel_skipped_frames);
    EXPECT_TRUE(some_pixel_traced_more);
  }
}

TEST(ActivePixels, ResultsDoNotDependOnTheThreadCount) {
  const Scene scene = make_cornell_box(true);
  std::vector<std::unique_ptr<ProgressiveRenderer>> renders;
  for (int threads : {1, 2, 5}) {
    TraceParams params;
    params.threads = threads;
    renders.push_back(std::make_unique<ProgressiveRenderer>(scene, params, kWidth, kHeight));
    for (int f = 0; f < 5; ++f) {
      std::vector<uint8_t> counts = varying_counts(f);
      counts[300] = kMaxPathsPerFrame;  // the batches around it are cut short
      ASSERT_TRUE(renders.back()->add_frame(counts));
    }
  }
  expect_same_accumulation(renders[0]->accumulation(), renders[1]->accumulation());
  expect_same_accumulation(renders[0]->accumulation(), renders[2]->accumulation());
}

TEST(ActivePixels, AnInactivePixelIsUntouchedAndAResetClearsTheCounts) {
  const Scene scene = make_cornell_box(true);
  TraceParams params;
  params.threads = 2;
  ProgressiveRenderer renderer(scene, params, kWidth, kHeight);
  std::vector<uint8_t> one(static_cast<size_t>(kWidth) * kHeight, 0);
  one[kWidth * 10 + 20] = 1;
  ASSERT_TRUE(renderer.add_frame(one));
  ASSERT_TRUE(renderer.add_frame(one));
  EXPECT_EQ(renderer.stats().paths, 2u);
  for (size_t p = 0; p < one.size(); ++p) {
    EXPECT_EQ(renderer.pixel_frames()[p], one[p] ? 2u : 0u);
    EXPECT_EQ(renderer.accumulation().samples[p] > 0, one[p] != 0);
  }
  renderer.reset();
  for (uint32_t n : renderer.pixel_frames()) EXPECT_EQ(n, 0u);
  EXPECT_THROW(renderer.add_frame(std::vector<uint8_t>(3, 1)), Error);
  std::vector<uint8_t> too_many(static_cast<size_t>(kWidth) * kHeight, 1);
  too_many[5] = kMaxPathsPerFrame + 1;
  EXPECT_THROW(renderer.add_frame(too_many), Error);
}

TEST(ActivePixels, RestoredFramesCountForEveryPixel) {
  const Scene scene = make_cornell_box(true);
  TraceParams params;
  params.threads = 2;
  ProgressiveRenderer first(scene, params, kWidth, kHeight), resumed(scene, params, kWidth, kHeight);
  for (int f = 0; f < 3; ++f) ASSERT_TRUE(first.add_frame());
  resumed.restore(first.accumulation(), 0, 3);
  for (uint32_t n : resumed.pixel_frames()) EXPECT_EQ(n, 3u);
  ASSERT_TRUE(first.add_frame(varying_mask(0)));
  ASSERT_TRUE(resumed.add_frame(varying_mask(0)));
  expect_same_accumulation(first.accumulation(), resumed.accumulation());
}

TEST(Accumulation, LvVarianceOfMeanIsTheWelfordOfTheLvLuminance) {
  Accumulation acc;
  resize_accumulation(acc, 1, 1);
  EXPECT_EQ(acc.lv_variance_of_mean(0), -1.0f);
  accumulate_sample(acc, 0, glm::vec3(1.0f), glm::vec3(0.0f));
  EXPECT_EQ(acc.lv_variance_of_mean(0), -1.0f);
  accumulate_sample(acc, 0, glm::vec3(3.0f), glm::vec3(0.0f));
  // Y = 1 and 3: s^2 = 2, Var[mean] = s^2 / n = 1; the HV variance stays 0.
  EXPECT_FLOAT_EQ(acc.lv_variance_of_mean(0), 1.0f);
  EXPECT_EQ(acc.per_sample_variance_of_mean(0), 0.0f);
}

}  // namespace
}  // namespace pxf
