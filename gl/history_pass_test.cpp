// The history passes (gl/history_pass.h) against the CPU reference (gl/history_reference.h), and
// the history's formulas on their own: an unmoved camera reprojects exactly, a disoccluded surface
// is rejected, the weight falls to 0 after kHistoryFadeSamples fresh samples.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <glm/gtc/matrix_transform.hpp>
#include "gl/history_pass.h"
#include "gl/history_reference.h"
#include "gl/test_util.h"

namespace pxf {
namespace {

constexpr int W = 37, H = 29;

Camera test_camera(glm::vec3 position, float yaw_degrees) {
  Camera c;
  c.yfov = 0.7f;
  c.camera_to_world = glm::rotate(glm::translate(glm::mat4(1.0f), position), glm::radians(yaw_degrees), {0, 1, 0});
  return c;
}

// The range buffer of a wall at z = -6 (a checker of two colors) behind a yellow card at z = -3
// (x in [-0.6, 0.4], y in [-0.5, 0.5]), at the pixel centers: distance along the camera ray.
Image analytic_guide(const Camera& camera) {
  Image g = Image::rgba(W, H);
  const shared::ViewCamera v = view_camera(camera, W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const glm::vec3 o = v.origin, d = shared::view_point(v, {x + 0.5f, y + 0.5f}, 1.0f) - o;
      glm::vec3 color(0.0f);
      float t = (-3.0f - o.z) / d.z;
      glm::vec3 hit = o + t * d;
      if (t > 0 && hit.x >= -0.6f && hit.x <= 0.4f && hit.y >= -0.5f && hit.y <= 0.5f) {
        color = {0.9f, 0.8f, 0.1f};
      } else {
        t = (-6.0f - o.z) / d.z;
        hit = o + t * d;
        const bool odd = (static_cast<int>(std::floor(2.0f * hit.x)) + static_cast<int>(std::floor(2.0f * hit.y))) & 1;
        color = odd ? glm::vec3(0.2f, 0.5f, 0.3f) : glm::vec3(0.6f, 0.3f, 0.2f);
      }
      for (int c = 0; c < 3; ++c) g.at(x, y, c) = color[c];
      g.at(x, y, 3) = t;  // d is unit length
    }
  return g;
}

struct FreshSamples {
  Image lv = Image::rgba(W, H), hv = Image::rgba(W, H);
};

// Noisy radiance with known and unknown (n < 2) variances, one non-finite pixel.
FreshSamples random_samples(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  FreshSamples s;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      for (int c = 0; c < 3; ++c) {
        s.lv.at(x, y, c) = 0.5f * u01(rng);
        s.hv.at(x, y, c) = 2.0f * u01(rng);
      }
      s.lv.at(x, y, 3) = 1.0f;
      s.hv.at(x, y, 3) = u01(rng) < 0.1f ? shared::kVarUnknown : 0.01f * u01(rng);
    }
  s.hv.at(3, 4, 1) = std::numeric_limits<float>::quiet_NaN();
  return s;
}

void upload(PreviewInputs& inputs, const FreshSamples& s) {
  inputs.upload_packed_with_threshold(s.lv.pixels.data(), s.hv.pixels.data());
}

Texture2D texture_of(const Image& rgba) {
  Texture2D t(W, H, TextureFormat::RGBA32F);
  t.upload(rgba);
  return t;
}

void expect_near_images(const Image& gl, const Image& cpu, const Image& outcome_gl, const Image& outcome_cpu,
                        const char* what) {
  int differ = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (outcome_gl.at(x, y, 0) != outcome_cpu.at(x, y, 0)) continue;
      for (int c = 0; c < cpu.num_channels(); ++c) {
        const float a = gl.at(x, y, c), b = cpu.at(x, y, c);
        if (!(std::abs(a - b) <= 1e-4f * std::max(1.0f, std::abs(b)))) ++differ;
      }
    }
  EXPECT_EQ(differ, 0) << what;
}

