#include "pathtracer/guiding_lobes.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace pxf {

namespace {

constexpr double kTwoPi = 6.283185307179586476925;
constexpr double kInvFourPi = 0.0795774715459476678844;
constexpr double kMinKappa = 0.05;  // below this a lobe is as good as uniform
constexpr int kKMeansRounds = 4;
constexpr int kEmRounds = 10;
constexpr double kMinLobeShare = 1e-3;

uint64_t mix64(uint64_t x) {  // splitmix64's finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

bool kept_before(const GuidingLobeRecord& a, const GuidingLobeRecord& b) {
  return a.priority != b.priority ? a.priority > b.priority : a.key < b.key;
}

// An orthonormal frame around a unit vector (Duff et al. 2017).
void tangents(const glm::vec3& n, glm::vec3* t, glm::vec3* b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  *t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  *b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

glm::dvec3 unit_or(const glm::dvec3& v, const glm::dvec3& fallback) {
  const double length = glm::length(v);
  return length > 1e-12 && std::isfinite(length) ? v / length : fallback;
}

// Banerjee et al. 2005's estimate of kappa from the mean resultant length r in [0, 1).
double kappa_of(double r) {
  r = std::min(std::max(r, 0.0), 0.999999);
  const double kappa = r * (3.0 - r * r) / (1.0 - r * r);
  return std::min(std::max(kappa, kMinKappa), double(kMaxLobeKappa));
}

// log of the vMF density's constant without log(1 / 2 pi): log kappa - log(1 - e^-2kappa).
double vmf_log_normalisation(double kappa) { return std::log(kappa) - std::log(-std::expm1(-2.0 * kappa)); }

// log of the vMF density without log(1 / 2 pi); the exponent kappa (cos - 1) as -kappa |mu - w|^2 / 2.
double vmf_log(const glm::dvec3& mean, double kappa, double log_normalisation, const glm::dvec3& w) {
  const glm::dvec3 d = mean - w;
  return log_normalisation - 0.5 * kappa * glm::dot(d, d);
}

// Farthest-point seeds then a few rounds of spherical k-means: a deterministic start for EM.
std::vector<glm::dvec3> seed_means(const std::vector<glm::dvec3>& v, int count) {
  std::vector<glm::dvec3> means{v[0]};
  std::vector<double> nearest(v.size(), -2.0);  // the largest cosine to any mean so far
  while (static_cast<int>(means.size()) < count) {
    size_t far = 0;
    for (size_t i = 0; i < v.size(); ++i) {
      nearest[i] = std::max(nearest[i], glm::dot(v[i], means.back()));
      if (nearest[i] < nearest[far]) far = i;
    }
    if (nearest[far] > 0.9999) break;  // every direction is already next to a mean
    means.push_back(v[far]);
  }
  for (int round = 0; round < kKMeansRounds; ++round) {
    std::vector<glm::dvec3> sums(means.size(), glm::dvec3(0.0));
    for (const glm::dvec3& d : v) {
      size_t best = 0;
      for (size_t j = 1; j < means.size(); ++j)
        if (glm::dot(d, means[j]) > glm::dot(d, means[best])) best = j;
      sums[best] += d;
    }
    for (size_t j = 0; j < means.size(); ++j) means[j] = unit_or(sums[j], means[j]);
  }
  return means;
}

}  // namespace

glm::vec3 record_direction(const GuidingLobeRecord& r) {
  if (r.kind == kSourceAtInfinity) return r.source;
  const glm::vec3 d = r.kind == kSourceAhead ? r.position - r.source : r.source - r.position;
  const float length = glm::length(d);
  return length > 0.0f && std::isfinite(length) ? d / length : glm::vec3(0.0f);
}

float best_guided_share(const std::vector<GuidingLobe>& lobes, const std::vector<GuidingLobeRecord>& records,
                        float uniform_fraction, float min_kappa, float fallback, const std::vector<double>& weights) {
  constexpr int kSteps = 10;  // alpha = 0, 0.1, ..., 0.9: the BSDF keeps at least a tenth
  struct Densities {
    double guide, cosine, share, weight;
  };
  std::vector<Densities> at;
  for (size_t i = 0; i < records.size(); ++i) {
    const GuidingLobeRecord& r = records[i];
    const glm::vec3 d = record_direction(r);
    const float cosine = glm::dot(d, r.normal);
    if (!(cosine > 0.0f)) continue;  // no normal, or light from behind: not a sample of L_i cos
    const LobeMixture mixture(lobes, r.position, uniform_fraction, r.normal, min_kappa);
    at.push_back({mixture.empty() ? 0.0 : double(mixture.pdf(d)), cosine / 3.14159265358979323846, mixture.share(),
                  weights.empty() ? 1.0 : weights[i]});
  }
  if (at.size() < kMinLobeRecords) return fallback;
  int best = 0;
  double best_divergence = 0.0;
  for (int step = 0; step < kSteps; ++step) {
    const double alpha = step / double(kSteps);
    double divergence = 0.0;  // minus the sum of log p_mixture
    for (const Densities& x : at)
      divergence -= x.weight * std::log(alpha * x.share * x.guide + (1.0 - alpha * x.share) * x.cosine);
    if (step == 0 || divergence < best_divergence) {
      best = step;
      best_divergence = divergence;
    }
  }
  return best / float(kSteps);
}

float lobe_record_priority(uint64_t key, float energy) {
  // u in (0, 1] from the key; A-ES keeps the largest u^(1/energy), i.e. log(u) / energy.
  const double u = (double(mix64(key) >> 11) + 1.0) * 0x1.0p-53;
  return static_cast<float>(std::log(u) / std::max(double(energy), 1e-30));
}

void merge_into_reservoir(std::vector<GuidingLobeRecord>& reservoir, const std::vector<GuidingLobeRecord>& incoming,
                          size_t capacity) {
  std::vector<GuidingLobeRecord> all = reservoir;
  all.insert(all.end(), incoming.begin(), incoming.end());
  if (all.size() > capacity) std::nth_element(all.begin(), all.begin() + capacity, all.end(), kept_before);
  reservoir.reserve(capacity);  // the reservoir never holds more than its capacity, nor allocates more
  reservoir.assign(all.begin(), all.begin() + std::min(capacity, all.size()));
}

std::vector<GuidingLobe> fit_guiding_lobes(const std::vector<GuidingLobeRecord>& unordered, int max_lobes,
                                           size_t min_records) {
  min_records = std::max<size_t>(min_records, 1);
  if (unordered.size() < min_records || max_lobes < 1) return {};
  std::vector<GuidingLobeRecord> records = unordered;  // in key order: the fit does not depend on arrival
  std::sort(records.begin(), records.end(), [](const auto& a, const auto& b) { return a.key < b.key; });
  const size_t n = records.size();
  glm::dvec3 o(0.0);
  for (const GuidingLobeRecord& r : records) o += glm::dvec3(r.position);
  o /= double(n);

  // Each record's light seen from the mean position: toward its source, away from a focus ahead
  // (its own direction where the source is at the mean position).
  std::vector<glm::dvec3> v(n);
  for (size_t i = 0; i < n; ++i) {
    const GuidingLobeRecord& r = records[i];
    if (r.kind == kSourceAtInfinity) {
      v[i] = glm::dvec3(r.source);
      continue;
    }
    const double sign = r.kind == kSourceAhead ? -1.0 : 1.0;
    const glm::dvec3 own = unit_or(sign * (glm::dvec3(r.source) - glm::dvec3(r.position)), {0, 0, 1});
    v[i] = unit_or(sign * (glm::dvec3(r.source) - o), own);
  }

  // Weighted EM of a vMF mixture (every kept record weighs the same: the reservoir sampled by energy).
  std::vector<glm::dvec3> mean = seed_means(v, std::min<int>(max_lobes, std::max<int>(1, int(n / min_records))));
  const size_t k = mean.size();
  std::vector<double> kappa(k, 10.0), share(k, 1.0 / double(k));
  std::vector<double> resp(n * k);
  for (int round = 0; round < kEmRounds; ++round) {
    std::vector<double> log_weight(k);  // log(share x the vMF's normalisation)
    for (size_t j = 0; j < k; ++j) log_weight[j] = share[j] > 0.0 ? std::log(share[j]) + vmf_log_normalisation(kappa[j]) : -1e300;
    for (size_t i = 0; i < n; ++i) {  // E: responsibilities, in logs (tight lobes overflow exp)
      double top = -1e300;
      for (size_t j = 0; j < k; ++j) {
        resp[i * k + j] = share[j] > 0.0 ? vmf_log(mean[j], kappa[j], log_weight[j], v[i]) : -1e300;
        top = std::max(top, resp[i * k + j]);
      }
      double sum = 0.0;
      for (size_t j = 0; j < k; ++j) sum += resp[i * k + j] = std::exp(resp[i * k + j] - top);
      for (size_t j = 0; j < k; ++j) resp[i * k + j] /= sum;
    }
    for (size_t j = 0; j < k; ++j) {  // M
      double weight = 0.0;
      glm::dvec3 resultant(0.0);
      for (size_t i = 0; i < n; ++i) {
        weight += resp[i * k + j];
        resultant += resp[i * k + j] * v[i];
      }
      share[j] = weight / double(n);
      if (!(weight > 0.0)) continue;
      mean[j] = unit_or(resultant, mean[j]);
      kappa[j] = kappa_of(glm::length(resultant) / weight);
    }
  }

  std::vector<GuidingLobe> lobes;
  lobes.reserve(k);  // exactly: the field counts a leaf's lobes at their capacity
  double kept = 0.0;
  for (size_t j = 0; j < k; ++j) {
    if (!(share[j] >= kMinLobeShare)) continue;
    // The lobe's source: the mean of its records' sources of the kind most of them have.
    double weight[3] = {0.0, 0.0, 0.0};
    glm::dvec3 sources[3] = {glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};
    for (size_t i = 0; i < n; ++i) {
      const double r = resp[i * k + j];
      weight[records[i].kind] += r;
      sources[records[i].kind] += r * glm::dvec3(records[i].source);
    }
    GuidingLobe lobe;
    lobe.direction = glm::vec3(mean[j]);
    lobe.kappa = static_cast<float>(kappa[j]);
    lobe.share = static_cast<float>(share[j]);
    const int kind = weight[kSourceAhead] > weight[kSourceBehind] ? kSourceAhead : kSourceBehind;
    if (weight[kind] > weight[kSourceAtInfinity] && weight[kind] > 0.0) {  // parallax: most of its light has a source
      const glm::dvec3 centre = sources[kind] / weight[kind];
      const double distance = glm::length(centre - o);
      const double sign = kind == kSourceAhead ? -1.0 : 1.0;
      if (distance > 0.0 && std::isfinite(distance)) {
        lobe.source = glm::vec3(centre);
        lobe.distance = static_cast<float>(sign * distance);
        lobe.direction = glm::vec3(sign * (centre - o) / distance);
      }
    }
    kept += share[j];
    lobes.push_back(lobe);
  }
  for (GuidingLobe& lobe : lobes) lobe.share = static_cast<float>(lobe.share / kept);
  return lobes;
}

double vmf_pdf(const glm::dvec3& mean, double kappa, const glm::dvec3& w) {
  return std::exp(vmf_log(mean, kappa, vmf_log_normalisation(kappa), w)) / kTwoPi;
}

glm::vec3 vmf_sample(const glm::vec3& mean, float kappa, glm::vec2 u) {
  // 1 - cos theta = -log(1 + (1 - u) (e^-2kappa - 1)) / kappa, inverted from the CDF of cos theta;
  // log1p and expm1 keep it accurate in float for both small and large kappa (u = 0 gives 2).
  const float one_minus_cos =
      std::min(std::max(-std::log1p((1.0f - u.x) * std::expm1(-2.0f * kappa)) / kappa, 0.0f), 2.0f);
  const float cos_theta = 1.0f - one_minus_cos;
  const float sin_theta = std::sqrt(std::max(0.0f, one_minus_cos * (2.0f - one_minus_cos)));
  const float phi = float(kTwoPi) * u.y;
  glm::vec3 t, b;
  tangents(mean, &t, &b);
  return glm::normalize(cos_theta * mean + sin_theta * (std::cos(phi) * t + std::sin(phi) * b));
}

LobeMixture::LobeMixture(const std::vector<GuidingLobe>& lobes, const glm::vec3& point, float uniform_fraction,
                         const glm::vec3& normal, float min_kappa)
    : uniform_fraction_(uniform_fraction) {
  // Built once per guided vertex: squared distances and one reciprocal square root per lobe, no
  // division, because this runs for every camera path's first diffuse vertex.
  float total = 0.0f;
  for (const GuidingLobe& lobe : lobes) {
    if (count_ == kMaxGuidingLobes) break;
    if (lobe.kappa * 4.0f < min_kappa) continue;  // too wide even at the largest distance factor
    glm::vec3 mean = lobe.direction;
    float kappa = lobe.kappa;
    if (lobe.distance != 0.0f) {
      const glm::vec3 to_source = lobe.source - point;
      const float distance_squared = glm::dot(to_source, to_source), reference_squared = lobe.distance * lobe.distance;
      if (distance_squared > 1e-12f * reference_squared && distance_squared <= FLT_MAX) {
        const float inverse_distance = 1.0f / std::sqrt(distance_squared);
        mean = (lobe.distance > 0.0f ? inverse_distance : -inverse_distance) * to_source;
        const float ratio_squared = distance_squared / reference_squared;
        kappa = std::min(kMaxLobeKappa, kappa * std::min(4.0f, std::max(0.25f, ratio_squared)));
      }
    }
    if (kappa < min_kappa) continue;
    const float below = -glm::dot(mean, normal);  // below the horizon by more than 1 / sqrt(kappa)?
    if (below > 0.0f && below * below * kappa > 1.0f) continue;
    mean_[count_] = mean;
    kappa_[count_] = kappa;
    weight_[count_] = lobe.share;
    total += lobe.share;
    cumulative_[count_] = total;
    ++count_;
  }
  share_ = std::min(total, 1.0f);
  if (!(total > 0.0f)) {
    count_ = 0;
    share_ = 0.0f;
    return;
  }
  const float inverse_total = 1.0f / total;
  for (int j = 0; j < count_; ++j) {
    const float kappa = kappa_[j];
    // 1 - e^-2kappa, which rounds to 1 in float from kappa = 9 on: most lobes skip the exponential.
    const float normalisation = kappa < 9.0f ? -std::expm1(-2.0f * kappa) : 1.0f;
    weight_[j] = weight_[j] * inverse_total * kappa / (float(kTwoPi) * normalisation);
    cumulative_[j] *= inverse_total;
  }
  cumulative_[count_ - 1] = 1.0f;
}

glm::vec3 LobeMixture::sample(glm::vec2 u, float* pdf_out) const {
  constexpr float kBelowOne = 0x1.fffffep-1f;
  float x = std::min(std::max(u.x, 0.0f), kBelowOne);
  const float y = std::min(std::max(u.y, 0.0f), kBelowOne);
  glm::vec3 direction;
  if (count_ == 0 || x < uniform_fraction_) {
    const float z = count_ == 0 ? 1.0f - 2.0f * x : 1.0f - 2.0f * (x / uniform_fraction_);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    direction = glm::vec3(r * std::cos(float(kTwoPi) * y), r * std::sin(float(kTwoPi) * y), z);
  } else {
    x = std::min((x - uniform_fraction_) / (1.0f - uniform_fraction_), kBelowOne);
    int j = 0;
    while (j < count_ - 1 && x >= cumulative_[j]) ++j;
    const float lo = j == 0 ? 0.0f : cumulative_[j - 1];
    const float width = cumulative_[j] - lo;
    const float within = width > 0.0f ? std::min(std::max((x - lo) / width, 0.0f), kBelowOne) : 0.5f;
    direction = vmf_sample(mean_[j], kappa_[j], glm::vec2(within, y));
  }
  if (pdf_out) *pdf_out = pdf(direction);  // the same function as every MIS weight of this direction uses
  return direction;
}

float LobeMixture::pdf(const glm::vec3& direction) const {
  const float length_squared = glm::dot(direction, direction);
  if (!(length_squared > 0.0f) || !(length_squared <= FLT_MAX)) return 0.0f;
  if (count_ == 0) return static_cast<float>(kInvFourPi);
  const glm::vec3 w = direction * (1.0f / std::sqrt(length_squared));
  float lobes = 0.0f;
  for (int j = 0; j < count_; ++j) {
    const glm::vec3 d = mean_[j] - w;  // kappa (cos - 1) = -kappa |mean - w|^2 / 2, exact near the mean
    const float exponent = 0.5f * kappa_[j] * glm::dot(d, d);
    // Beyond e^-60 a lobe adds less than 1e-21 of its peak (at most 1e5 / 2 pi): nothing next to the uniform part.
    if (exponent < 60.0f) lobes += weight_[j] * std::exp(-exponent);
  }
  return uniform_fraction_ * float(kInvFourPi) + (1.0f - uniform_fraction_) * lobes;
}

}  // namespace pxf
