// Light through openings (environment_visibility.h): the regions, what a region learns and when,
// the learned sky's sampling against its pdf (chi-square), the light sampler's mixture, the state's
// round trip, and in the renderer: an unbiased room lit through a window (block Z-test against
// sampling by radiance) with less noise, no change without an environment, the same image with 1
// and 2 threads, and a restored render that continues exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "pathtracer/accumulation_state.h"
#include "pathtracer/environment_visibility.h"
#include "pathtracer/integrator.h"
#include "pathtracer/lights.h"
#include "scene/texture.h"
#include "testing/block_z_test.h"
#include "testing/learned_state_test.h"
#include "testing/shapes.h"
#include "testing/stat_tests.h"

namespace pxf {
namespace {

const glm::vec3 kLo(-1.0f), kHi(1.0f);
const glm::vec3 kUp(0.0f, 1.0f, 0.0f);

// A direction inside the "window": a patch of the sky around +x, 0.3 rad either way.
glm::vec3 window_direction(float a, float b) { return glm::normalize(glm::vec3(1.0f, 0.3f + 0.6f * a - 0.3f, 0.6f * b - 0.3f)); }

// `count` unblocked NEE records from the window, and as many blocked ones from elsewhere, at the origin.
void record_window(EnvironmentVisibility& field, uint32_t region, int count) {
  for (int i = 0; i < count; ++i) {
    const float a = (i % 7) / 7.0f, b = (i % 11) / 11.0f;
    field.record(region, window_direction(a, b), 1.0f, true, true);
    field.record(region, glm::normalize(glm::vec3(-1.0f, 0.5f, b)), 4.0f, false, true);
  }
}

TEST(EnvironmentVisibility, RegionsSeparateCellsAndSides) {
  const EnvironmentVisibility field(sky_with_sun(), kLo, kHi);
  const uint32_t r = field.region(glm::vec3(0.1f), kUp);
  EXPECT_NE(r, EnvironmentVisibility::kNoRegion);
  EXPECT_NE(field.region(glm::vec3(0.1f), -kUp), r);                     // the other side of a surface
  EXPECT_NE(field.region(glm::vec3(0.1f), glm::vec3(1, 0, 0)), r);      // another axis
  EXPECT_NE(field.region(glm::vec3(0.9f), kUp), r);                      // another cell
  EXPECT_EQ(field.region(glm::vec3(0.1001f), glm::vec3(0.1f, 1, 0)), r);  // the same cell and side
  EXPECT_EQ(field.region(glm::vec3(1.5f), kUp), EnvironmentVisibility::kNoRegion);
  EXPECT_EQ(field.region(glm::vec3(NAN), kUp), EnvironmentVisibility::kNoRegion);
  EXPECT_LE(field.region_count(), EnvironmentVisibility::kMaxCells * EnvironmentVisibility::kSides);
  EXPECT_EQ(field.sky(r).region(), r);  // not learned yet, but its samples are recorded there
  EXPECT_FALSE(field.sky(r).learned());
  EXPECT_EQ(VisibleSky{}.region(), EnvironmentVisibility::kNoRegion);
}

// A region samples what it learned once it holds kMinRecords unblocked records, at the field's
// frames 1, 2, 4, 8, ... only; where most of NEE's light got through it draws nothing from it.
TEST(EnvironmentVisibility, LearnsFromEnoughRecordsAtDoublingFrames) {
  EnvironmentVisibility field(sky_with_sun(), kLo, kHi);
  const uint32_t r = field.region(glm::vec3(0.0f), kUp);
  record_window(field, r, EnvironmentVisibility::kMinRecords - 1);
  field.end_frame();  // frame 1: too few records
  EXPECT_FALSE(field.sky(r).learned());
  record_window(field, r, 1);
  field.end_frame();  // frame 2
  ASSERT_TRUE(field.sky(r).learned());
  EXPECT_FLOAT_EQ(field.sky(r).share(), EnvironmentVisibility::kMaxLearnedShare);  // a fifth got through
  EXPECT_EQ(field.learned_regions(), 1u);
  // An open sky: everything gets through, and the region keeps sampling by radiance.
  const uint32_t open = field.region(glm::vec3(0.5f), kUp);
  for (int i = 0; i < 64; ++i) field.record(open, window_direction(0.5f, 0.5f), 1.0f, true, true);
  field.end_frame();  // frame 3: no rebuild
  EXPECT_FALSE(field.sky(open).learned());
  field.end_frame();  // frame 4
  EXPECT_FALSE(field.sky(open).learned());  // nothing to draw from it: no distribution kept
  EXPECT_FLOAT_EQ(EnvironmentVisibility::learned_share(0.5), 0.5f * EnvironmentVisibility::kMaxLearnedShare);
}

// The learned sky's sample() draws from its pdf(): chi-square over its 32 x 16 equirect bins, the
// expected counts from the pdf integrated over each bin, inside which its density over the
// equirect square is constant (so the sum is exact); the pdf it returns is pdf() (but where a
// direction lands on a bin's edge and reads as the next bin), and the pdf integrates to 1.
TEST(EnvironmentVisibility, LearnedSkySamplesItsPdf) {
  EnvironmentVisibility field(sky_with_sun(), kLo, kHi);
  const uint32_t r = field.region(glm::vec3(0.0f), kUp);
  record_window(field, r, 200);
  field.record(r, glm::normalize(glm::vec3(1.0f, 0.8f, 0.1f)), 50.0f, true, true);  // the sun
  field.end_frame();
  const VisibleSky sky = field.sky(r);
  ASSERT_TRUE(sky.learned());
  constexpr int nu = 32, nv = 16, fine = 4;
  std::vector<double> expected(nu * nv, 0.0), observed(nu * nv, 0.0);
  double integral = 0.0;
  for (int y = 0; y < nv * fine; ++y)
    for (int x = 0; x < nu * fine; ++x) {
      const glm::vec2 uv((x + 0.5f) / (nu * fine), (y + 0.5f) / (nv * fine));
      const double uv_density = sky.pdf(equirect_direction(uv)) * 2.0 * kPi * kPi * std::sin(kPi * uv.y);
      const double p = uv_density / (nu * fine * nv * fine);
      expected[(y / fine) * nu + x / fine] += p;
      integral += p;
    }
  EXPECT_NEAR(integral, 1.0, 1e-3);
  const int n = 200000;
  Rng rng(5, 0, 0);
  int pdf_mismatches = 0;
  for (int k = 0; k < n; ++k) {
    float pdf;
    const glm::vec3 d = sky.sample(rng.next_2d(), &pdf);
    pdf_mismatches += std::abs(pdf / sky.pdf(d) - 1.0) > 1e-3;
    const glm::vec2 uv = equirect_uv(d);
    observed[std::min(static_cast<int>(uv.y * nv), nv - 1) * nu + std::min(static_cast<int>(uv.x * nu), nu - 1)] += 1.0;
  }
  for (double& e : expected) e *= n;
  const stat::ChiSquareResult chi = stat::chi_square(observed, expected);
  std::printf("learned sky: chi2 %.1f, %d dof, p %.3g; pdf mismatches %d of %d\n", chi.statistic, chi.dof, chi.p_value,
              pdf_mismatches, n);
  EXPECT_GT(chi.p_value, 1e-3);
  EXPECT_LT(pdf_mismatches, n / 1000);
}

// With a learned sky the light sampler's environment samples come from the mixture: each sample's
// pdf is what pdf_environment() says of its direction given the same sky, and luminance / pdf
// estimates the sky's integral as sampling by radiance does (Z-test).
TEST(EnvironmentVisibility, LightSamplerMixtureIsUnbiased) {
  const Scene scene = make_room_with_window();
  const LightSampler lights(scene);
  EnvironmentVisibility field(*scene.environment, kLo, kHi);
  const glm::vec3 point(0.0f, -0.99f, 0.0f);
  const uint32_t r = field.region(point, kUp);
  record_window(field, r, 64);
  field.end_frame();
  const VisibleSky sky = field.sky(r);
  ASSERT_TRUE(sky.learned());
  ASSERT_GT(sky.share(), 0.0f);
  const int n = 400000;
  double sum[2] = {0, 0}, sum2[2] = {0, 0};
  int pdf_mismatches = 0;
  Rng rng(9, 0, 0);
  for (int k = 0; k < n; ++k)
    for (int mixed = 0; mixed < 2; ++mixed) {
      LightSample ls;
      ASSERT_TRUE(lights.sample(point, rng.next_2d(), &ls, mixed ? &sky : nullptr));
      if (mixed) pdf_mismatches += std::abs(ls.pdf / lights.pdf_environment(ls.wi, &sky) - 1.0) > 1e-3;
      const double e = luminance(ls.radiance) / ls.pdf;
      sum[mixed] += e;
      sum2[mixed] += e * e;
    }
  double mean[2], var[2];
  for (int m = 0; m < 2; ++m) {
    mean[m] = sum[m] / n;
    var[m] = (sum2[m] / n - mean[m] * mean[m]) / n;
  }
  const double z = (mean[1] - mean[0]) / std::sqrt(var[0] + var[1]);
  std::printf("sky integral: mixture %.4f, radiance %.4f, z %.2f\n", mean[1], mean[0], z);
  EXPECT_LT(std::abs(z), 4.0);
  EXPECT_LT(pdf_mismatches, n / 1000);
}

// Fixed-point sums: the same records in another order give the same bytes; the bytes restore into
// a field of the same grid and environment, and anything else is refused in one line.
TEST(EnvironmentVisibility, SerializesExactlyAndRefusesOthers) {
  EnvironmentVisibility a(sky_with_sun(), kLo, kHi), b(sky_with_sun(), kLo, kHi);
  const uint32_t r1 = a.region(glm::vec3(0.0f), kUp), r2 = a.region(glm::vec3(0.5f), -kUp);
  for (int i = 0; i < 40; ++i) {
    a.record(r1, window_direction(i / 40.0f, 0.3f), 0.1f * i, true, true);
    a.record(r2, window_direction(0.3f, i / 40.0f), 1.0f, i % 4 == 0, true);
  }
  for (int i = 39; i >= 0; --i) {
    b.record(r2, window_direction(0.3f, i / 40.0f), 1.0f, i % 4 == 0, true);
    b.record(r1, window_direction(i / 40.0f, 0.3f), 0.1f * i, true, true);
  }
  a.end_frame();
  b.end_frame();
  const std::vector<uint8_t> bytes = a.serialize();
  EXPECT_EQ(bytes, b.serialize());
  EnvironmentVisibility c(sky_with_sun(), kLo, kHi);
  c.deserialize(bytes.data(), bytes.size());
  EXPECT_EQ(c.serialize(), bytes);
  EXPECT_EQ(c.learned_regions(), a.learned_regions());
  EXPECT_EQ(c.frames(), 1u);
  EnvironmentVisibility other_box(sky_with_sun(), kLo, 2.0f * kHi);
  EXPECT_THROW(other_box.deserialize(bytes.data(), bytes.size()), Error);
  EnvironmentVisibility other_sky(uniform_environment(1.0f), kLo, kHi);
  EXPECT_THROW(other_sky.deserialize(bytes.data(), bytes.size()), Error);
  std::vector<uint8_t> corrupt = bytes;
  corrupt[corrupt.size() / 2] ^= 1;
  EXPECT_THROW(c.deserialize(corrupt.data(), corrupt.size()), Error);
  EXPECT_THROW(c.deserialize(bytes.data(), bytes.size() / 2), Error);
  EXPECT_THROW(c.deserialize(nullptr, 0), Error);
  EXPECT_EQ(c.serialize(), bytes);  // a refused state leaves the field as it was
}

// Light through openings alone: without the guiding that --guiding auto starts in such a room, so
// that these figures and resumes are the visibility field's (guiding's own: guiding_test.cpp).
TraceParams room_params(bool visibility, uint64_t seed) {
  TraceParams params;
  params.guiding = GuidingMode::Off;
  params.environment_visibility = visibility;
  params.seed = seed;
  params.threads = 2;
  return params;
}

// Unbiased and worth it: the room lit through its window agrees with a render that samples the sky
// by radiance (another seed), block by block and over the image, and its variance at equal samples
// is less than 0.7 of that one's. The reference traces 8 times the frames: sampled by radiance, the
// sky through the window is heavy-tailed, and at equal frames its variance estimate reads low
// (at 2048 frames two dark blocks were 4.5 and 5.8 of those low standard errors away).
TEST(EnvironmentVisibility, RoomAgreesWithRadianceSamplingWithLessNoise) {
  const Scene scene = make_room_with_window();
  const int w = 32, h = 24, frames = 512, reference_frames = 8 * frames;
  ProgressiveRenderer learned(scene, room_params(true, 11), w, h), plain(scene, room_params(false, 12), w, h);
  for (int i = 0; i < frames; ++i) learned.add_frame();
  for (int i = 0; i < reference_frames; ++i) plain.add_frame();
  const BlockComparison c = compare_blocks(learned.accumulation(), plain.accumulation(), 4, "learned sky vs radiance");
  EXPECT_LT(c.worst_z, 4.5);
  EXPECT_LE(c.beyond3, 2);
  EXPECT_LT(std::abs(c.image_z), 4.0);
  EXPECT_GT(learned.environment_visibility_regions(), 10u);
  EXPECT_LT(c.variance_a, 0.7 * c.variance_b * reference_frames / frames);
  EXPECT_TRUE(plain.environment_visibility().empty());
}

// A scene that sees most of its sky (spheres under a uniform sky) goes dormant at the field's 4th
// frame: nothing learned, nothing asked, and the state says so.
TEST(EnvironmentVisibility, OpenSkyGoesDormant) {
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.8f))};
  scene.meshes.push_back(make_sphere(glm::vec3(0.0f), 0.5f, 0));
  scene.meshes.push_back(make_quad(glm::vec3(-2, -0.5f, 2), glm::vec3(4, 0, 0), glm::vec3(0, 0, -4), 0));
  scene.environment = sky_with_sun();
  scene.camera = look_at_camera(glm::vec3(0, 0.5f, 3.0f), glm::vec3(0), glm::vec3(0, 1, 0), 0.8f);
  ProgressiveRenderer renderer(scene, room_params(true, 8), 24, 20);
  for (int i = 0; i < 3; ++i) renderer.add_frame();
  EXPECT_GT(renderer.environment_visibility_regions(), 0u);  // regions in the sphere's shadow learned
  renderer.add_frame();
  EXPECT_EQ(renderer.environment_visibility_regions(), 0u);
  EXPECT_FALSE(renderer.environment_visibility().empty());  // the state keeps the dormant field
  // The room, enclosed, stays awake.
  const Scene enclosed = make_room_with_window();
  ProgressiveRenderer room(enclosed, room_params(true, 8), 24, 20);
  for (int i = 0; i < 8; ++i) room.add_frame();
  EXPECT_GT(room.environment_visibility_regions(), 0u);
}

