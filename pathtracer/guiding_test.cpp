// Path guiding in the integrator and the renderer (TraceParams::guiding, docs/guiding.md): white
// furnaces stay at 1, a guided image agrees with an unguided one of another seed (block Z-test),
// guiding off and an untrained field trace the samples of before, the image and the field do not
// depend on the thread count (masked frames too), a restored field continues the render exactly,
// and the state file keeps the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "pathtracer/accumulation_state.h"
#include "pathtracer/guiding_field.h"
#include "pathtracer/integrator.h"
#include "testing/block_z_test.h"
#include "testing/learned_state_test.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

TraceParams guided_params() {
  TraceParams params;
  params.guiding = GuidingMode::On;
  params.threads = 2;
  return params;
}

// A white furnace: a white Lambertian sphere, a perfect mirror sphere and a white sphere with a
// smooth clear coat (a diffuse and a delta lobe: the mixture's delta branch) in a uniform sky of
// radiance 1. Every pixel's expectation is exactly 1; MIS weights of guiding, BSDF sampling, NEE and
// near specular chains that did not sum to 1 would move it.
Scene furnace_scene() {
  Scene scene;
  Material coated = make_diffuse(glm::vec3(1.0f));
  coated.roughness = 0.0f;
  coated.specular = 1.0f;
  scene.materials = {make_diffuse(glm::vec3(1.0f)), make_mirror(glm::vec3(1.0f)), coated};
  scene.meshes.push_back(make_sphere(glm::vec3(-0.51f, 0.3f, 0), 0.5f, 0, 64, 32));
  scene.meshes.push_back(make_sphere(glm::vec3(0.51f, 0.3f, 0), 0.5f, 1, 64, 32));
  scene.meshes.push_back(make_sphere(glm::vec3(0.0f, -0.62f, 0), 0.4f, 2, 64, 32));
  scene.environment = uniform_environment(1.0f);
  scene.camera = look_at_camera(glm::vec3(0, 0, 3.0f), glm::vec3(0), glm::vec3(0, 1, 0), 0.75f);
  return scene;
}

TEST(Guiding, WhiteFurnaceStaysOne) {
  const Scene scene = furnace_scene();
  TraceParams params = guided_params();
  params.max_vertices = 64;
  const int size = 32, frames = 128;
  ProgressiveRenderer guided(scene, params, size, size);
  for (int i = 0; i < frames; ++i) guided.add_frame();
  const Accumulation& acc = guided.accumulation();
  // Each pixel within its noise (5 standard errors, from the LV and HV Welford states) plus the
  // tessellated spheres' shading normals' 0.02 either way.
  double sum = 0, worst = 0, worst_excess = 0;
  for (size_t i = 0; i < acc.samples.size(); ++i) {
    const double y = luminance(acc.lv_mean[i] + acc.hv_mean[i]), n = acc.samples[i];
    const double sd = std::sqrt(acc.lv_lum_m2[i] / (n - 1)) + std::sqrt(acc.hv_lum_m2[i] / (n - 1));
    sum += y;
    worst = std::max(worst, std::abs(y - 1.0));
    worst_excess = std::max(worst_excess, std::abs(y - 1.0) - 5.0 * sd / std::sqrt(n));
  }
  const double mean = sum / static_cast<double>(acc.samples.size());
  std::printf("guided furnace: mean %.5f, worst pixel off by %.4f (beyond 5 se: %.4f), field %zu bytes\n", mean,
              worst, worst_excess, guided.guiding_memory_bytes());
  EXPECT_NEAR(mean, 1.0, 2e-3);
  EXPECT_LT(worst_excess, 0.03);
  // The field learned and was used: the image is not the unguided one.
  params.guiding = GuidingMode::Off;
  ProgressiveRenderer plain(scene, params, size, size);
  for (int i = 0; i < frames; ++i) plain.add_frame();
  EXPECT_FALSE(same_accumulation(acc, plain.accumulation()));
  EXPECT_GT(GuidingField::deserialize(guided.guiding_field().data(), guided.guiding_field().size()).iteration(), 5);
}

