// Accumulation: running means and Welford variance stay exact over long streams; the
// renderer's buffers, reset and image getters.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <limits>
#include <thread>

#include <cmath>

#include "pathtracer/integrator.h"
#include "pathtracer/rng.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

TEST(Accumulation, LongStreamMatchesDoubleSums) {
  Accumulation acc;
  resize_accumulation(acc, 1, 1);
  Rng rng(42, 0, 0);
  const int n = 200000;
  double sum_lv[3] = {0, 0, 0}, sum_hv[3] = {0, 0, 0}, sum_y = 0, sum_y2 = 0;
  std::vector<double> ys;
  ys.reserve(n);
  for (int i = 0; i < n; ++i) {
    // Heavy-tailed HV (rare fireflies) over a bright LV, like a real pixel.
    float u = rng.next_float();
    glm::vec3 lv(3.0f + rng.next_float(), 0.5f, 7.25f);
    glm::vec3 hv = glm::vec3(0.2f, 0.3f, 0.1f) * (u < 0.001f ? 500.0f : rng.next_float());
    accumulate_sample(acc, 0, lv, hv);
    for (int c = 0; c < 3; ++c) {
      sum_lv[c] += lv[c];
      sum_hv[c] += hv[c];
    }
    double y = luminance(hv);
    ys.push_back(y);
    sum_y += y;
  }
  double mean_y = sum_y / n;
  for (double y : ys) sum_y2 += (y - mean_y) * (y - mean_y);
  EXPECT_EQ(acc.samples[0], static_cast<uint32_t>(n));
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(acc.lv_mean[0][c], sum_lv[c] / n, 2e-5 * std::abs(sum_lv[c] / n)) << c;
    EXPECT_NEAR(acc.hv_mean[0][c], sum_hv[c] / n, 2e-4 * std::abs(sum_hv[c] / n)) << c;
  }
  EXPECT_NEAR(acc.hv_lum_mean[0], mean_y, 1e-10 * mean_y);
  double var_of_mean = sum_y2 / (n - 1) / n;
  EXPECT_NEAR(acc.variance_of_mean(0), var_of_mean, 1e-6 * var_of_mean);
}

TEST(Accumulation, VarianceOfMeanNeedsTwoSamples) {
  Accumulation acc;
  resize_accumulation(acc, 2, 1);
  EXPECT_EQ(acc.variance_of_mean(0), -1.0f);
  accumulate_sample(acc, 0, glm::vec3(0), glm::vec3(1.0f));
  EXPECT_EQ(acc.variance_of_mean(0), -1.0f);
  accumulate_sample(acc, 0, glm::vec3(0), glm::vec3(3.0f));
  // Y = 1 and 3: s^2 = 2, Var[mean] = s^2 / n = 1.
  EXPECT_NEAR(acc.variance_of_mean(0), 1.0f, 1e-6f);
  EXPECT_EQ(acc.variance_of_mean(1), -1.0f);
}

// The packed HV buffer the preview uploads: rgb hv_mean and a variance_of_mean, bit for bit the
// per-pixel query (-1 where n < 2), with and without replicates (whose gain pools the 3x3 neighbourhood).
TEST(Accumulation, PackedHvAndVarianceMatchThePerPixelValues) {
  for (int replicates : {1, 4}) {
    Accumulation acc;
    resize_accumulation(acc, 5, 3, replicates);
    Rng rng(7, 0, 0);
    for (size_t p = 0; p < acc.samples.size(); ++p) {
      const int n = static_cast<int>(p % 4);  // 0, 1, 2, 3 samples: unknown, unknown, known, known
      for (int i = 0; i < n; ++i)
        accumulate_sample(acc, p, glm::vec3(rng.next_float()), glm::vec3(rng.next_float(), 0.5f, rng.next_float()), i);
    }
    std::vector<float> packed(acc.samples.size() * 4, 123.0f);
    acc.hv_and_variance_of_mean(packed.data());
    const std::vector<float> image = acc.variance_of_mean_image();
    for (size_t p = 0; p < acc.samples.size(); ++p) {
      for (int c = 0; c < 3; ++c) EXPECT_EQ(packed[4 * p + c], acc.hv_mean[p][c]) << replicates << " " << p;
      EXPECT_EQ(packed[4 * p + 3], acc.variance_of_mean(p)) << replicates << " " << p;
      EXPECT_EQ(packed[4 * p + 3], image[p]) << replicates << " " << p;
      if (acc.samples[p] < 2) {
        EXPECT_EQ(packed[4 * p + 3], -1.0f) << p;
      } else {
        EXPECT_GE(packed[4 * p + 3], 0.0f) << p;
      }
    }
  }
}

