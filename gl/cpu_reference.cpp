#include "gl/cpu_reference.h"

#include <algorithm>
#include <cmath>
#include "gl/grid_reference.h"

namespace pxf {

namespace {

struct Px {
  float c[3];
};
Px rgb_at(const Image& im, int x, int y) {
  return {{clean(im.at(x, y, 0)), clean(im.at(x, y, 1)), clean(im.at(x, y, 2))}};
}

// Images as the shared code reads textures (shaders/cpu_gpu.h): texel p is the first three
// channels of `rgb` and the first channel of `a`, as the GL passes pack L_u with Var[L_u] and the
// range color with the distance. Without `a`, the alpha is the fourth channel of `rgb` where it has
// one, else 0; L_lv's texel reads 1 there instead (lv_view), as the GL texture does, whose alpha is
// the pixel's threshold factor (shared::pixel_threshold).
struct TexelView {
  const Image* rgb = nullptr;
  const Image* a = nullptr;
  float a_default = 0.0f;
};
TexelView lv_view(const Image& lv) { return TexelView{&lv, nullptr, 1.0f}; }
glm::vec4 texelFetch(const TexelView& t, glm::ivec2 p, int) {
  glm::vec4 v(0.0f, 0.0f, 0.0f, t.a_default);
  if (t.rgb) {  // the channels it has (a two-channel image reads (x, y, 0, a_default), as an RG texture)
    const int channels = std::min(t.rgb->num_channels(), 4);
    for (int c = 0; c < channels; ++c) v[c] = t.rgb->at(p.x, p.y, c);
  }
  if (t.a) v.a = t.a->at(p.x, p.y, 0);
  return v;
}
glm::ivec2 textureSize(const TexelView& t, int) {
  const Image& im = t.a ? *t.a : *t.rgb;
  return {im.width, im.height};
}

// The surface buffer (xyz shading normal, w roughness) as the shaders read it; none: every texel 0,
// an unknown normal, which leaves the surface term out.
TexelView surface_view(const Image* surface) { return TexelView{surface, nullptr, 0.0f}; }

// The exponent of the range weight between pixels p and q (color, depth and surface terms).
double range_exponent(const Image& range_color, const Image& depth, const Image* surface, int px, int py, int qx,
                      int qy, const RangeWeights& range) {
  const TexelView guide{&range_color, &depth};
  const TexelView s = surface_view(surface);
  return shared::range_exponent(texelFetch(guide, {px, py}, 0), texelFetch(guide, {qx, qy}, 0),
                                texelFetch(s, {px, py}, 0), texelFetch(s, {qx, qy}, 0), range.k_c, range.k_d,
                                range.k_n, range.k_r);
}

// One pixel's kernel sums (shared::KernelSums, in double here), accumulated from images.
struct KernelSums {
  shared::KernelSums sums = shared::kernel_sums_zero();