// The guiding learns what it is for. In the cornell box the heaviest-tailed light is the ceiling
// light's reflection in the mirror sphere, reaching the walls as a caustic (D S L) that BSDF
// sampling finds about once in a thousand directions, each find a firefly. After training, guided
// paths must find it at least 5x as often, with smaller weights: the parallax-aware lobes clear
// that with a wide margin. Without the photons (camera paths do not find the caustic often enough
// to learn it), or with Russian roulette on the guided throughput (it kills the guided paths and
// gives the survivors their weight back), guided paths find it about as often as unguided ones.
TEST(Guiding, TrainedFieldFindsTheMirrorCaustic) {
  const Scene scene = make_cornell_box(true);
  const int size = 128, train = 31, measure = 16;
  TraceParams params = guided_params();
  ProgressiveRenderer trainer(scene, params, size, size);
  for (int i = 0; i < train; ++i) trainer.add_frame();
  const std::vector<uint8_t> bytes = trainer.guiding_field();
  GuidingField field = GuidingField::deserialize(bytes.data(), bytes.size());
  ASSERT_TRUE(field.trained());
  auto caustic_samples = [&](bool guided) {
    PathTracer tracer(scene);
    if (guided) tracer.set_guiding(&field);
    TraceParams p = params;
    p.guiding = guided ? GuidingMode::On : GuidingMode::Off;
    p.seed = 5;
    // Guiding alone: the specular chains solve for the mirror's caustic themselves (docs/sampling.md).
    p.specular_chains = false;
    const PixelRect rect{0, 0, size, size};
    std::vector<PathSample> out(static_cast<size_t>(rect.count()));
    std::vector<HvSampleClass> classes(out.size());
    int found = 0;
    double moment = 0.0;
    // Where the HV light's second moment comes from, by the class of each sample's largest HV term
    // (docs/guiding.md, "Where the variance left is").
    double class_moment[static_cast<int>(HvClass::Count)] = {};
    for (int frame = 0; frame < measure; ++frame) {
      tracer.trace_pixels_classified(scene.camera, size, size, rect, 1000 + frame, p, out.data(), classes.data());
      for (size_t i = 0; i < out.size(); ++i) {
        const double hv = luminance(out[i].hv);
        class_moment[static_cast<int>(classes[i].dominant)] += hv * hv;
        if (classes[i].dominant == HvClass::CausticMirror) {
          ++found;
          moment += double(classes[i].dominant_luminance) * classes[i].dominant_luminance;
        }
      }
    }
    const double samples = double(out.size()) * measure;
    std::printf("%s: %d samples found the mirror caustic, their second moment %.5f per sample\n",
                guided ? "guided" : "unguided", found, moment / samples);
    for (int c = 0; c < static_cast<int>(HvClass::Count); ++c)
      if (class_moment[c] > 0.0)
        std::printf("  HV second moment per sample, %s: %.5f\n", hv_class_name(static_cast<HvClass>(c)), class_moment[c] / samples);
    return found;
  };
  const int unguided = caustic_samples(false), guided = caustic_samples(true);
  EXPECT_GT(unguided, 50);
  EXPECT_GT(guided, 5.0 * unguided);
}

