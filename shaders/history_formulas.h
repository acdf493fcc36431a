// The reprojected history of a moving camera (docs/method.md section 4.1): where a pixel of the
// new view was seen in the previous one, whether it is still the same surface there, and how much
// the previous estimate may count beside the fresh samples. Computed by history_reproject.frag and
// history_combine.frag and by the CPU reference (gl/history_reference.cpp): one source, valid GLSL
// and C++ (shaders/cpu_gpu.h).
#include "pass_formulas.h"

PXF_SHARED_BEGIN

// ---- Constants ----

// The history counts as at most this many samples (an exponential moving average of about this
// length while the camera keeps moving), so that the lag and the blur of repeated resampling stay
// short. Beyond a few samples a longer history barely lowers the error or the flicker of a moving
// camera (pxf bench motion), while it keeps a wrongly kept history longer.
PXF_CONST float kHistoryMaxCount = 8.0f;
// The history's weight falls linearly to 0 over this many fresh samples: from then on the pixel is
// the unbiased mean of its fresh samples, exactly as if the camera had never moved.
PXF_CONST float kHistoryFadeSamples = 16.0f;
// A reprojected tap is the same surface if its guide distance is within this share of the one the
// new view expects there ...
PXF_CONST float kHistoryDepthTolerance = 0.05f;
// ... and its range color within this absolute plus relative difference per channel (the range
// color's shading term changes with the viewing direction; 0.8 of the albedo over a full turn).
PXF_CONST float kHistoryColorTolerance = 0.05f;
PXF_CONST float kHistoryColorRelTolerance = 0.25f;
// ... and the surface normals the two guides' distances give, each turned towards its own camera,
// at most about 37 degrees apart (a thin wall seen from its other side agrees in distance and,
// near grazing, in range color: only its facing tells).
PXF_CONST float kHistoryNormalAgreement = 0.8f;
// A pixel with a neighbour more than this share of its distance nearer or farther is on a
// silhouette: no normal, and it neither gives nor takes history. Its samples mix the surfaces on
// both sides (the path tracer's pixel footprint); reprojected as the surface of its center they
// smear a mirror sphere's reflections along the wall beside it while the camera orbits.
PXF_CONST float kHistoryEdgeDepthJump = 0.2f;

// Texture units of the history passes (beyond the pass shaders' kUnit* of pass_formulas.h).
PXF_CONST int kUnitHistoryLv = 10;     // rgb L_lv, a the sample count it holds
PXF_CONST int kUnitHistoryHv = 11;     // rgb L_u, a Var[L_u]
PXF_CONST int kUnitHistoryGuide = 12;  // the previous view's guide (rgb range color, a distance)
PXF_CONST int kUnitHistoryNormals = 13;  // the previous view's guide_normal per pixel
PXF_CONST int kUnitNormals = 14;         // the new view's guide_normal per pixel

// What the reprojection found per pixel (the "history" view of the explorer).
PXF_CONST int kHistoryNone = 0;        // no history (the camera did not move, or no previous samples)
PXF_CONST int kHistoryKept = 1;        // reprojected
PXF_CONST int kHistoryDisoccluded = 2; // seen in the previous view, but another surface was there
PXF_CONST int kHistoryOutside = 3;     // outside the previous view (or behind its camera)

// ---- Cameras ----

// A camera as camera_ray (scene/camera.cpp) uses it: origin, rotation (camera to world),
// tan(yfov / 2) or ymag, the image aspect and size in pixels.
struct ViewCamera {
  vec3 origin;
  mat3 basis;
  float half_height;
  float aspect;
  vec2 size;
  bool orthographic;
};

// The point at guide distance `distance` along the ray through image position `pixel` (pixels, (0,0)
// the top-left corner): the surface the range buffer saw there. The same ray as camera_ray.
PXF_INLINE vec3 view_point(ViewCamera c, vec2 pixel, float distance) {
  float ndc_x = 2.0f * pixel.x / c.size.x - 1.0f;
  float ndc_y = 1.0f - 2.0f * pixel.y / c.size.y;
  vec3 on_plane = vec3(ndc_x * c.half_height * c.aspect, ndc_y * c.half_height, 0.0f);
  if (c.orthographic) return c.origin + c.basis * on_plane + normalize(c.basis * vec3(0.0f, 0.0f, -1.0f)) * distance;
  return c.origin + normalize(c.basis * (on_plane + vec3(0.0f, 0.0f, -1.0f))) * distance;
}