TEST(Accumulation, CancelledFrameResetsTheSamplesAndTheNextFrameCounts) {
  // The explorer cancels the frame in flight when the camera moves (cancel_frame from the UI
  // thread). A cancelled frame is incomplete: add_frame returns false and the samples are reset.
  // Deterministic here: the cancel arrives before the frame starts, so no tile is traced.
  Scene scene = make_cornell_box(false);
  TraceParams params;
  params.threads = 2;
  ProgressiveRenderer renderer(scene, params, 16, 12);
  ASSERT_TRUE(renderer.add_frame());
  ASSERT_TRUE(renderer.add_frame());
  renderer.cancel_frame();
  EXPECT_FALSE(renderer.add_frame());
  EXPECT_EQ(renderer.frames(), 0);
  for (uint32_t n : renderer.accumulation().samples) EXPECT_EQ(n, 0u);
  for (const glm::vec3& v : renderer.accumulation().hv_mean) EXPECT_EQ(v, glm::vec3(0.0f));
  // The cancel is spent: the next frame counts, as does one after a reset that follows a stale cancel.
  EXPECT_TRUE(renderer.add_frame());
  EXPECT_EQ(renderer.frames(), 1);
  renderer.cancel_frame();
  renderer.reset();
  EXPECT_TRUE(renderer.add_frame());
  EXPECT_EQ(renderer.frames(), 1);
  // Cancelling from another thread while frames run: each add_frame either completes or is
  // cancelled and leaves no samples behind.
  std::atomic<bool> stop{false};
  std::thread canceller([&] {
    while (!stop.load()) {
      renderer.cancel_frame();
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  });
  for (int i = 0; i < 20; ++i) {
    if (!renderer.add_frame()) {
      EXPECT_EQ(renderer.frames(), 0);
      for (uint32_t n : renderer.accumulation().samples) ASSERT_EQ(n, 0u);
    }
  }
  stop = true;
  canceller.join();
}

TEST(Accumulation, RendererBuffersResetAndImages) {
  Scene scene = make_cornell_box(false);
  TraceParams params;
  params.threads = 2;
  ProgressiveRenderer renderer(scene, params, 16, 12);
  for (int i = 0; i < 3; ++i) renderer.add_frame();
  EXPECT_EQ(renderer.frames(), 3);
  EXPECT_EQ(renderer.stats().paths, 3u * 16 * 12);
  EXPECT_GT(renderer.stats().rays, renderer.stats().paths);
  Image samples = renderer.samples_image();
  ASSERT_EQ(samples.channels, std::vector<std::string>{"Y"});
  for (float s : samples.pixels) EXPECT_EQ(s, 3.0f);
  Image variance = renderer.variance_image();
  std::vector<float> vom = renderer.variance_of_mean();
  for (size_t i = 0; i < vom.size(); ++i) {
    EXPECT_GE(vom[i], 0.0f);
    EXPECT_EQ(variance.pixels[i], vom[i]);
  }
  Image lv = renderer.lv_image();
  EXPECT_EQ(lv.width, 16);
  EXPECT_EQ(lv.num_channels(), 3);
  Camera moved = renderer.camera();
  moved.yfov *= 0.5f;
  renderer.set_camera(moved);
  EXPECT_EQ(renderer.frames(), 0);
  EXPECT_EQ(renderer.accumulation().samples[0], 0u);
  EXPECT_EQ(renderer.variance_of_mean()[0], -1.0f);
  EXPECT_EQ(renderer.stats().paths, 0u);
}

// Camera at the origin looking down -z at z = -1: left half an emitter facing the camera
// (or away from it), right half a grey wall. On a 9-pixel-wide image the seam x = 0 runs
// through the middle of column 4.
Scene half_emitter_scene(bool emitter_faces_camera) {
  Scene scene;
  scene.source = "test:half-emitter";
  scene.materials = {make_diffuse(glm::vec3(0.5f)), make_emitter(glm::vec3(4.0f))};
  const glm::vec3 up(0, 20, 0), right(20, 0, 0);
  if (emitter_faces_camera)
    scene.meshes.push_back(make_quad(glm::vec3(-20, -10, -1), right, up, 1));  // normal +z
  else
    scene.meshes.push_back(make_quad(glm::vec3(-20, -10, -1), up, right, 1));  // normal -z
  scene.meshes.push_back(make_quad(glm::vec3(0, -10, -1), right, up, 0));
  scene.camera = look_at_camera(glm::vec3(0), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), 0.8f);
  return scene;
}

TEST(Accumulation, EmitterCoverageIsTheFractionOfCameraRaysSeeingAnEmitter) {
  TraceParams params;
  params.threads = 2;
  const Scene scene = half_emitter_scene(true);
  ProgressiveRenderer renderer(scene, params, 9, 4);
  const Image coverage = renderer.emitter_coverage_image();
  ASSERT_EQ(coverage.channels, std::vector<std::string>{"Y"});
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 9; ++x) {
      const float expected = x < 4 ? 1.0f : (x == 4 ? 0.5f : 0.0f);  // 2 of the 2x2 rays at the seam
      EXPECT_EQ(coverage.at(x, y, 0), expected) << x << "," << y;
    }
  // An emitter seen from its back emits nothing toward the camera: not in the mask.
  const Scene back = half_emitter_scene(false);
  ProgressiveRenderer back_renderer(back, params, 9, 4);
  for (float v : back_renderer.emitter_coverage_image().pixels) EXPECT_EQ(v, 0.0f);
}

}  // namespace

// Luminance near the float limit has a variance beyond float range; it saturates.
TEST(Accumulation, VarianceOfMeanSaturatesInsteadOfOverflowing) {
  Accumulation acc;
  resize_accumulation(acc, 1, 1);
  for (int i = 0; i < 8; ++i) accumulate_sample(acc, 0, glm::vec3(0.0f), glm::vec3(i % 2 ? 3e38f : 0.0f));
  EXPECT_TRUE(std::isfinite(acc.variance_of_mean(0)));
  EXPECT_EQ(acc.variance_of_mean(0), std::numeric_limits<float>::max());
}

}  // namespace pxf