TEST(HistoryPass, ReprojectionAndCombinationMatchTheCpuReference) {
  test::osmesa_context();
  const Camera before = test_camera({0.0f, 0.0f, 0.0f}, 0.0f);
  const Camera now = test_camera({0.25f, 0.05f, 0.1f}, 3.0f);
  const Image guide_before = analytic_guide(before), guide_now = analytic_guide(now);
  const FreshSamples previous = random_samples(1), fresh = random_samples(2);
  const float previous_samples = 5.0f;

  HistoryPass pass(W, H);
  PreviewInputs inputs(W, H);
  upload(inputs, previous);
  const Texture2D guide_before_tex = texture_of(guide_before), guide_now_tex = texture_of(guide_now);
  // One specular pixel in each view (flag in alpha): neither gives nor takes history.
  Image flags_before = Image::rgba(W, H), flags_now = Image::rgba(W, H);
  flags_before.at(20, 14, 3) = 1.0f;
  flags_now.at(12, 9, 3) = 1.0f;
  const Texture2D flags_before_tex = texture_of(flags_before), flags_now_tex = texture_of(flags_now);
  pass.keep(inputs, previous_samples, guide_before_tex, flags_before_tex, before);
  pass.reproject(guide_now_tex, flags_now_tex, now);

  const HistoryCombination kept = cpu_combine_history(previous.lv, previous.hv, previous_samples, nullptr);
  const Image specular_before = flags_before.select({"A"}), specular_now = flags_now.select({"A"});
  const HistoryReprojection cpu = cpu_reproject_history(kept.state, kept.hv, guide_before, before, guide_now, now,
                                                        &specular_before, &specular_now);
  EXPECT_EQ(cpu.outcome.at(12, 9, 0), shared::kHistoryDisoccluded);  // the specular pixel takes none
  const Image outcome = pass.outcome_image();
  int mismatched = 0, counts[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < outcome.pixels.size(); ++i) {
    mismatched += outcome.pixels[i] != cpu.outcome.pixels[i];
    ++counts[static_cast<int>(cpu.outcome.pixels[i])];
  }
  // The float rounding of a tolerance test may flip a pixel's outcome; none did here.
  EXPECT_LE(mismatched, 2);
  EXPECT_GT(counts[shared::kHistoryKept], W * H / 2);
  EXPECT_GT(counts[shared::kHistoryDisoccluded], 10);  // the wall beside the card, uncovered by the move
  EXPECT_GT(counts[shared::kHistoryOutside], 10);      // the strip the move brought into view
  expect_near_images(pass.history_lv_image(), cpu.lv, outcome, cpu.outcome, "history L_lv and count");
  expect_near_images(pass.history_hv_image(), cpu.hv, outcome, cpu.outcome, "history L_u and Var");

  for (float n : {1.0f, 4.0f, shared::kHistoryFadeSamples}) {
    upload(inputs, fresh);
    const PreviewInputs& combined = pass.combine(inputs, n);
    const HistoryCombination c = cpu_combine_history(fresh.lv, fresh.hv, n, &cpu);
    const Image same = Image::gray(W, H);
    expect_near_images(combined.lv().download({"R", "G", "B", "A"}), c.lv, same, same, "combined L_lv");
    expect_near_images(combined.hv().download({"R", "G", "B", "A"}), c.hv, same, same, "combined L_u");
    expect_near_images(pass.weight_image(), c.weight, same, same, "history weight");
  }
}

// The same camera before and after: every pixel center but the card's silhouette reprojects onto its own texel (up to the
// rounding of the projection, a bilinear fraction of about 1e-5).
TEST(HistoryPass, AnUnmovedCameraReprojectsEveryPixelOntoItself) {
  const Camera camera = test_camera({0.1f, 0.0f, 0.0f}, 1.0f);
  const Image guide = analytic_guide(camera);
  const FreshSamples s = random_samples(3);
  const HistoryCombination kept = cpu_combine_history(s.lv, s.hv, 3.0f, nullptr);
  const HistoryReprojection r = cpu_reproject_history(kept.state, kept.hv, guide, camera, guide, camera);
  auto silhouette = [&](int x, int y) {  // a 4-neighbour more than kHistoryEdgeDepthJump away
    const float d = guide.at(x, y, 3);
    const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int i = 0; i < 4; ++i) {
      const int qx = x + dx[i], qy = y + dy[i];
      if (qx >= 0 && qy >= 0 && qx < W && qy < H && std::abs(guide.at(qx, qy, 3) - d) > shared::kHistoryEdgeDepthJump * d)
        return true;
    }
    return false;
  };
  int edges = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (silhouette(x, y)) {  // neither gives nor takes history
        EXPECT_EQ(r.outcome.at(x, y, 0), shared::kHistoryDisoccluded) << x << "," << y;
        ++edges;
        continue;
      }
      ASSERT_EQ(r.outcome.at(x, y, 0), shared::kHistoryKept) << x << "," << y;
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(r.lv.at(x, y, c), kept.state.at(x, y, c), 1e-4f) << x << "," << y;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.hv.at(x, y, c), kept.hv.at(x, y, c), 1e-4f) << x << "," << y;
      // An unknown variance may be taken from a neighbour whose bilinear weight is a rounding error.
      if (kept.hv.at(x, y, 3) >= 0.0f) {
        EXPECT_NEAR(r.hv.at(x, y, 3), kept.hv.at(x, y, 3), 1e-4f) << x << "," << y;
      }
    }
  EXPECT_GT(edges, 10);
}