// The inverse: the image position of point x in camera c and the guide distance it would have
// there (to the eye; from the camera plane for an orthographic camera). False behind the camera.
PXF_INLINE bool view_project(ViewCamera c, vec3 x, PXF_OUT(vec2) pixel, PXF_OUT(float) distance) {
  vec3 local = transpose(c.basis) * (x - c.origin);  // the basis is a rotation
  float depth = -local.z;
  pixel = vec2(-1.0f);
  distance = 0.0f;
  if (!(depth > 1.0e-6f)) return false;
  vec2 plane = c.orthographic ? vec2(local.x, local.y) : vec2(local.x, local.y) / depth;
  distance = c.orthographic ? depth : length(x - c.origin);
  float ndc_x = plane.x / (c.half_height * c.aspect);
  float ndc_y = plane.y / c.half_height;
  pixel = vec2((ndc_x + 1.0f) * 0.5f * c.size.x, (1.0f - ndc_y) * 0.5f * c.size.y);
  return true;
}

// ---- Reprojection ----

// The step from pixel p's surface point to its neighbour's along `axis`, towards +axis; vec3(0)
// where a neighbour on either side jumps by more than kHistoryEdgeDepthJump (a silhouette) or
// there is no neighbour.
PXF_SAMPLER_FN vec3 guide_step(sampler2D guide, ivec2 p, ivec2 axis, ViewCamera c, vec3 point, float d) {
  ivec2 size = textureSize(guide, 0);
  ivec2 ahead = p + axis, behind = p - axis;
  bool has_ahead = all(lessThan(ahead, size));
  bool has_behind = all(greaterThanEqual(behind, ivec2(0)));
  float d_ahead = has_ahead ? clean(texelFetch(guide, ahead, 0).a) : d;
  float d_behind = has_behind ? clean(texelFetch(guide, behind, 0).a) : d;
  bool no_jump = abs(d_ahead - d) <= kHistoryEdgeDepthJump * d && abs(d_behind - d) <= kHistoryEdgeDepthJump * d;
  if (!(has_ahead || has_behind) || !no_jump) return vec3(0.0f);
  if (has_ahead) return view_point(c, vec2(ahead) + vec2(0.5f), d_ahead) - point;
  return point - view_point(c, vec2(behind) + vec2(0.5f), d_behind);
}

// Whether a background pixel of a guide has a surface among its eight neighbours. Its samples then
// mix the surface and the background (the path tracer's pixel footprint), so it is a silhouette
// from the other side: reprojected as background, it carried a lit object's light away with the
// background, a trail of specks beside a sphere that the camera orbits.
PXF_SAMPLER_FN bool background_beside_surface(sampler2D guide, ivec2 p) {
  ivec2 size = textureSize(guide, 0);
  for (int i = 0; i < 9; ++i) {
    ivec2 q = p + ivec2(i % 3 - 1, i / 3 - 1);
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
    if (clean(texelFetch(guide, q, 0).a) < kBackgroundDistanceMin) return true;
  }
  return false;
}

// The unit normal of the surface a guide shows at pixel p, from the distances of p and its
// neighbours, turned towards the camera, in xyz; w = 1 where known, 0 on the background (no
// evidence either way), -1 where it cannot be told (a silhouette on either side, a degenerate step).
PXF_SAMPLER_FN vec4 guide_normal(sampler2D guide, ivec2 p, ViewCamera c) {
  float d = clean(texelFetch(guide, p, 0).a);
  if (!(d < kBackgroundDistanceMin)) return background_beside_surface(guide, p) ? vec4(0.0f, 0.0f, 0.0f, -1.0f) : vec4(0.0f);
  vec3 point = view_point(c, vec2(p) + vec2(0.5f), d);
  vec3 n = cross(guide_step(guide, p, ivec2(1, 0), c, point, d), guide_step(guide, p, ivec2(0, 1), c, point, d));
  float len = length(n);
  if (!(len > 0.0f)) return vec4(0.0f, 0.0f, 0.0f, -1.0f);
  n = n / len;
  vec3 to_camera = c.orthographic ? c.basis * vec3(0.0f, 0.0f, 1.0f) : c.origin - point;
  return vec4(dot(n, to_camera) < 0.0f ? -n : n, 1.0f);
}

// guide_normal where the newest raster frame's surface is not perfectly specular; w = -2 where it
// is: its guide distance is a specular chain's, no point on the camera ray, and a mirror pixel's
// history reprojected through it put the mirror's reflections onto the wall beside it.
PXF_SAMPLER_FN vec4 history_normal(sampler2D guide, float specular_flag, ivec2 p, ViewCamera c) {
  if (specular_flag > 0.5f) return vec4(0.0f, 0.0f, 0.0f, -2.0f);
  return guide_normal(guide, p, c);
}

// Whether two such normals allow the same surface: no silhouette or specular chain on either
// side, and where both are known, close enough.
PXF_INLINE bool history_normals_agree(vec4 a, vec4 b) {
  if (a.w < 0.0f || b.w < 0.0f) return false;
  if (a.w == 0.0f || b.w == 0.0f) return true;
  return dot(vec3(a), vec3(b)) >= kHistoryNormalAgreement;
}