// The photons say where their light seems to come from: after a flat mirror, the light's mirror
// image (found by the companion ray), not the point on the mirror, which moves with the receiver.
// A point light beside a vertical mirror over a diffuse floor; the photons that reach the floor by
// the mirror make the largest lobe of the floor's one leaf, and its source is the light's image.
TEST(Guiding, PhotonsRecordTheLightsImageInAMirror) {
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.5f)), make_mirror(glm::vec3(1.0f))};
  scene.meshes.push_back(make_quad(glm::vec3(-3, 0, -3), glm::vec3(0, 0, 6), glm::vec3(6, 0, 0), 0));
  scene.meshes.push_back(make_quad(glm::vec3(1, 0, -1), glm::vec3(0, 2, 0), glm::vec3(0, 0, 2), 1));
  PunctualLight light;
  light.position = glm::vec3(0.0f, 1.0f, 0.0f);
  light.intensity = 10.0f;
  scene.lights.push_back(light);
  scene.camera = look_at_camera(glm::vec3(0, 3, 5), glm::vec3(0), glm::vec3(0, 1, 0), 0.8f);
  PathTracer tracer(scene);
  GuidingSettings settings;
  settings.spatial_threshold = 1e9f;  // one leaf
  settings.parallax_lobes = 8;
  settings.lobe_records = 512;
  GuidingField field(glm::vec3(-3.0f, -3.0f, -3.0f), glm::vec3(3.0f, 3.0f, 3.0f), settings);
  tracer.set_guiding(&field);
  TraceParams params = guided_params();
  tracer.trace_guiding_photons(0, 40000, params);
  field.end_iteration();
  const std::vector<GuidingLobe>& lobes = field.lobes(glm::vec3(0.0f));
  ASSERT_FALSE(lobes.empty());
  const GuidingLobe& largest = *std::max_element(lobes.begin(), lobes.end(),
                                                 [](const GuidingLobe& a, const GuidingLobe& b) { return a.share < b.share; });
  const glm::vec3 image(2.0f, 1.0f, 0.0f);
  std::printf("largest lobe: share %.3f, source (%.4f %.4f %.4f), kappa %.0f\n", largest.share, largest.source.x,
              largest.source.y, largest.source.z, largest.kappa);
  EXPECT_GT(largest.distance, 0.0f);
  EXPECT_LT(glm::length(largest.source - image), 0.02f);
  EXPECT_GT(largest.kappa, 1000.0f);  // a point source: as narrow as the fit allows
}

// Unbiased: the guided cornell box (mirror and glass spheres: caustics, near specular chains) agrees
// with an unguided render of another seed, block by block and over the whole image.
TEST(Guiding, GuidedImageAgreesWithUnguidedReference) {
  const Scene scene = make_cornell_box(true);
  const int size = 32, frames = 256, block = 4;
  TraceParams params = guided_params();
  params.seed = 11;
  ProgressiveRenderer guided(scene, params, size, size);
  params.guiding = GuidingMode::Off;
  params.seed = 12;
  ProgressiveRenderer plain(scene, params, size, size);
  for (int i = 0; i < frames; ++i) {
    guided.add_frame();
    plain.add_frame();
  }
  const BlockComparison c = compare_blocks(guided.accumulation(), plain.accumulation(), block, "guided vs unguided");
  EXPECT_LT(c.worst_z, 4.5);
  EXPECT_LE(c.beyond3, 2);
  EXPECT_LT(std::abs(c.image_z), 4.0);
}

// Before the first iteration ends (frame 1) the field is untrained: the guided renderer traces the
// unguided samples, bit for bit (no guiding numbers are drawn, no pdf changes); afterwards it does not.
TEST(Guiding, UntrainedFieldTracesTheUnguidedSamples) {
  const Scene scene = make_cornell_box(true);
  TraceParams params = guided_params();
  ProgressiveRenderer guided(scene, params, 24, 20);
  params.guiding = GuidingMode::Off;
  ProgressiveRenderer plain(scene, params, 24, 20);
  guided.add_frame();
  plain.add_frame();
  EXPECT_TRUE(same_accumulation(guided.accumulation(), plain.accumulation()));
  EXPECT_EQ(guided.stats().rays, plain.stats().rays);
  EXPECT_TRUE(plain.guiding_field().empty());
  EXPECT_EQ(plain.guiding_memory_bytes(), 0u);
  guided.add_frame();
  plain.add_frame();
  EXPECT_FALSE(same_accumulation(guided.accumulation(), plain.accumulation()));
}