// A surface that another one hid in the previous view gets no history from it.
TEST(HistoryPass, ASurfaceTheCardHidBeforeIsRejected) {
  const Camera before = test_camera({0.0f, 0.0f, 0.0f}, 0.0f);
  const Camera now = test_camera({0.6f, 0.0f, 0.0f}, 0.0f);
  const Image guide_before = analytic_guide(before), guide_now = analytic_guide(now);
  const FreshSamples s = random_samples(4);
  const HistoryCombination kept = cpu_combine_history(s.lv, s.hv, 3.0f, nullptr);
  const HistoryReprojection r = cpu_reproject_history(kept.state, kept.hv, guide_before, before, guide_now, now);
  const shared::ViewCamera v_now = view_camera(now, W, H), v_before = view_camera(before, W, H);
  int hidden = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      // The wall point this pixel shows, and whether the card covered it from the previous camera.
      const glm::vec3 p = shared::view_point(v_now, {x + 0.5f, y + 0.5f}, guide_now.at(x, y, 3));
      if (p.z > -5.0f) continue;  // the card itself
      const glm::vec3 to = p - v_before.origin;
      const glm::vec3 on_card = v_before.origin + to * ((-3.0f - v_before.origin.z) / to.z);
      const float margin = 0.1f;  // away from the card's edges, where the bilinear taps straddle it
      if (on_card.x < -0.6f + margin || on_card.x > 0.4f - margin || std::abs(on_card.y) > 0.5f - margin) continue;
      ++hidden;
      EXPECT_EQ(r.outcome.at(x, y, 0), shared::kHistoryDisoccluded) << x << "," << y;
      EXPECT_EQ(r.lv.at(x, y, 3), 0.0f) << x << "," << y;
    }
  EXPECT_GT(hidden, 20);
}

// The card alone, the same color on both sides, before an empty background.
Image card_guide(const Camera& camera) {
  Image g = Image::rgba(W, H);
  const shared::ViewCamera v = view_camera(camera, W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const glm::vec3 o = v.origin, d = shared::view_point(v, {x + 0.5f, y + 0.5f}, 1.0f) - o;
      const float t = (-3.0f - o.z) / d.z;
      const glm::vec3 hit = o + t * d;
      const bool card = t > 0 && std::abs(hit.x) <= 0.5f && std::abs(hit.y) <= 0.5f;
      for (int c = 0; c < 3; ++c) g.at(x, y, c) = card ? 0.3f : 0.0f;
      g.at(x, y, 3) = card ? t : shared::kBackgroundDepth;
    }
  return g;
}

// Whether a guide's pixel is background with the surface among its eight neighbours.
bool background_beside_card(const Image& guide, int x, int y) {
  if (guide.at(x, y, 3) < shared::kBackgroundDistanceMin) return false;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int u = x + dx, v = y + dy;
      if (u >= 0 && v >= 0 && u < W && v < H && guide.at(u, v, 3) < shared::kBackgroundDistanceMin) return true;
    }
  return false;
}