PXF_INLINE float max_component(vec3 v) { return max(v.x, max(v.y, v.z)); }

// Whether a texel of the previous guide shows the surface the new pixel shows: its distance is the
// one the previous camera would see that surface at, and its range color is the new one's up to
// the change of the shading term (disocclusions fail one or both).
PXF_INLINE bool history_tap_agrees(vec4 previous_guide, vec3 new_color, float expected_distance) {
  float d = clean(previous_guide.a);
  if (!(abs(d - expected_distance) <= kHistoryDepthTolerance * max(d, expected_distance))) return false;
  vec3 old_color = clean(vec3(previous_guide));
  float allowed = kHistoryColorTolerance + kHistoryColorRelTolerance * max(max_component(old_color), max_component(new_color));
  return max_component(abs(old_color - clean(new_color))) <= allowed;
}

struct HistorySample {
  vec3 lv;        // L_lv of the history
  vec3 hv;        // L_u of the history
  float var;      // its Var[L_u] (kVarUnknown where not known)
  float count;    // the samples it holds (0: none)
  int outcome;    // kHistory*
};

PXF_INLINE HistorySample history_none(int outcome) {
  HistorySample h;
  h.lv = vec3(0.0f);
  h.hv = vec3(0.0f);
  h.var = kVarUnknown;
  h.count = 0.0f;
  h.outcome = outcome;
  return h;
}

// The previous view's estimate at new pixel p: the surface point the new guide shows at the pixel
// center, projected into the previous view, read there bilinearly from the texels that still show
// that surface (history_tap_agrees, history_normals_agree), their weights renormalized for the
// values; the count is the taps' weighted sum (the share of the footprint that agrees). The taps are independent pixel
// means: the variance is sum w^2 Var / (sum w)^2, a tap of unknown variance counted with the
// weighted mean of the known ones (as the filter does, method.md 2.3); unknown if none is known.
// The normals (guide_normal) of both guides come computed, one texel a pixel.
PXF_SAMPLER_FN HistorySample reproject_history(sampler2D previous_lv, sampler2D previous_hv, sampler2D previous_guide,
                                               sampler2D previous_normals, sampler2D new_guide_tex,
                                               sampler2D new_normals, ivec2 p, ViewCamera now, ViewCamera before) {
  vec4 new_guide = texelFetch(new_guide_tex, p, 0);
  vec3 x = view_point(now, vec2(p) + vec2(0.5f), clean(new_guide.a));
  vec2 q;
  float expected;
  if (!view_project(before, x, q, expected)) return history_none(kHistoryOutside);
  ivec2 size = textureSize(previous_guide, 0);
  vec4 normal = texelFetch(new_normals, p, 0);
  if (!(q.x >= 0.0f && q.y >= 0.0f && q.x <= float(size.x) && q.y <= float(size.y)))
    return history_none(kHistoryOutside);
  vec2 corner = q - vec2(0.5f);
  ivec2 base = ivec2(floor(corner));
  vec2 f = corner - floor(corner);
  wide_float sw = 0.0f, swm = 0.0f;
  wide_float sw_known = 0.0f, swv_known = 0.0f, sw2v_known = 0.0f, sw2_unknown = 0.0f;
  wide_vec3 slv = wide_vec3(0.0f), shv = wide_vec3(0.0f);
  for (int i = 0; i < 4; ++i) {
    ivec2 o = ivec2(i % 2, i / 2);
    ivec2 t = base + o;
    if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, size))) continue;
    wide_float w = wide_float((o.x == 1 ? f.x : 1.0f - f.x) * (o.y == 1 ? f.y : 1.0f - f.y));
    if (!(w > 0.0f) || !history_tap_agrees(texelFetch(previous_guide, t, 0), vec3(new_guide), expected)) continue;
    if (!history_normals_agree(normal, texelFetch(previous_normals, t, 0))) continue;
    vec4 lv = texelFetch(previous_lv, t, 0);
    vec4 hv = texelFetch(previous_hv, t, 0);
    float m = clean(lv.a);
    if (!(m > 0.0f)) continue;
    float v = clean_var(hv.a);
    sw += w;
    swm += w * wide_float(m);
    slv += w * wide_vec3(clean(vec3(lv)));
    shv += w * wide_vec3(clean(vec3(hv)));
    if (v >= 0.0f) {
      sw_known += w;
      swv_known += w * wide_float(v);
      sw2v_known += w * w * wide_float(v);
    } else {
      sw2_unknown += w * w;
    }
  }
  if (!(sw > 0.0f)) return history_none(kHistoryDisoccluded);
  HistorySample h;
  h.lv = vec3(slv / sw);
  h.hv = vec3(shv / sw);
  h.var = sw_known > 0.0f ? float((sw2v_known + swv_known / sw_known * sw2_unknown) / (sw * sw)) : kVarUnknown;
  // Not renormalized: a pixel that only a corner of the taps supports gets that share of their
  // samples (renormalized, one tap of small weight would stand for a whole history and smear
  // streaks along the motion).
  h.count = float(swm);
  h.outcome = kHistoryKept;
  return h;
}