// A scene without an environment has nothing to learn: the same samples either way, and no state.
TEST(EnvironmentVisibility, SceneWithoutEnvironmentTracesTheSameSamples) {
  const Scene scene = make_cornell_box(false);
  ProgressiveRenderer on(scene, room_params(true, 3), 24, 20), off(scene, room_params(false, 3), 24, 20);
  for (int i = 0; i < 4; ++i) {
    on.add_frame();
    off.add_frame();
  }
  EXPECT_TRUE(same_accumulation(on.accumulation(), off.accumulation()));
  EXPECT_TRUE(on.environment_visibility().empty());
}

// Fixed-point sums and rebuilds between frames: the image and what was learned are the same with
// 1 and 2 threads, masked frames too.
TEST(EnvironmentVisibility, DeterministicAcrossThreadCounts) {
  const Scene scene = make_room_with_window();
  expect_thread_count_independent(scene, room_params(true, 21),
                                  [](const ProgressiveRenderer& r) { return r.environment_visibility(); });
  ProgressiveRenderer learned(scene, room_params(true, 21), 40, 30);
  for (int i = 0; i < 4; ++i) learned.add_frame();
  EXPECT_GT(learned.environment_visibility_regions(), 0u);  // the state compared above is not empty
}

// Restored from its accumulation and what it learned after k frames, a render continues exactly,
// between rebuilds and just after one; restored without it, it learns anew (other samples); a
// state that is not one is refused.
TEST(EnvironmentVisibility, RestoredRenderContinuesExactly) {
  const Scene scene = make_room_with_window();
  expect_resume_continues_exactly(
      scene, room_params(true, 4), 24, 20, 10, {3, 4},
      [](const ProgressiveRenderer& r) { return r.environment_visibility(); },
      [](ProgressiveRenderer& r, const Accumulation& acc, int k, const std::vector<uint32_t>& traced,
         const std::vector<uint8_t>& learned) { r.restore(acc, 0, k, traced, {}, learned); });
}