  void add(double w, const Image& signal, const Image& signal_var, int qx, int qy) {
    const Px l = rgb_at(signal, qx, qy);
    shared::kernel_sums_add(sums, w, glm::vec3(l.c[0], l.c[1], l.c[2]), clean_var(signal_var.at(qx, qy, 0)));
  }
  void write(FilterOutput& out, int x, int y, float variance_factor = 1.0f) const {
    const glm::vec3 mean = shared::kernel_sums_mean(sums);
    for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = mean[c];
    out.variance.at(x, y, 0) = shared::kernel_sums_variance(sums, variance_factor);
    if (!out.centre_weight.pixels.empty()) out.centre_weight.at(x, y, 0) = static_cast<float>(1.0 / sums.w);
  }
};

}  // namespace

bool case2_skip_decision(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                         const Image& depth, const FilterParams& p, float t, int x, int y, const Image* surface,
                         const Image* half_variances) {
  const RangeWeights range = range_weights(p);
  return shared::skip_pixel(filter_skip_mode(p, half_variances != nullptr), TexelView{&hv, &var_u}, lv_view(lv),
                            TexelView{&range_color, &depth}, surface_view(surface), TexelView{half_variances},
                            glm::ivec2(x, y), range.k_c, range.k_d, range.k_n, range.k_r, t);
}

bool skip_as_case2(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                   const Image& depth, const FilterParams& p, float t, int x, int y, FilterOutput& out,
                   const Image* surface, const Image* half_variances) {
  if (!case2_skip_decision(hv, var_u, lv, range_color, depth, p, t, x, y, surface, half_variances)) return false;
  const Px lu = rgb_at(hv, x, y);
  for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = lu.c[c];
  out.variance.at(x, y, 0) = kVarSkipped;
  return true;
}

float pooled_var_u(const Image& var_u, const Image& range_color, const Image& depth, int x, int y,
                   const RangeWeights& range, const Image* surface) {
  return shared::pooled_var_u(TexelView{nullptr, &var_u}, TexelView{&range_color, &depth}, surface_view(surface),
                              glm::ivec2(x, y), range.k_c, range.k_d, range.k_n, range.k_r);
}

BlendDecision blend_decision(float u, float f, float t) {
  BlendDecision d;
  d.s = shared::blend_factor(u, f, t, d.blend_case);
  return d;
}

BlendDecision blend_decision(float u, float f, float t, float w) {
  BlendDecision d;
  d.s = shared::blend_factor_covariance(u, f, t, w, d.blend_case);
  return d;
}

namespace {

// One bilateral pass over `signal` (rgb) with variance `signal_var`, kernel extent (ex, ey) times
// the radius; skipping (final pass only) looks at the unfiltered hv / var_u.
FilterOutput filter_once(const Image& signal, const Image& signal_var, const Image& hv, const Image& var_u,
                         const Image& lv, const Image& range_color, const Image& depth, const Image* surface,
                         const FilterParams& p, float t, int ex, int ey, bool final_pass,
                         const Image* half_variances) {
  const int w = hv.width, h = hv.height;
  FilterOutput out{Image::rgb(w, h), Image::gray(w, h), Image::gray(w, h, "Y", 1.0f)};
  const int radius = std::min(kMaxFilterRadius, static_cast<int>(std::ceil(3.0f * std::max(p.sigma_s, 0.0f))));
  const float ks = inv_two_sigma2(p.sigma_s);
  const RangeWeights range = range_weights(p);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (final_pass && p.skip_case2 &&
          skip_as_case2(hv, var_u, lv, range_color, depth, p, t, x, y, out, surface, half_variances))
        continue;
      KernelSums sums;
      for (int qy = std::max(0, y - radius * ey); qy <= std::min(h - 1, y + radius * ey); ++qy)
        for (int qx = std::max(0, x - radius * ex); qx <= std::min(w - 1, x + radius * ex); ++qx) {
          double e = double((qx - x) * (qx - x) + (qy - y) * (qy - y)) * ks +
                     range_exponent(range_color, depth, surface, x, y, qx, qy, range);
          sums.add(std::exp(-e), signal, signal_var, qx, qy);
        }
      sums.write(out, x, y);
    }
  return out;
}

// ---- Edge-avoiding à-trous (FilterKind::Atrous) ----

// One à-trous pass over `signal` (rgb) with variance `signal_var`: the 5x5 taps at hole spacing
// `step`, weighted by h x the range weights (color, depth), taps outside the image left out (the
// sums are normalized). Skipping (final pass only) looks at the unfiltered hv / var_u.
FilterOutput atrous_pass(const Image& signal, const Image& signal_var, const Image& hv, const Image& var_u,
                         const Image& lv, const Image& range_color, const Image& depth, const Image* surface,
                         const FilterParams& p, float t, int step, float variance_factor, bool final_pass,
                         const Image* half_variances) {
  const int w = hv.width, h = hv.height;
  FilterOutput out{Image::rgb(w, h), Image::gray(w, h), Image{}};
  const RangeWeights range = range_weights(p);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (depth.at(x, y, 0) >= shared::kBackgroundOnlyDistance) {  // as it is (kBackgroundOnlyDistance)
        const Px own = rgb_at(signal, x, y);
        for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = own.c[c];
        out.variance.at(x, y, 0) = final_pass ? kVarSkipped : signal_var.at(x, y, 0);
        continue;
      }
      if (final_pass && p.skip_case2 &&
          skip_as_case2(hv, var_u, lv, range_color, depth, p, t, x, y, out, surface, half_variances))
        continue;
      KernelSums sums;
      double h_sum = 0;
      const float var_p = atrous_k_l(p) > 0.0f ? shared::edge_stop_variance(TexelView{&signal, &signal_var}, glm::ivec2(x, y))
                                                : kVarUnknown;
      const Px l_p = rgb_at(signal, x, y);
      for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i) {
          const int qx = x + (i - 2) * step, qy = y + (j - 2) * step;
          if (qx < 0 || qx >= w || qy < 0 || qy >= h) continue;
          const Px l_q = rgb_at(signal, qx, qy);
          const double edge = shared::luminance_edge_exponent(glm::vec3(l_p.c[0], l_p.c[1], l_p.c[2]),
                                                              glm::vec3(l_q.c[0], l_q.c[1], l_q.c[2]),
                                                              var_p, atrous_k_l(p));
          const double range_weight = std::exp(-range_exponent(range_color, depth, surface, x, y, qx, qy, range) - edge);
          h_sum += double(shared::kB3[i]) * shared::kB3[j];
          sums.add(double(shared::kB3[i]) * shared::kB3[j] * range_weight, signal, signal_var, qx, qy);
        }
      // sum w >= h(0,0) = 0.14: the center tap has range weight 1.
      sums.write(out, x, y, shared::atrous_local_correction(variance_factor, float(sums.sums.w / h_sum)));
    }
  return out;
}

