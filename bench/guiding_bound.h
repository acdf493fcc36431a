// How far path guiding at a path's first non-delta vertex can go (docs/guiding.md, "How
// far first-vertex guiding can go"): the variance of the cosine-weighted indirect light at sampled
// first vertices under cosine sampling, under the renderer's trained field, and under guides that
// know the light exactly. `pxf bench guiding-bound` prints it.
//
// At a point, the hemisphere is cut into cells (a cube map around the shading normal) and every
// cell's indirect radiance is traced from the point with many paths: its mean and second moment,
// the deeper vertices' noise included (the direct light a direction sees, which NEE serves, is
// left out). A one-sample estimator that picks cell c with probability q_c, a direction in it as
// cosine sampling would, and weighs the path by b_c / q_c (b_c: cosine sampling's probability of
// the cell) has a variance that follows from those moments alone, so one set of traced cells
// rates every guide: cosine sampling (q = b), the learned field, the light known exactly, and the
// least variance any choice of q can give.
#pragma once
#include <cstdint>
#include <vector>

#include "pathtracer/pathtracer.h"

namespace pxf {

// One cell of directions around a point.
struct DirectionCell {
  double cosine_share = 0.0;   // b: the probability that cosine sampling picks a direction in it
  double guide_share = 0.0;    // the learned field's probability of it (its pdf times the cell's solid angle)
  double mean = 0.0;           // E[L]: the indirect radiance one path brings back from a direction in it
  double second_moment = 0.0;  // E[L^2] of the same
};

// The variance of the estimator above for cell probabilities q (q_c > 0 wherever b_c > 0).
double cell_estimator_variance(const std::vector<DirectionCell>& cells, const std::vector<double>& q);
// The renderer's one-sample mixture: alpha of the field's guide, the rest cosine sampling.
std::vector<double> field_guide(const std::vector<DirectionCell>& cells, double alpha);
// The light known exactly: q proportional to b mean with probability alpha, cosine sampling the rest.
std::vector<double> known_light_guide(const std::vector<DirectionCell>& cells, double alpha);
// q proportional to b sqrt(E[L^2]): the least variance of any choice of cells (deeper noise and all).
std::vector<double> least_variance_guide(const std::vector<DirectionCell>& cells);
// A floor under every guide, however fine: for any density q of directions (positive wherever
// light comes from), the variance E_q[(b L / q)^2] - I^2 is at least E_b[sqrt(e)]^2 - I^2, with e(w)
// = E[L^2] of one path in the exact direction w (Cauchy-Schwarz; the least over cells is the same
// figure on a partition, and tends to it as the cells shrink). From directions drawn by cosine
// sampling, each with several paths: `second_moments` the mean of L^2 over a direction's paths,
// `means` the mean of L. Both estimates err low (sqrt of an unbiased estimate, and the square of
// the mean estimated from them), so the floor does too: no guide gets below it.
double guide_variance_floor(const std::vector<double>& second_moments, const std::vector<double>& means);

// One first vertex's figures: variances of one sample's estimate of the cosine-weighted indirect
// radiance, times the squared luminance of the diffuse albedo (so that points add up as the
// pixels' HDR errors do).
struct GuidingBoundPoint {
  int x = 0, y = 0;         // the pixel whose camera ray found the point
  double indirect = 0.0;    // the cosine-weighted indirect radiance times the albedo
  double cosine = 0.0;      // cosine sampling (the unguided renderer's diffuse lobe)
  double field = 0.0;       // the trained field at the share the renderer would guide with
  double known_light = 0.0; // known_light_guide at alpha 0.5 (the share Müller et al. fix)
  double least = 0.0;       // least_variance_guide
  double floor = 0.0;       // guide_variance_floor: no first-vertex guide, however fine, has less
  double deeper = 0.0;      // sum b (E[L^2] - mean^2): the noise of the vertices after this one, under cosine sampling
  double field_alpha = 0.0; // the field's guided share at the point (0: not guided)
};

struct GuidingBoundSettings {
  int points = 48;            // first vertices, at pixels drawn uniformly (points without a diffuse lobe skipped)
  int face_cells = 24;        // cells along a cube face's edge (5 faces cover the hemisphere)
  int paths_per_cell = 32;
  int floor_directions = 256;   // directions drawn by cosine sampling for the floor,
  int floor_paths = 256;        // paths in each (exactly that direction): fewer read the floor low
  int train_frames = 31;      // the field's training: frames of a guided render at the image size
  uint64_t seed = 1;
};

struct GuidingBound {
  std::vector<GuidingBoundPoint> points;
  // The renderer's first vertices also trace specular chains toward the scene's perfectly specular
  // meshes (TraceParams::specular_chains), a strategy the cells leave out: cosine sampling
  // here is then noisier than the unguided renderer, and the figures do not bound it.
  bool chains_left_out = false;
};

// `params`: the render's (its guiding flag is ignored: the training is guided, the cells' paths are
// not). Points are the first surfaces camera rays meet (not through mirrors or glass).
GuidingBound measure_guiding_bound(const Scene& scene, const TraceParams& params, int width, int height,
                                   const GuidingBoundSettings& settings);

}  // namespace pxf
