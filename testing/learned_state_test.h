// A render that learns as it goes (path guiding, light through openings) does not depend on the
// thread count and resumes exactly: shared by the tests of each learned state. Header-only: its users link the path tracer, which pxf_testing
// does not.
#pragma once
#include <initializer_list>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "pathtracer/pathtracer.h"
#include "testing/same_bits.h"

namespace pxf {

// The accumulations hold the same samples, bit for bit (the even halves too, where they are kept).
inline bool same_accumulation(const Accumulation& a, const Accumulation& b) {
  return a.samples == b.samples && same_bits(a.lv_mean, b.lv_mean) && same_bits(a.hv_mean, b.hv_mean) &&
         same_bits(a.hv_lum_m2, b.hv_lum_m2) && same_bits(a.lv_lum_m2, b.lv_lum_m2) &&
         a.even_samples == b.even_samples && same_bits(a.even_hv_mean, b.even_hv_mean) &&
         same_bits(a.even_lum_m2, b.even_lum_m2);
}

// A render restored after k frames (each of `ks`) from its accumulation and the learned state
// `learned(renderer)` gives continues exactly: the same image and learned state as the
// uninterrupted render of `frames` frames. Restored without that state (an empty one) it learns
// anew and traces other samples; a state that is not one is refused. `restore(renderer, acc, k,
// traced, state)` hands the state to the renderer.
template <class Learned, class Restore>
void expect_resume_continues_exactly(const Scene& scene, const TraceParams& params, int w, int h, int frames,
                                     std::initializer_list<int> ks, Learned learned, Restore restore) {
  ProgressiveRenderer whole(scene, params, w, h);
  for (int i = 0; i < frames; ++i) whole.add_frame();
  for (int k : ks) {
    SCOPED_TRACE(k);
    ProgressiveRenderer first(scene, params, w, h);
    for (int i = 0; i < k; ++i) first.add_frame();
    ProgressiveRenderer resumed(scene, params, w, h);
    restore(resumed, first.accumulation(), k, first.pixel_frames(), learned(first));
    for (int i = k; i < frames; ++i) resumed.add_frame();
    EXPECT_TRUE(same_accumulation(resumed.accumulation(), whole.accumulation()));
    EXPECT_EQ(learned(resumed), learned(whole));
  }
  ProgressiveRenderer first(scene, params, w, h);
  for (int i = 0; i < 5; ++i) first.add_frame();
  ProgressiveRenderer fresh(scene, params, w, h);
  restore(fresh, first.accumulation(), 5, first.pixel_frames(), std::vector<uint8_t>{});
  for (int i = 5; i < frames; ++i) fresh.add_frame();
  EXPECT_FALSE(same_accumulation(fresh.accumulation(), whole.accumulation()));
  ProgressiveRenderer broken(scene, params, w, h);
  EXPECT_THROW(restore(broken, first.accumulation(), 5, first.pixel_frames(), std::vector<uint8_t>{1, 2, 3}), Error);
}

// The image and the learned state `learned(renderer)` are the same with 1 and 2 threads, over 9
// frames of which every 4th traces a mask of two pixels in three.
template <class Learned>
void expect_thread_count_independent(const Scene& scene, TraceParams params, Learned learned) {
  params.threads = 1;
  ProgressiveRenderer one(scene, params, 40, 30);
  params.threads = 2;
  ProgressiveRenderer two(scene, params, 40, 30);
  std::vector<uint8_t> mask(40 * 30);
  for (size_t p = 0; p < mask.size(); ++p) mask[p] = (p % 3) != 0;
  const std::vector<uint8_t> all(mask.size(), 1);
  for (int i = 0; i < 9; ++i) {
    one.add_frame(i % 4 == 3 ? mask : all);
    two.add_frame(i % 4 == 3 ? mask : all);
  }
  EXPECT_TRUE(same_accumulation(one.accumulation(), two.accumulation()));
  EXPECT_EQ(one.stats().rays, two.stats().rays);
  EXPECT_EQ(learned(one), learned(two));
}

}  // namespace pxf