// ---- The first frame after a move ----

// A pixel of the new view should hold about this many samples in its first frame, history and fresh
// paths together: one whose history holds less (disoccluded, outside the previous view, a partial
// footprint) traces the difference, so that the pixels without history are not the noisiest of the
// frame (in that frame their variance stays unknown: Preview::hide_first_frame_variances).
// With one path, a silhouette's pixels are 1-spp antialiasing and dominate a moving camera's error
// and flicker; more paths lower both, at the cost of the extra paths in the uncovered pixels, which
// is small where few pixels are uncovered and grows where many never take history (perfectly
// specular objects). 4 meets the error and flicker a moving camera aims at; more costs more where
// much is uncovered, for a gain not needed (docs/notebook/measurements.md, "A moving camera", has
// the figures).
PXF_CONST float kHistoryFirstFrameSamples = 4.0f;

// The paths pixel p traces in the first frame after a move, given the samples its reprojected
// history holds (HistorySample::count, 0 without history): at least 1, at most
// kHistoryFirstFrameSamples.
PXF_INLINE int first_frame_paths(float history_count) {
  float missing = kHistoryFirstFrameSamples - max(clean(history_count), 0.0f);
  return int(clamp(ceil(missing), 1.0f, kHistoryFirstFrameSamples));
}

// ---- The history beside the fresh samples ----

// The samples the history counts as after n fresh ones: at most kHistoryMaxCount, falling linearly
// to 0 at kHistoryFadeSamples fresh samples.
PXF_INLINE float history_count_kept(float m, float n) {
  return max(min(m, kHistoryMaxCount), 0.0f) * max(0.0f, 1.0f - n / kHistoryFadeSamples);
}

// The weight of the history in the pixel's estimate: h / (h + n), h = history_count_kept(m, n); 0
// without history.
PXF_INLINE float history_weight(float m, float n) {
  float h = history_count_kept(m, n);
  return h > 0.0f ? h / (h + max(n, 0.0f)) : 0.0f;
}

struct HistoryBlend {
  vec3 lv;       // alpha L_lv(history) + (1 - alpha) L_lv(fresh)
  vec3 hv;       // the same for L_u
  float var;     // its variance (kVarUnknown where neither part's is known)
  float count;   // the samples it counts as: h + n
  float weight;  // alpha
};

// The history as a second estimate beside the fresh samples (n of them, Var[L_u] `var`), the two
// mixed with weight alpha = history_weight(m, n). Its variance is alpha^2 Var_h + (1 - alpha)^2
// Var_n; where one part's variance is unknown (n < 2 fresh samples, or an unknown history), it is
// estimated from the other part's per-sample variance (Var times count) and its own count. The
// history's bias (it saw the surface from elsewhere, resampled) is not in the variance: its weight
// falls to 0 instead, and with it the bias. alpha = 0 passes the fresh samples through unchanged.
PXF_INLINE HistoryBlend combine_history(vec3 lv, vec3 hv, float var, float n, HistorySample history) {
  HistoryBlend b;
  b.weight = history_weight(history.count, n);
  b.lv = clean(lv);
  b.hv = clean(hv);
  b.var = clean_var(var);
  b.count = max(n, 0.0f);
  if (!(b.weight > 0.0f)) return b;
  float a = b.weight;
  float var_h = clean_var(history.var);
  float var_n = b.var;
  if (var_n < 0.0f && var_h >= 0.0f && n > 0.0f) var_n = var_h * history.count / n;
  if (var_h < 0.0f && var_n >= 0.0f) var_h = var_n * n / max(history.count, 1.0f);
  b.lv = a * clean(history.lv) + (1.0f - a) * b.lv;
  b.hv = a * clean(history.hv) + (1.0f - a) * b.hv;
  if (!(a < 1.0f)) var_n = 0.0f;  // no fresh samples: their part has no weight
  b.var = (var_h >= 0.0f && var_n >= 0.0f) ? min(a * a * var_h + (1.0f - a) * (1.0f - a) * var_n, kMaxInput) : kVarUnknown;
  b.count = history_count_kept(history.count, n) + max(n, 0.0f);
  return b;
}

PXF_SHARED_END