// atrous_iterations(sigma_s) passes at spacing 1, 2, 4, ...; each pass is a linear filter of the
// previous pass's output. Its Var[L_f] is propagated as if that output's pixels were independent
// and then multiplied by atrous_variance_correction(pass), which makes it exact where all range
// weights are 1 (Atrous.WhiteNoiseVarianceShrinksBySumOfSquaredWeights in gl/passes_test.cpp),
// scaled per pixel by the share of the kernel its range weights keep (atrous_local_correction).
FilterOutput cpu_atrous(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                        const Image& depth, const Image* surface, const FilterParams& p, float t,
                        const Image* half_variances) {
  const int passes = atrous_iterations(p.sigma_s);
  FilterOutput level{hv, var_u, Image{}};
  for (int i = 0; i < passes; ++i)
    level = atrous_pass(level.filtered, level.variance, hv, var_u, lv, range_color, depth, surface, p, t, 1 << i,
                        atrous_variance_correction(i), i + 1 == passes, half_variances);
  return level;
}

// ---- Subsampled (FilterKind::Subsampled) ----

// The bilateral-depth kernel at the pixel's rotation of the tap table only: each tap weighted by
// its count x the range weights (the spatial weight is in the tap density), taps outside the image
// left out. Mirrors shaders/subsampled.frag.
FilterOutput cpu_subsampled(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                            const Image& depth, const Image* surface, const FilterParams& p, float t,
                            const Image* half_variances) {
  const int w = hv.width, h = hv.height;
  FilterOutput out{Image::rgb(w, h), Image::gray(w, h), Image{}};
  const RangeWeights range = range_weights(p);
  const SubsampledTapTable table = subsampled_tap_table(p.sigma_s, p.subsampled_taps > 0 ? p.subsampled_taps : kSubsampledTaps);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (p.skip_case2 && skip_as_case2(hv, var_u, lv, range_color, depth, p, t, x, y, out, surface, half_variances))
        continue;
      KernelSums sums;
      const SubsampledTap* taps = &table.taps[static_cast<size_t>(subsampled_rotation(x, y)) * table.per_rotation];
      for (int i = 0; i < table.per_rotation && taps[i].count > 0; ++i) {
        const int qx = x + taps[i].dx, qy = y + taps[i].dy;
        if (qx < 0 || qx >= w || qy < 0 || qy >= h) continue;
        const double weight = taps[i].count * std::exp(-range_exponent(range_color, depth, surface, x, y, qx, qy, range));
        sums.add(weight, hv, var_u, qx, qy);
      }
      sums.write(out, x, y);  // sum w >= 1: the centre tap is in every rotation
    }
  return out;
}

}  // namespace