// A background pixel beside a surface mixes the two in its samples: it neither gives history (a
// marked value in such pixels of the previous view reaches no pixel of the new one) nor takes any.
// Reprojected as background it carried an orbited sphere's light away with the background.
TEST(HistoryPass, ABackgroundPixelBesideASurfaceNeitherGivesNorTakesHistory) {
  test::osmesa_context();
  const Camera before = test_camera({0.0f, 0.0f, 0.0f}, 0.0f);
  const Camera now = test_camera({0.0f, 0.0f, 0.0f}, 4.0f);
  const Image guide_before = card_guide(before), guide_now = card_guide(now);
  FreshSamples previous = random_samples(6);
  constexpr float kMarker = 1000.0f;
  int marked = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (background_beside_card(guide_before, x, y)) {
        for (int c = 0; c < 3; ++c) previous.lv.at(x, y, c) = kMarker;
        ++marked;
      }
  const HistoryCombination kept = cpu_combine_history(previous.lv, previous.hv, 3.0f, nullptr);
  const HistoryReprojection cpu = cpu_reproject_history(kept.state, kept.hv, guide_before, before, guide_now, now);

  HistoryPass pass(W, H);
  PreviewInputs inputs(W, H);
  upload(inputs, previous);
  const Texture2D guide_before_tex = texture_of(guide_before), guide_now_tex = texture_of(guide_now);
  const Texture2D no_flags = texture_of(Image::rgba(W, H));
  pass.keep(inputs, 3.0f, guide_before_tex, no_flags, before);
  pass.reproject(guide_now_tex, no_flags, now);
  const Image outcome = pass.outcome_image(), lv = pass.history_lv_image();
  EXPECT_EQ(outcome.pixels, cpu.outcome.pixels);

  int beside = 0, background_kept = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      for (const Image* image : {&cpu.lv, &lv}) EXPECT_LT(image->at(x, y, 0), 0.5f * kMarker) << x << "," << y;
      if (background_beside_card(guide_now, x, y)) {
        ++beside;
        EXPECT_EQ(cpu.lv.at(x, y, 3), 0.0f) << x << "," << y;
        EXPECT_EQ(lv.at(x, y, 3), 0.0f) << x << "," << y;
      } else if (guide_now.at(x, y, 3) >= shared::kBackgroundDistanceMin && cpu.lv.at(x, y, 3) > 0.0f) {
        ++background_kept;
      }
    }
  EXPECT_GT(marked, 20);
  EXPECT_GT(beside, 20);
  EXPECT_GT(background_kept, W * H / 3);  // the rest of the background keeps its history
}

// A thin card seen from its other side: the same distance and range color, but it faces away.
TEST(HistoryPass, TheOtherSideOfAThinCardIsRejected) {
  const Camera before = test_camera({0.0f, 0.0f, 0.0f}, 0.0f);
  const Camera behind = test_camera({0.0f, 0.0f, -6.0f}, 180.0f);
  const Image guide_before = card_guide(before), guide_behind = card_guide(behind);
  const FreshSamples s = random_samples(5);
  const HistoryCombination kept = cpu_combine_history(s.lv, s.hv, 3.0f, nullptr);
  const HistoryReprojection r = cpu_reproject_history(kept.state, kept.hv, guide_before, before, guide_behind, behind);
  int card = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (guide_behind.at(x, y, 3) >= shared::kBackgroundDistanceMin) continue;
      ++card;
      EXPECT_EQ(r.outcome.at(x, y, 0), shared::kHistoryDisoccluded) << x << "," << y;
    }
  EXPECT_GT(card, 50);
}

// The history is a biased estimate: its weight falls with the fresh samples and is exactly 0 from
// kHistoryFadeSamples on, where the fresh samples pass through unchanged.
TEST(HistoryPass, TheHistorysWeightFallsToZeroAndTheFreshSamplesPassThrough) {
  shared::HistorySample h = shared::history_none(shared::kHistoryKept);
  h.lv = glm::vec3(1.0f);
  h.hv = glm::vec3(2.0f);
  h.var = 0.01f;
  h.count = 20.0f;
  float previous = 1.0f;
  for (float n = 1.0f; n < shared::kHistoryFadeSamples; n += 1.0f) {
    const float a = shared::history_weight(h.count, n);
    EXPECT_GT(a, 0.0f) << n;
    EXPECT_LT(a, previous) << n;
    previous = a;
  }
  const glm::vec3 lv(0.3f, 0.2f, 0.1f), hv(0.7f, 0.5f, 0.4f);
  const shared::HistoryBlend b = shared::combine_history(lv, hv, 0.002f, shared::kHistoryFadeSamples, h);
  EXPECT_EQ(b.weight, 0.0f);
  EXPECT_EQ(b.lv, lv);
  EXPECT_EQ(b.hv, hv);
  EXPECT_EQ(b.var, 0.002f);
  // One fresh sample (its variance unknown): the history's per-sample variance stands in for it.
  const shared::HistoryBlend one = shared::combine_history(lv, hv, shared::kVarUnknown, 1.0f, h);
  const float a = one.weight;
  EXPECT_NEAR(one.var, a * a * 0.01f + (1 - a) * (1 - a) * 0.01f * 20.0f, 1e-6f);
  EXPECT_NEAR(one.hv.x, a * 2.0f + (1 - a) * 0.7f, 1e-6f);
}

}  // namespace
}  // namespace pxf
