// Parallax-aware directional distributions for path guiding (after Ruppert, Herholz and Lensch
// 2020, "Robust fitting of parallax-aware mixtures for path guiding"): a few von Mises-Fisher lobes
// per spatial region, each aimed at the point its light comes from rather than in a fixed
// direction, so that a lobe re-aims at whatever point of the region asks.
//
// Why: a directional distribution learned over a region is the same at every point of it, while a
// caustic's direction changes across the region (the mirror sphere's image of the light seen from
// different points of a wall). A distribution fixed in direction has to spread over all of them; a
// lobe that keeps the caustic's source point (the photons' previous vertex, on the mirror) stays as
// narrow as the source region seen from the point (docs/guiding.md, "Parallax-aware lobes").
//
// Learning: the photons that reach a region during an iteration are sampled into a bounded
// reservoir (weighted by their energy, deterministically), and at the end of the iteration a
// weighted spherical EM fits the lobes to the directions of their source points seen from the
// reservoir's mean position.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace pxf {

// A lobe as learned: the point its light seems to come from (or only a direction), how
// concentrated it is seen from `reference_distance` away, and its share of the region's energy.
struct GuidingLobe {
  glm::vec3 direction{0.0f, 0.0f, 1.0f};  // unit, seen from the region's mean position
  glm::vec3 source{0.0f};  // the point the light seems to come from, when distance != 0
  // From the region's mean position to source; 0: no parallax (far or unknown); negative: the light
  // converges toward source (a focus ahead), so it arrives from the side opposite to it.
  float distance = 0.0f;
  float kappa = 1.0f;      // vMF concentration seen from the region's mean position, in (0, kMaxLobeKappa]
  float share = 0.0f;      // of the region's energy; the lobes of a region add up to at most 1
};

// Where a record's light seems to come from (GuidingRecord::source).
enum GuidingSourceKind : uint32_t {
  kSourceBehind = 0,    // a point the light diverges from: the previous vertex, or its image
  kSourceAtInfinity = 1,  // unknown or far: `source` is the unit direction toward the light
  kSourceAhead = 2,     // a point the light converges to (past the record: a focus)
};

// A photon record kept for the fit: where it arrived, where from, and its reservoir priority.
struct GuidingLobeRecord {
  uint64_t key = 0;
  float priority = 0.0f;   // log(u) / energy (A-ES weighted reservoir sampling): the largest are kept
  glm::vec3 position{0.0f};
  glm::vec3 source{0.0f};
  uint32_t kind = kSourceBehind;
  glm::vec3 normal{0.0f};  // of the receiving surface, on the side the light arrives; 0: unknown
};

// The direction toward the light of a record (from its source and kind).
glm::vec3 record_direction(const GuidingLobeRecord& record);

constexpr int kMaxGuidingLobes = 8;
constexpr float kMaxLobeKappa = 1.0e5f;  // about 0.2 degrees wide: far narrower than any light seen here

// The reservoir priority of a record of energy > 0 with a unique key: a deterministic function of
// both, so that the kept set is the same whatever order records arrive in.
float lobe_record_priority(uint64_t key, float energy);
// Adds `incoming` to a reservoir and keeps the `capacity` records of largest (priority, -key).
void merge_into_reservoir(std::vector<GuidingLobeRecord>& reservoir, const std::vector<GuidingLobeRecord>& incoming,
                          size_t capacity);

// The lobes that fit a reservoir (at most max_lobes, one per min_records records; none when it holds
// fewer than min_records), their directions and distances seen from the records' mean position.
constexpr size_t kMinLobeRecords = 16;
// The light that arrives through delta bounces (a mirror's or a lens's caustic) is fitted from as
// few as this many records: it is concentrated, so few records place its lobe, and a leaf meets
// few such photons (GuidingSettings::delta_lobes).
constexpr size_t kMinDeltaLobeRecords = 4;
std::vector<GuidingLobe> fit_guiding_lobes(const std::vector<GuidingLobeRecord>& records, int max_lobes,
                                           size_t min_records = kMinLobeRecords);

// The guided share alpha (of 0, 0.1, ..., 0.9) whose mixture alpha s p_lobes + (1 - alpha s) p_cos
// is closest to the light the records show, with p_lobes the LobeMixture at each record's point and
// normal, s its share() and p_cos = cos / pi: the records are distributed like that light (L_i cos),
// so the mean of log p_mixture over them is, up to a constant, minus the KL divergence from it
// (Müller et al. 2019 learn their selection probability by the same divergence). `fallback` where
// fewer than kMinLobeRecords records have a normal. `weights` (empty: all 1) weigh the records where
// they are not one sample of that light alike (two reservoirs, each sampled by energy within itself).
float best_guided_share(const std::vector<GuidingLobe>& lobes, const std::vector<GuidingLobeRecord>& records,
                        float uniform_fraction, float min_kappa, float fallback,
                        const std::vector<double>& weights = {});

// The vMF density on the unit sphere, stable for large kappa.
double vmf_pdf(const glm::dvec3& mean, double kappa, const glm::dvec3& direction);
glm::vec3 vmf_sample(const glm::vec3& mean, float kappa, glm::vec2 u);  // in float: sampled per guided vertex

// The lobes of a region as seen from one point: what sampling and pdf evaluation use at a vertex. A
// lobe with a source aims at it (away from it for a focus), its concentration scaled by the square of the distance ratio (a
// source region looks that much smaller from farther away; the factor is kept within [1/4, 4]).
class LobeMixture {
 public:
  LobeMixture() = default;
  // uniform_fraction of the density is uniform over the sphere (no direction gets pdf 0).
  // A non-zero `normal` leaves out the lobes whose (re-aimed) mean lies more than 1 / sqrt(kappa),
  // about one standard deviation, below its horizon: light from behind the surface serves no sample.
  // Lobes less concentrated than min_kappa (there) are left out too. share() says what is left.
  LobeMixture(const std::vector<GuidingLobe>& lobes, const glm::vec3& point, float uniform_fraction,
              const glm::vec3& normal = glm::vec3(0.0f), float min_kappa = 0.0f);
  bool empty() const { return count_ == 0; }
  // The share of the region's lobes this point samples (those left out: behind it, or too wide).
  float share() const { return share_; }
  glm::vec3 sample(glm::vec2 u, float* pdf) const;  // pdf: exactly pdf(direction)
  float pdf(const glm::vec3& direction) const;

 private:
  int count_ = 0;
  float uniform_fraction_ = 0.0f;
  float share_ = 0.0f;
  glm::vec3 mean_[kMaxGuidingLobes];
  float kappa_[kMaxGuidingLobes];
  float weight_[kMaxGuidingLobes];  // share x the vMF normalisation
  float cumulative_[kMaxGuidingLobes];
};

}  // namespace pxf