FilterOutput cpu_filter(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                        const Image& depth, const FilterParams& p, float t, const Image* surface,
                        const Image* half_variances) {
  if (p.kind == FilterKind::None) throw Error("cpu_filter: filter kind none");
  if (p.kind == FilterKind::Atrous) return cpu_atrous(hv, var_u, lv, range_color, depth, surface, p, t, half_variances);
  if (p.kind == FilterKind::Subsampled)
    return cpu_subsampled(hv, var_u, lv, range_color, depth, surface, p, t, half_variances);
  if (p.kind == FilterKind::Grid)
    return cpu_grid_filter(hv, var_u, lv, range_color, depth, p, t, surface, half_variances);
  if (p.kind != FilterKind::Separable)
    return filter_once(hv, var_u, hv, var_u, lv, range_color, depth, surface, p, t, 1, 1, true, half_variances);
  FilterOutput rows = filter_once(hv, var_u, hv, var_u, lv, range_color, depth, surface, p, t, 1, 0, false, nullptr);
  FilterOutput out = filter_once(rows.filtered, rows.variance, hv, var_u, lv, range_color, depth, surface, p, t, 0,
                                 1, true, half_variances);
  out.centre_weight = Image();  // the second pass's centre weight alone would understate it: none
  return out;
}

namespace {

// The guard's finding at p, (b2, var_u) of each half (the even half's pixel window judged on the odd
// half, and the other way round), or the one finding twice, by the definition of its windows.
glm::vec4 guard_findings(const TexelView& hv, const TexelView& filtered, glm::ivec2 p, const BlendHalves& halves) {
  if (!halves.halves) {
    const shared::BiasGuardEstimate e =
        shared::bias_guard_estimate_at(hv, filtered, p, shared::bias_guard_texel(hv, filtered, p));
    return {e.b2, e.var_u, e.b2, e.var_u};
  }
  const glm::vec4 u = texelFetch(hv, p, 0), f = texelFetch(filtered, p, 0);
  const glm::vec4 h = texelFetch(TexelView{halves.halves}, p, 0);
  const glm::vec2 v(texelFetch(TexelView{halves.variances}, p, 0));
  auto finding = [&](int which) {  // half `which`'s finding, the other half read at the pixel
    const glm::vec4 other = shared::bias_guard_texel_of(shared::half_texel(u, h, v, 1 - which), f);
    const shared::BiasGuardEstimate e = shared::bias_guard_estimate_at(hv, filtered, p, other);
    return glm::vec2(e.b2, e.var_u);
  };
  return {finding(0), finding(1)};
}

}  // namespace

