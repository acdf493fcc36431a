// Per-pass timings at 512x512 (run explicitly: gl_tests --gtest_also_run_disabled_tests
// --gtest_filter='*Timing*'; PXF_TIMING_FILTER=NAME,NAME,... times only those filter variants,
// PXF_TIMING_ROUNDS=N reports medians of N rounds). Not part of the default run: it takes seconds
// on llvmpipe.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>
#include "core/timing.h"
#include "gl/blend_pass.h"
#include "gl/filter_pass.h"
#include "gl/inputs.h"
#include "gl/range_pass.h"
#include "gl/test_util.h"
#include "gl/tonemap_pass.h"
#include "scene/load.h"

namespace pxf {
namespace {

TEST(Timing, DISABLED_Passes512) {
  GlContext& ctx = test::osmesa_context();
  const int w = 512, h = 512;
  std::printf("GL: %s / %s (%s)\n", ctx.gl_version().c_str(), ctx.gl_renderer().c_str(), ctx.backend_name());
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  std::vector<float> lv(w * h * 3), hv(w * h * 3), var(w * h);
  for (float& v : lv) v = 0.2f * u01(rng);
  for (float& v : hv) v = u01(rng);
  for (float& v : var) v = 0.05f * u01(rng);
  PreviewInputs inputs(w, h);
  for (int i = 0; i < 3; ++i) inputs.upload(lv.data(), hv.data(), var.data());
  std::printf("upload (lv + hv/var): %.2f ms\n", inputs.last_upload_ms());

  RangePass range(w, h);
  Scene scene;
  try {
    scene = load_scene("cornell");
  } catch (const std::exception& e) {
    std::printf("no cornell scene (%s)\n", e.what());
  }
  range.set_scene(scene);
  double range_total = 0;
  while (range.step()) range_total += range.last_ms();
  std::printf("range pass: %d frames, %.2f ms per frame, %.1f ms total (last change %g)\n", range.frames(),
              range_total / range.frames(), range_total, range.last_change());
  {
    range.invalidate();
    StageTimer raster, accumulate;
    raster.begin();
    range.begin_frame();
    raster.end();
    accumulate.begin();
    range.end_frame();
    accumulate.end();
    std::printf("  raster %.2f ms, accumulate + convergence %.2f ms\n", raster.last_ms(), accumulate.last_ms());
    GpuReduction reduction;
    StageTimer rt;
    rt.begin();
    reduction.run(range.guide(), 0);
    float sum = reduction.read_sum();
    rt.end();
    std::printf("  reduction alone %.2f ms (sum %g)\n", rt.last_ms(), sum);
  }

  FilterPass filter(w, h);
  const char* only = std::getenv("PXF_TIMING_FILTER");  // e.g. "separable,atrous" to skip the slow ones
  const char* rounds_env = std::getenv("PXF_TIMING_ROUNDS");  // median over rounds (default 1)
  const int rounds = rounds_env ? std::max(1, std::atoi(rounds_env)) : 1;
  std::vector<std::string> kinds;
  for (const std::string& name : filter_kind_names())
    if (!only || ("," + std::string(only) + ",").find("," + name + ",") != std::string::npos) kinds.push_back(name);
  // Rounds alternate the variants back to back (A B A B ...), so background load hits them alike.
  // A first untimed run of each variant compiles its shader (llvmpipe also JITs at the first draw).
  std::vector<std::vector<double>> ms(kinds.size() * 2);
  std::vector<uint32_t> filtered(kinds.size() * 2);
  for (int round = -1; round < rounds; ++round)
    for (size_t k = 0; k < kinds.size(); ++k)
      for (bool skip : {false, true}) {
        FilterParams p;
        p.kind = parse_filter_kind(kinds[k]);
        p.skip_case2 = skip;
        const float t = 0.05f;
        filter.run(inputs, range.guide(), p, t);
        if (round < 0) continue;
        ms[2 * k + skip].push_back(filter.last_ms());
        filtered[2 * k + skip] = filter.filtered_pixels();
      }
  for (size_t k = 0; k < kinds.size(); ++k)
    for (bool skip : {false, true})
      std::printf("filter %s sigma_s=8 skip=%d: %.1f ms (median of %d; %u of %d pixels filtered)\n", kinds[k].c_str(),
                  skip, median_of(ms[2 * k + skip]), rounds, filtered[2 * k + skip], w * h);
  BlendPass blend(w, h);
  TonemapPass tonemap(w, h);
  for (int i = 0; i < 3; ++i) {
    blend.run(inputs, &filter, range.guide(), 0.01f, {});
    tonemap.run(blend.output(), {});
  }
  std::printf("blend: %.2f ms\ntone map: %.2f ms\n", blend.last_ms(), tonemap.last_ms());
  StageTimer t;
  t.begin();
  Image a = blend.final_image(), b = tonemap.display_image(), c = filter.filtered_image();
  std::printf("read-back of 3 images: %.2f ms\n", t.end());
}

}  // namespace
}  // namespace pxf