// The field's records are keyed and sorted, the sampling field is fixed during a frame: the image
// and the field are the same with 1 and 2 threads, also for frames that trace a mask of pixels.
TEST(Guiding, DeterministicAcrossThreadCounts) {
  TraceParams params = guided_params();
  params.seed = 77;
  expect_thread_count_independent(make_cornell_box(true), params,
                                  [](const ProgressiveRenderer& r) { return r.guiding_field(); });
}

// A render restored from its accumulation and its field after k frames continues exactly: the
// same image and field as the uninterrupted render, for a k inside an iteration and at its end.
TEST(Guiding, RestoredFieldContinuesExactly) {
  expect_resume_continues_exactly(
      make_cornell_box(true), guided_params(), 24, 20, 12, {3, 5},
      [](const ProgressiveRenderer& r) { return r.guiding_field(); },
      [](ProgressiveRenderer& r, const Accumulation& acc, int k, const std::vector<uint32_t>& traced,
         const std::vector<uint8_t>& field) { r.restore(acc, 0, k, traced, field); });
}

// GuidingMode::Auto, the default, starts guiding only where the scene sees at most half of its
// sky (the visibility field's verdict after frame 4). Under an open sky and without an environment
// it never starts, and traces Off's samples bit for bit.
TEST(Guiding, AutoStaysOffUnderAnOpenSkyAndWithoutAnEnvironment) {
  ASSERT_EQ(TraceParams{}.guiding, GuidingMode::Auto);
  for (const Scene& scene : {furnace_scene(), make_cornell_box(true)}) {
    TraceParams params;
    params.threads = 2;
    ProgressiveRenderer automatic(scene, params, 24, 20);
    params.guiding = GuidingMode::Off;
    ProgressiveRenderer off(scene, params, 24, 20);
    for (int i = 0; i < 12; ++i) {
      automatic.add_frame();
      off.add_frame();
    }
    EXPECT_FALSE(automatic.guiding_active());
    EXPECT_TRUE(automatic.guiding_field().empty());
    EXPECT_TRUE(same_accumulation(automatic.accumulation(), off.accumulation()));
  }
}

// In a room lit through a window, auto starts guiding at the verdict: the field learns from frame
// 5 on and is trained after it, so frames 1 to 5 are Off's samples and frame 6 is guided.
TEST(Guiding, AutoStartsInARoomLitThroughAWindow) {
  const Scene scene = make_room_with_window();
  TraceParams params;
  params.threads = 2;
  ProgressiveRenderer automatic(scene, params, 24, 20);
  params.guiding = GuidingMode::Off;
  ProgressiveRenderer off(scene, params, 24, 20);
  for (int frame = 1; frame <= 5; ++frame) {
    automatic.add_frame();
    off.add_frame();
    EXPECT_EQ(automatic.guiding_active(), frame >= 4) << frame;
  }
  EXPECT_TRUE(same_accumulation(automatic.accumulation(), off.accumulation()));
  automatic.add_frame();
  off.add_frame();
  EXPECT_FALSE(same_accumulation(automatic.accumulation(), off.accumulation()));
  EXPECT_FALSE(automatic.guiding_field().empty());
}

// Auto's learned state is the visibility field and the guiding field it starts: one blob for the
// shared resume and thread tests, [guiding field's length, 8 bytes][guiding field][visibility].
std::vector<uint8_t> auto_learned(const ProgressiveRenderer& r) {
  const std::vector<uint8_t> field = r.guiding_field(), visibility = r.environment_visibility();
  std::vector<uint8_t> blob(8);
  const uint64_t n = field.size();
  std::memcpy(blob.data(), &n, 8);
  blob.insert(blob.end(), field.begin(), field.end());
  blob.insert(blob.end(), visibility.begin(), visibility.end());
  return blob;
}

