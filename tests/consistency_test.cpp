// Consistency of pixel filtering (issue 4): as spp grows, the fraction of pixels with s = 1 rises
// to 1 and the error of the filtered image to a high-spp reference falls (the bias vanishes).
#include <gtest/gtest.h>

#include "app/render_output.h"
#include "pathtracer/pathtracer.h"
#include "tests/test_support.h"

using namespace pxf;

namespace {

double fraction_unfiltered(const Image& s) {
  size_t ones = 0;
  for (float v : s.pixels) ones += v >= 1.0f ? 1 : 0;
  return static_cast<double>(ones) / s.pixels.size();
}

Image plain_reference(const Scene& scene, int w, int h, int spp) {
  TraceParams params;
  params.seed = 4242;  // independent of the preview's samples
  ProgressiveRenderer r(scene, params, w, h);
  for (int i = 0; i < spp; ++i) r.add_frame();
  return r.unfiltered_image();
}

TEST(Consistency, BlendMovesToUnfilteredAndErrorFallsAsSamplesGrow) {
  test_support::headless_context();
  const int w = 32, h = 32;
  const Scene scene = load_scene("cornell");
  const Image reference = plain_reference(scene, w, h, 4096);
  PreviewSettings settings;
  settings.threshold = 0.1f;  // sqrt(t) ~ 30 % relative noise: reachable within the test's budget
  Preview preview(scene, settings, w, h);
  // The antialiased guide of a long render. At 32x32 the tracing time is so short that the range
  // frames the pass budget allows (Preview::advance_range_buffer) would leave it at one frame.
  preview.converge_range_buffer();

  std::vector<double> fractions, errors, bias;
  const std::vector<int> checkpoints = {2, 8, 32, 128, 512, 2048};
  for (int spp = 1, next = 0; spp <= checkpoints.back(); ++spp) {
    const bool checkpoint = spp == checkpoints[next];
    preview.add_frame(checkpoint, false);
    if (!checkpoint) continue;
    ++next;
    const std::vector<Layer> buffers = preview.buffers();
    fractions.push_back(fraction_unfiltered(layer_image(buffers, "blend")));
    errors.push_back(compare_images(layer_image(buffers, "final"), reference).nrmse_percent);
    bias.push_back(compare_images(layer_image(buffers, "final"), unfiltered_image(buffers)).nrmse_percent);
    std::printf("spp %5d: s=1 on %.3f of pixels, NRMSE %.3f %%, final vs unfiltered %.3f %%\n", spp,
                fractions.back(), errors.back(), bias.back());
  }
  // Rises towards 1, up to the noise of the variance estimates: at a few dozen samples, pixels
  // near the caustic that have not sampled it yet look quiet, so the fraction dips between 32 and
  // 128 spp before it rises again (seen on this 32x32 image: 0.92 at 32 spp, 0.83 at 128, 0.98 at
  // 2048). The dip belongs to the method, not to the sampler: over seeds 1-16, 32 -> 128 spp, it
  // is 0.093 +- 0.027 (max 0.130) with independent samples and 0.079 +- 0.027 (max 0.124) with
  // Sobol. The last few percent are caustic pixels whose relative variance needs far more samples
  // than a test can afford.
  for (size_t i = 1; i < fractions.size(); ++i) EXPECT_GE(fractions[i], fractions[i - 1] - 0.15) << i;
  EXPECT_GE(fractions.back(), 0.95);
  EXPECT_LT(fractions.front(), fractions.back() - 0.15);
  // The error falls from the first to the last checkpoint, and the filtered image converges to the
  // unfiltered one (no bias left).
  EXPECT_LT(errors.back(), 0.5 * errors.front());
  EXPECT_LT(errors[3], errors[0]);
  EXPECT_LT(bias.back(), 0.25 * bias.front());
}

}  // namespace