// shared::blend_pixel (or blend_pixel_split) on the images; the guard's finding by the definition
// of its windows.
BlendOutput cpu_blend(const Image& lv, const Image& hv, const Image& var_u, const FilterOutput* filtered, float t,
                      const BlendParams& params, const Image* range_color, const Image* depth, const Image* surface,
                      BlendHalves halves) {
  const bool pool = range_color && depth;
  if (!params.split || !halves.variances) halves.halves = nullptr;
  const int w = hv.width, h = hv.height;
  BlendOutput out{Image::rgb(w, h), Image::gray(w, h), Image::gray(w, h)};
  const TexelView hv_texels{&hv, &var_u};
  const TexelView filtered_texels = filtered ? TexelView{&filtered->filtered, &filtered->variance} : hv_texels;
  const shared::BlendSwitches on{filtered != nullptr, pool, params.bias_guard, t, params.samples};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::ivec2 p(x, y);
      const shared::BlendTexels px{texelFetch(hv_texels, p, 0), texelFetch(lv_view(lv), p, 0),
                                   texelFetch(filtered_texels, p, 0), pool ? depth->at(x, y, 0) : 0.0f};
      shared::PooledNeighbours pooled{0.0, 0.0, 0.0};
      glm::vec4 guard(0.0f);
      float centre_weight = 0.0f;
      if (shared::blend_compares_variances(px, on)) {
        if (pool)
          pooled = shared::pooled_neighbours(hv_texels, TexelView{range_color, depth}, surface_view(surface), p,
                                             params.range.k_c, params.range.k_d, params.range.k_n, params.range.k_r);
        if (!filtered->centre_weight.pixels.empty()) centre_weight = filtered->centre_weight.at(x, y, 0);
        if (params.bias_guard) guard = guard_findings(hv_texels, filtered_texels, p, halves);
      }
      auto inputs = [&](const shared::BlendTexels& decided, glm::vec2 finding) {
        return shared::blend_variance_inputs(decided, on, pooled, centre_weight, finding);
      };
      shared::BlendPixel b;
      if (halves.halves) {
        const glm::vec4 hl = texelFetch(TexelView{halves.halves}, p, 0);
        const glm::vec2 hv2(texelFetch(TexelView{halves.variances}, p, 0));
        b = shared::blend_pixel_split(px, hl, hv2, on, inputs(shared::decision_texels(px, hv2, 0), {guard.x, guard.y}),
                                      inputs(shared::decision_texels(px, hv2, 1), {guard.z, guard.w}));
      } else {
        b = shared::blend_pixel(px, on, inputs(px, {guard.x, guard.y}));
      }
      for (int c = 0; c < 3; ++c) out.final_rgb.at(x, y, c) = b.radiance[c];
      out.s.at(x, y, 0) = b.s;
      out.blend_case.at(x, y, 0) = static_cast<float>(b.blend_case);
    }
  return out;
}

DemodulatedInputs cpu_demodulate(const Image& hv, const Image& var_u, const Image& lv, const Image& albedo,
                                 const Image& range_color, const Image& depth, const FilterParams& p, float t,
                                 const Image* surface, const Image* half_variances) {
  const int w = hv.width, h = hv.height;
  DemodulatedInputs out{Image::rgb(w, h), Image::gray(w, h), Image::rgb(w, h)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec4 d = shared::demodulated_texel(TexelView{&hv, &var_u}, TexelView{&albedo}, glm::ivec2(x, y));
      for (int c = 0; c < 3; ++c) out.hv.at(x, y, c) = d[c];
      out.var_u.at(x, y, 0) = d.a;
      const bool skip =
          p.skip_case2 && case2_skip_decision(hv, var_u, lv, range_color, depth, p, t, x, y, surface, half_variances);
      for (int c = 0; c < 3; ++c) out.lv.at(x, y, c) = skip ? kMaxInput : -kMaxInput;
    }
  return out;
}

FilterOutput cpu_remodulate(const FilterOutput& filtered, const Image& albedo) {
  FilterOutput out = filtered;
  for (int y = 0; y < albedo.height; ++y)
    for (int x = 0; x < albedo.width; ++x) {
      const glm::vec4 f = texelFetch(TexelView{&filtered.filtered, &filtered.variance}, glm::ivec2(x, y), 0);
      const glm::vec4 r = shared::remodulated_texel(f, glm::vec3(albedo.at(x, y, 0), albedo.at(x, y, 1), albedo.at(x, y, 2)));
      for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = r[c];
      out.variance.at(x, y, 0) = r.a;
    }
  return out;
}

double cpu_log_average(const Image& rgb, float delta) { return log_average_luminance(rgb, delta); }

Image cpu_tonemap(const Image& rgb, const TonemapParams& p) { return tonemap_reinhard(rgb, p); }

}  // namespace pxf
