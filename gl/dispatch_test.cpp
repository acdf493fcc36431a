// Dispatch layout and limit checks (gl/dispatch.h) with mock limits, and the grid filter on a real
// context at a size whose blur pass needs more than 65,535 work groups in one row.
#include "gl/dispatch.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "gl/filter_pass.h"
#include "gl/grid_layout.h"
#include "gl/grid_reference.h"
#include "gl/inputs.h"
#include "gl/test_util.h"

namespace pxf {
namespace {

GlLimits limits_of(uint32_t max_x, uint32_t max_y) {
  GlLimits limits;
  limits.max_work_groups[0] = max_x;
  limits.max_work_groups[1] = max_y;
  return limits;
}

TEST(WorkGroupGrid, OneRowWhileTheGroupsFitTheXLimit) {
  const WorkGroupGrid grid = work_group_grid(65535, limits_of(65535, 65535));
  EXPECT_EQ(grid.x, 65535u);
  EXPECT_EQ(grid.y, 1u);
}

TEST(WorkGroupGrid, RowsOfTheXLimitCoverEveryGroupBeyondIt) {
  // 100,500 groups: the blur of the grid filter at 4000x4000 with the default sigma_s.
  const GlLimits limits = limits_of(65535, 65535);
  const WorkGroupGrid grid = work_group_grid(100500, limits);
  EXPECT_EQ(grid.x, 65535u);
  EXPECT_EQ(grid.y, 2u);
  EXPECT_GE(grid.count(), 100500u);
  EXPECT_LT(grid.count() - 100500u, grid.x);  // less than one row left over
  EXPECT_NO_THROW(check_work_groups("test", grid.x, grid.y, 1, limits));
}

TEST(WorkGroupGrid, MockLimitSplitsSmallCounts) {
  const WorkGroupGrid grid = work_group_grid(10, limits_of(4, 3));
  EXPECT_EQ(grid.x, 4u);
  EXPECT_EQ(grid.y, 3u);
  EXPECT_THROW(work_group_grid(13, limits_of(4, 3)), Error);
  EXPECT_EQ(work_group_grid(0, limits_of(4, 3)).count(), 0u);
}

TEST(GlLimitChecks, RefuseWhatTheContextCannotDoWithOneLine) {
  GlLimits limits = limits_of(65535, 65535);
  limits.max_texture_size = 16384;
  EXPECT_NO_THROW(check_texture_size("texture", 16384, 16384, limits));
  EXPECT_THROW(check_texture_size("texture", 16385, 1, limits), Error);
  EXPECT_THROW(check_work_groups("pass", 65536, 1, 1, limits), Error);
  try {
    check_texture_size("texture", 20000, 10, limits);
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos);
    EXPECT_NE(message.find("20000x10"), std::string::npos);
  }
}

TEST(GlLimits, QueriedFromTheContext) {
  test::osmesa_context();
  const GlLimits limits = query_gl_limits();
  EXPECT_GE(limits.max_work_groups[1], 65535u);
  EXPECT_GE(limits.max_work_groups[0], 65535u);  // the least GL 4.3 allows
  EXPECT_GE(limits.max_texture_size, 16384);     // GL 4.5
}

// A hostile case: 16384x100 at sigma_s 0.1 makes a grid of 4097 x 26 x 40 cells, whose blur
// needs 66,578 groups of 64: more than one row of 65,535 (GL_INVALID_VALUE before the 2D layout).
// The guide's luminance ramps along x over [0, 1], so that the cells past the first row (the top
// range cells: the layout is z-major) hold pixels, and the pass must match the CPU reference there.
TEST(GridFilterDispatch, BlurOverMoreThan65535GroupsMatchesTheReference) {
  test::osmesa_context();
  constexpr int W = 16384, H = 100;
  FilterParams p;
  p.kind = FilterKind::Grid;
  p.sigma_s = 0.1f;
  p.skip_case2 = false;
  ASSERT_GT((grid_layout(W, H, p).cells() + 63) / 64, 65535u);
  Image hv = Image::rgb(W, H), var = Image::gray(W, H, "Y", 0.01f), lv = Image::rgb(W, H);
  Image range = Image::rgb(W, H), depth = Image::gray(W, H, "Y", 3.0f), guide = Image::rgba(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const float luminance = float(x) / (W - 1);
      for (int c = 0; c < 3; ++c) {
        hv.at(x, y, c) = 0.5f + 0.25f * float((x * 7 + y * 13) % 5);
        range.at(x, y, c) = guide.at(x, y, c) = luminance;
      }
      guide.at(x, y, 3) = 3.0f;
    }
  PreviewInputs inputs(W, H);
  inputs.upload(lv, hv, var);
  Texture2D guide_texture(W, H, TextureFormat::RGBA32F);
  guide_texture.upload(guide);
  FilterPass filter(W, H);
  ASSERT_NO_THROW(filter.run(inputs, guide_texture, p, test::kTestThreshold));
  const FilterOutput reference = cpu_grid_filter(hv, var, lv, range, depth, p, test::kTestThreshold);
  const Image gpu = filter.filtered_image();
  size_t bad = 0;
  for (size_t i = 0; i < gpu.pixels.size(); ++i) {
    const float a = gpu.pixels[i], b = reference.filtered.pixels[i];
    if (!(std::abs(a - b) <= 1e-4f * std::max(std::abs(a), std::abs(b)) + 1e-6f) && bad++ < 5)
      ADD_FAILURE() << "sample " << i << " (x " << (i / 3) % W << "): gpu " << a << " cpu " << b;
  }
  EXPECT_EQ(bad, 0u);
}

}  // namespace
}  // namespace pxf