void restore_auto_learned(ProgressiveRenderer& r, const Accumulation& acc, int k, const std::vector<uint32_t>& traced,
                          const std::vector<uint8_t>& blob) {
  if (blob.empty()) return r.restore(acc, 0, k, traced);
  uint64_t n = 0;
  if (blob.size() < 8) throw Error("not an auto-guiding state");
  std::memcpy(&n, blob.data(), 8);
  if (n > blob.size() - 8) throw Error("not an auto-guiding state");
  const std::vector<uint8_t> field(blob.begin() + 8, blob.begin() + 8 + static_cast<ptrdiff_t>(n));
  const std::vector<uint8_t> visibility(blob.begin() + 8 + static_cast<ptrdiff_t>(n), blob.end());
  r.restore(acc, 0, k, traced, field, visibility);
}

// Auto resumes exactly before its verdict (k = 3), inside the field's first iteration (5) and later
// (7), and does not depend on the thread count.
TEST(Guiding, AutoResumesExactlyAndIsDeterministicAcrossThreadCounts) {
  TraceParams params;
  params.threads = 2;
  params.seed = 31;
  expect_resume_continues_exactly(make_room_with_window(), params, 24, 20, 12, {3, 5, 7}, auto_learned,
                                  restore_auto_learned);
  expect_thread_count_independent(make_room_with_window(), params, auto_learned);
}

// The state file keeps the guiding flag and the field; a corrupt field is refused; a merge of
// guided shards keeps no field.
TEST(Guiding, StateKeepsTheField) {
  const Scene scene = make_cornell_box(true);
  const TraceParams params = guided_params();
  const int w = 8, h = 6;
  ProgressiveRenderer r(scene, params, w, h);
  for (int i = 0; i < 4; ++i) r.add_frame();
  AccumulationState state;
  state.settings = sample_settings(0x1234, w, h, params);
  EXPECT_EQ(state.settings.guiding, 1u);
  state.frames = {FrameRange{0, 4}};
  state.acc = r.accumulation();
  state.traced = r.pixel_frames();
  state.guiding_field = r.guiding_field();
  ASSERT_FALSE(state.guiding_field.empty());
  const std::vector<uint8_t> bytes = encode_state(state);
  const AccumulationState back = decode_state(bytes.data(), bytes.size());
  EXPECT_EQ(back.settings.guiding, 1u);
  EXPECT_EQ(back.guiding_field, state.guiding_field);
  EXPECT_EQ(encode_state(back), bytes);

  SampleSettings unguided = state.settings;
  unguided.guiding = 0;
  EXPECT_EQ(state.settings.difference(unguided), "guiding on vs off");
  unguided.guiding = 2;
  EXPECT_EQ(state.settings.difference(unguided), "guiding on vs auto");

  // A corrupted byte inside the field, the checksum recomputed: refused by the field's own checks
  // (the field's header counts and indices) or accepted only as a valid field.
  std::vector<uint8_t> corrupt = bytes;
  const size_t field_start = corrupt.size() - 8 - state.guiding_field.size();
  corrupt[field_start + 4] ^= 0xff;  // in the field's header
  const uint64_t hash = fnv1a64(corrupt.data(), corrupt.size() - 8);
  std::memcpy(corrupt.data() + corrupt.size() - 8, &hash, 8);
  try {
    decode_state(corrupt.data(), corrupt.size());
    ADD_FAILURE() << "a corrupt field was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("guiding field"), std::string::npos) << e.what();
  }
  // A state without guiding cannot carry a field.
  AccumulationState wrong = state;
  wrong.settings.guiding = 0;
  EXPECT_THROW(encode_state(wrong), Error);

  // Shards: each learned its own field; the merge keeps none.
  AccumulationState second = state;
  second.frames = {FrameRange{4, 8}};
  const AccumulationState merged = merge_states({state, second});
  EXPECT_TRUE(merged.guiding_field.empty());
  const std::vector<uint8_t> merged_bytes = encode_state(merged);
  EXPECT_TRUE(decode_state(merged_bytes.data(), merged_bytes.size()).guiding_field.empty());
}

}  // namespace
}  // namespace pxf