// The state file keeps the flag and what was learned; a merge of shards keeps nothing learned.
TEST(EnvironmentVisibility, StateKeepsWhatWasLearned) {
  const Scene scene = make_room_with_window();
  const TraceParams params = room_params(true, 6);
  const int w = 12, h = 10;
  const auto state_of = [&](uint32_t begin, uint32_t end) {
    ProgressiveRenderer r(scene, params, w, h);
    r.set_first_frame(begin);
    for (uint32_t i = begin; i < end; ++i) r.add_frame();
    AccumulationState s;
    s.settings = sample_settings(1, w, h, params);
    s.frames = {FrameRange{begin, end}};
    s.acc = r.accumulation();
    s.traced = r.pixel_frames();
    s.environment_visibility = r.environment_visibility();
    return s;
  };
  const AccumulationState a = state_of(0, 4), b = state_of(4, 6);
  ASSERT_FALSE(a.environment_visibility.empty());
  const std::vector<uint8_t> file = encode_state(a);
  const AccumulationState decoded = decode_state(file.data(), file.size());
  EXPECT_EQ(decoded.settings.environment_visibility, 1u);
  EXPECT_EQ(decoded.environment_visibility, a.environment_visibility);
  AccumulationState off = a;
  off.settings.environment_visibility = 0;
  EXPECT_THROW(encode_state(off), Error);  // learned state without the flag
  EXPECT_NE(a.settings.difference(off.settings).find("env-visibility"), std::string::npos);
  const AccumulationState merged = merge_states({a, b});
  EXPECT_TRUE(merged.environment_visibility.empty());
}

}  // namespace
}  // namespace pxf
