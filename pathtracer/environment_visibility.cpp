#include "pathtracer/environment_visibility.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "core/error.h"
#include "pathtracer/byte_io.h"
#include "scene/texture.h"

namespace pxf {

struct EnvironmentVisibility::Sums {
  std::atomic<uint64_t> bins[kBins];
  std::atomic<uint32_t> records{0};  // unblocked ones
  // NEE's samples: the light all of them carried, and the light of those that got through.
  std::atomic<uint64_t> offered{0}, visible{0};
  Sums() {
    for (auto& b : bins) b.store(0, std::memory_order_relaxed);
  }
};

namespace {

constexpr char kMagic[8] = {'P', 'X', 'F', 'S', 'K', 'Y', 'V', 'S'};
constexpr uint32_t kFormatVersion = 1;
// A record's fixed-point value is capped here, so that 2^24 of them in one bin fit 64 bits.
constexpr double kMaxSteps = 1099511627776.0;  // 2^40

int side_of(const glm::vec3& n) {
  const glm::vec3 a = glm::abs(n);
  const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
  return 2 * axis + (n[axis] < 0.0f ? 1 : 0);
}

// The bin holding equirect position uv, and uv inside it (its unit square).
int bin_of(glm::vec2 uv, glm::vec2* local) {
  const float x = std::clamp(uv.x, 0.0f, 0x1.fffffep-1f) * EnvironmentVisibility::kBinsU;
  const float y = std::clamp(uv.y, 0.0f, 0x1.fffffep-1f) * EnvironmentVisibility::kBinsV;
  const int bx = std::min(static_cast<int>(x), EnvironmentVisibility::kBinsU - 1);
  const int by = std::min(static_cast<int>(y), EnvironmentVisibility::kBinsV - 1);
  if (local) *local = glm::vec2(x - bx, y - by);
  return by * EnvironmentVisibility::kBinsU + bx;
}

// The solid-angle density of a density over the equirect square at direction d.
float solid_angle_density(float uv_density, const glm::vec3& d) {
  const float sin_theta = std::sqrt(d.x * d.x + d.z * d.z) / std::max(glm::length(d), 1e-30f);
  return sin_theta > 0.0f ? uv_density / (2.0f * kPi * kPi * sin_theta) : 0.0f;
}

// A region's bin weights from its sums: each bin keeps its own and gets kNeighbourShare of each of
// its 8 neighbours' (around in u, clamped in v). The sky through an opening is one patch of bins,
// and a few records find only some of them: the neighbours' share sends samples to the rest.
constexpr double kNeighbourShare = 0.125;
void blur_bins(const double* sums, float* weights) {
  constexpr int nu = EnvironmentVisibility::kBinsU, nv = EnvironmentVisibility::kBinsV;
  for (int y = 0; y < nv; ++y)
    for (int x = 0; x < nu; ++x) {
      double w = sums[y * nu + x];
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int yy = y + dy;
          if ((dx == 0 && dy == 0) || yy < 0 || yy >= nv) continue;
          w += kNeighbourShare * sums[yy * nu + (x + dx + nu) % nu];
        }
      weights[y * nu + x] = static_cast<float>(w);
    }
}

// The environment's luminance integrated over the sphere (the texels as constant cells).
double environment_integral(const Environment& environment) {
  const Texture& image = environment.image;
  double integral = 0.0;
  for (int y = 0; y < image.height; ++y) {
    const double sin_theta = std::sin(kPi * (y + 0.5) / image.height);
    for (int x = 0; x < image.width; ++x) {
      const double l = luminance(glm::vec3(image.texel(static_cast<size_t>(y) * image.width + x)));
      if (std::isfinite(l) && l > 0.0) integral += l * sin_theta;
    }
  }
  return integral * environment.strength * 2.0 * kPi * kPi / (static_cast<double>(image.width) * image.height);
}

// A CDF over n entries from weights (a uniform one where they sum to 0): cdf[0] = 0, cdf[n] = 1.
void build_cdf(const double* weights, int n, float* cdf) {
  double total = 0.0;
  for (int i = 0; i < n; ++i) total += weights[i];
  double sum = 0.0;
  cdf[0] = 0.0f;
  for (int i = 0; i < n; ++i) {
    sum += total > 0.0 ? weights[i] : 1.0;
    cdf[i + 1] = static_cast<float>(sum / (total > 0.0 ? total : n));
  }
  cdf[n] = 1.0f;
}

// The entry of CDF cdf[0..n] holding u, skipping empty entries, and u's place in it (in [0, 1)).
int find_in_cdf(const float* cdf, int n, float u, float* t) {
  int i = static_cast<int>(sorted_upper_bound(cdf, static_cast<size_t>(n) + 1, u, 9)) - 1;
  i = std::clamp(i, 0, n - 1);
  while (!(cdf[i + 1] > cdf[i]) && i + 1 < n) ++i;
  const float width = cdf[i + 1] - cdf[i];
  *t = std::clamp(width > 0.0f ? (u - cdf[i]) / width : 0.5f, 0.0f, 0x1.fffffep-1f);
  return i;
}

// Each CDF runs from 0 to 1 without stepping back, and the share is one learned_share gives.
bool valid(const LearnedBins& b) {
  const auto monotone = [](const float* cdf, int n) {
    if (cdf[0] != 0.0f || cdf[n] != 1.0f) return false;
    for (int i = 0; i < n; ++i)
      if (!(cdf[i + 1] >= cdf[i])) return false;
    return true;
  };
  if (!monotone(b.row_cdf, LearnedBins::kV) || !(b.share >= 0.0f && b.share <= EnvironmentVisibility::kMaxLearnedShare))
    return false;
  for (int y = 0; y < LearnedBins::kV; ++y)
    if (!monotone(b.cdf[y], LearnedBins::kU)) return false;
  return true;
}

// A region's learned bins from its blurred sums.
LearnedBins learned_bins(const float* weights, float share) {
  LearnedBins b;
  double row[LearnedBins::kV], col[LearnedBins::kU];
  for (int y = 0; y < LearnedBins::kV; ++y) {
    row[y] = 0.0;
    for (int x = 0; x < LearnedBins::kU; ++x) row[y] += col[x] = weights[y * LearnedBins::kU + x];
    build_cdf(col, LearnedBins::kU, b.cdf[y]);
  }
  build_cdf(row, LearnedBins::kV, b.row_cdf);
  b.share = share;
  return b;
}

}  // namespace

EnvironmentVisibility::EnvironmentVisibility(const Environment& environment, glm::vec3 lo, glm::vec3 hi)
    : lo_(lo), hi_(hi) {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || !(lo[a] < hi[a]))
      throw Error("environment visibility: the scene's box is not finite and ordered");
  // Near-cubic cells: the side that gives kMaxCells cells over the box, thin axes one cell deep.
  const glm::vec3 extent = hi - lo;
  const float longest = std::max(extent.x, std::max(extent.y, extent.z));
  const glm::vec3 e = glm::max(extent, glm::vec3(1e-3f * longest));
  const float side = std::cbrt(e.x * e.y * e.z / static_cast<float>(kMaxCells));
  for (int a = 0; a < 3; ++a) dims_[a] = std::clamp(static_cast<int>(extent[a] / side), 1, 256);
  while (static_cast<size_t>(dims_.x) * dims_.y * dims_.z > kMaxCells)
    for (int a = 0; a < 3; ++a) dims_[a] = std::max(1, dims_[a] - 1);
  cells_ = static_cast<size_t>(dims_.x) * dims_.y * dims_.z;
  cell_scale_ = glm::vec3(dims_) / extent;
  sums_ = std::make_unique<std::atomic<Sums*>[]>(region_count());
  for (uint32_t r = 0; r < region_count(); ++r) sums_[r].store(nullptr, std::memory_order_relaxed);
  table_of_.assign(region_count(), -1);
  share_of_.assign(region_count(), 0.0f);
  unit_ = environment_integral(environment) / 16777216.0;
  if (!(unit_ > 0.0) || !std::isfinite(unit_)) unit_ = 1.0;
}

EnvironmentVisibility::~EnvironmentVisibility() {
  for (uint32_t r = 0; r < region_count(); ++r) delete sums_[r].load(std::memory_order_relaxed);
}

uint32_t EnvironmentVisibility::region(const glm::vec3& position, const glm::vec3& normal) const {
  const glm::vec3 c = (position - lo_) * cell_scale_;
  if (!(c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f)) return kNoRegion;  // below the box, or NaN
  const glm::ivec3 cell(c);
  if (cell.x >= dims_.x || cell.y >= dims_.y || cell.z >= dims_.z) return kNoRegion;
  const size_t index = (static_cast<size_t>(cell.z) * dims_.y + cell.y) * dims_.x + cell.x;
  return static_cast<uint32_t>(index * kSides + side_of(normal));
}

VisibleSky EnvironmentVisibility::sky(uint32_t region) const {
  VisibleSky s;
  s.region_ = region;
  if (region >= region_count() || table_of_[region] < 0) return s;
  s.field_ = this;
  s.bins_ = &tables_[static_cast<size_t>(table_of_[region])];
  // The vertex samples the table after its BSDF is set up: start loading the rows' CDF now.
  __builtin_prefetch(s.bins_->row_cdf);
  s.share_ = share_of_[region];
  return s;
}

EnvironmentVisibility::Sums* EnvironmentVisibility::sums_of(uint32_t region) {
  Sums* s = sums_[region].load(std::memory_order_acquire);
  if (s) return s;
  auto fresh = std::make_unique<Sums>();
  if (sums_[region].compare_exchange_strong(s, fresh.get(), std::memory_order_acq_rel)) return fresh.release();
  return s;  // another thread allocated it first
}

float EnvironmentVisibility::learned_share(double visible_fraction) {
  const double t = std::clamp((0.75 - visible_fraction) / 0.5, 0.0, 1.0);
  return static_cast<float>(kMaxLearnedShare * t);
}

void EnvironmentVisibility::record(uint32_t region, const glm::vec3& direction, float luminance_over_pdf,
                                   bool unblocked, bool nee) {
  if (region >= region_count() || !(luminance_over_pdf > 0.0f) || !std::isfinite(luminance_over_pdf)) return;
  const uint64_t steps = static_cast<uint64_t>(std::min(static_cast<double>(luminance_over_pdf) / unit_, kMaxSteps));
  Sums* s = sums_of(region);
  if (nee) s->offered.fetch_add(steps, std::memory_order_relaxed);
  if (!unblocked) return;
  if (nee) s->visible.fetch_add(steps, std::memory_order_relaxed);
  s->records.fetch_add(1, std::memory_order_relaxed);
  if (steps > 0) s->bins[bin_of(equirect_uv(direction), nullptr)].fetch_add(steps, std::memory_order_relaxed);
}

void EnvironmentVisibility::end_frame() {
  ++frames_;
  if (dormant_ || frames_ > kLearningFrames || (frames_ & (frames_ - 1)) != 0) return;
  if (frames_ == kDormantCheckFrame && sees_open_sky()) {
    dormant_ = true;
    table_of_.assign(region_count(), -1);
    share_of_.assign(region_count(), 0.0f);
    tables_.clear();
    return;
  }
  std::vector<float> weights(kBins);
  std::vector<double> sums(kBins);
  for (uint32_t r = 0; r < region_count(); ++r) {
    const Sums* s = sums_[r].load(std::memory_order_relaxed);
    if (!s || s->records.load(std::memory_order_relaxed) < kMinRecords) continue;
    for (int b = 0; b < kBins; ++b) sums[b] = static_cast<double>(s->bins[b].load(std::memory_order_relaxed));
    blur_bins(sums.data(), weights.data());
    double total = 0.0;
    for (float w : weights) total += w;
    if (!(total > 0.0)) continue;
    const uint64_t offered = s->offered.load(std::memory_order_relaxed);
    const double visible = offered > 0 ? static_cast<double>(s->visible.load(std::memory_order_relaxed)) / offered : 0.0;
    const float share = learned_share(visible);
    if (table_of_[r] < 0 && share == 0.0f) continue;  // it would not be sampled
    if (table_of_[r] < 0) {
      table_of_[r] = static_cast<int32_t>(tables_.size());
      tables_.emplace_back();
    }
    tables_[static_cast<size_t>(table_of_[r])] = learned_bins(weights.data(), share);
    share_of_[r] = share;
  }
}

// More than kOpenSkyFraction of all NEE's environment light got through.
bool EnvironmentVisibility::sees_open_sky() const {
  uint64_t offered = 0, visible = 0;
  for (uint32_t r = 0; r < region_count(); ++r)
    if (const Sums* s = sums_[r].load(std::memory_order_relaxed)) {
      offered += s->offered.load(std::memory_order_relaxed);
      visible += s->visible.load(std::memory_order_relaxed);
    }
  return static_cast<double>(visible) > kOpenSkyFraction * static_cast<double>(offered);
}

size_t EnvironmentVisibility::learned_regions() const { return tables_.size(); }

size_t EnvironmentVisibility::memory_bytes() const {
  size_t allocated = 0;
  for (uint32_t r = 0; r < region_count(); ++r)
    if (sums_[r].load(std::memory_order_relaxed)) ++allocated;
  return allocated * sizeof(Sums) + tables_.size() * sizeof(LearnedBins) +
         region_count() * (sizeof(Sums*) + sizeof(int32_t) + sizeof(float));
}

// A bin drawn from the rows' CDF by u.y and the row's by u.x, then uniform inside it on the map.
glm::vec3 VisibleSky::sample(glm::vec2 u, float* pdf, glm::vec2* uv_out) const {
  float tx, ty;
  const int y = find_in_cdf(bins_->row_cdf, LearnedBins::kV, u.y, &ty);
  const int x = find_in_cdf(bins_->cdf[y], LearnedBins::kU, u.x, &tx);
  const glm::vec2 uv((x + tx) / LearnedBins::kU, (y + ty) / LearnedBins::kV);
  const glm::vec3 d = equirect_direction(uv);
  *pdf = solid_angle_density(bins_->pmf(x, y) * EnvironmentVisibility::kBins, d);
  if (uv_out) *uv_out = uv;
  return d;
}

float VisibleSky::pdf(const glm::vec3& direction) const { return density(equirect_uv(direction), direction); }

float VisibleSky::density(glm::vec2 uv, const glm::vec3& direction) const {
  const int bin = bin_of(uv, nullptr);
  const float pmf = bins_->pmf(bin % LearnedBins::kU, bin / LearnedBins::kU);
  return pmf > 0.0f ? solid_angle_density(pmf * EnvironmentVisibility::kBins, direction) : 0.0f;
}

// --- The state file's part: the box and grid (checked against this field's), every region's
// sums and record count, and the sampled distributions' weights (so a resumed render samples
// exactly what the saved one did).
std::vector<uint8_t> EnvironmentVisibility::serialize() const {
  ByteWriter w;
  for (char c : kMagic) w.put(c);
  w.put(kFormatVersion);
  for (int a = 0; a < 3; ++a) w.put(dims_[a]);
  for (int a = 0; a < 3; ++a) w.put(lo_[a]);
  for (int a = 0; a < 3; ++a) w.put(hi_[a]);
  w.put(unit_);
  w.put(frames_);
  w.put(static_cast<uint8_t>(dormant_));
  std::vector<uint32_t> allocated;
  for (uint32_t r = 0; r < region_count(); ++r)
    if (sums_[r].load(std::memory_order_relaxed)) allocated.push_back(r);
  w.put(static_cast<uint64_t>(allocated.size()));
  for (uint32_t r : allocated) {
    const Sums* s = sums_[r].load(std::memory_order_relaxed);
    w.put(r);
    w.put(s->records.load(std::memory_order_relaxed));
    w.put(s->offered.load(std::memory_order_relaxed));
    w.put(s->visible.load(std::memory_order_relaxed));
    for (const auto& b : s->bins) w.put(b.load(std::memory_order_relaxed));
  }
  w.put(static_cast<uint64_t>(tables_.size()));
  for (uint32_t r = 0; r < region_count(); ++r) {  // in region order: the bytes do not depend on threads
    if (table_of_[r] < 0) continue;
    w.put(r);
    w.put(tables_[static_cast<size_t>(table_of_[r])]);
  }
  w.put(fnv1a64(w.bytes.data(), w.bytes.size()));
  return std::move(w.bytes);
}

void EnvironmentVisibility::deserialize(const uint8_t* data, size_t size) {
  bool checksum_ok;
  ByteReader r = open_checksummed(data, size, kMagic, "environment visibility", &checksum_ok);
  if (r.get<uint32_t>("header") != kFormatVersion) throw Error("environment visibility format version is not supported");
  if (!checksum_ok) throw Error("environment visibility is corrupted (checksum mismatch)");
  for (int a = 0; a < 3; ++a)
    if (r.get<int32_t>("grid") != dims_[a]) throw Error("environment visibility was learned on another scene's grid");
  for (const glm::vec3* corner : {&lo_, &hi_})
    for (int a = 0; a < 3; ++a)
      if (r.get<float>("grid") != (*corner)[a]) throw Error("environment visibility was learned on another scene's box");
  if (r.get<double>("header") != unit_) throw Error("environment visibility was learned under another environment");
  const uint64_t frames = r.get<uint64_t>("header");
  const uint8_t dormant = r.get<uint8_t>("header");
  if (dormant > 1) throw Error("environment visibility has an invalid dormant flag");
  std::vector<std::unique_ptr<Sums>> sums(region_count());
  const size_t allocated = r.get_count(sizeof(uint32_t) * 2 + sizeof(uint64_t) * (kBins + 2), "sums");
  for (size_t i = 0; i < allocated; ++i) {
    const uint32_t region = r.get<uint32_t>("sums");
    if (region >= region_count() || sums[region]) throw Error("environment visibility has an invalid region");
    sums[region] = std::make_unique<Sums>();
    sums[region]->records.store(r.get<uint32_t>("sums"), std::memory_order_relaxed);
    sums[region]->offered.store(r.get<uint64_t>("sums"), std::memory_order_relaxed);
    sums[region]->visible.store(r.get<uint64_t>("sums"), std::memory_order_relaxed);
    for (auto& b : sums[region]->bins) b.store(r.get<uint64_t>("sums"), std::memory_order_relaxed);
  }
  std::vector<int32_t> table_of(region_count(), -1);
  std::vector<float> share_of(region_count(), 0.0f);
  std::vector<LearnedBins> tables;
  const size_t count = r.get_count(sizeof(uint32_t) + sizeof(LearnedBins), "distributions");
  for (size_t i = 0; i < count; ++i) {
    const uint32_t region = r.get<uint32_t>("distributions");
    if (region >= region_count() || table_of[region] >= 0) throw Error("environment visibility has an invalid region");
    const LearnedBins b = r.get<LearnedBins>("distributions");
    if (!valid(b)) throw Error("environment visibility has an invalid distribution");
    table_of[region] = static_cast<int32_t>(tables.size());
    share_of[region] = b.share;
    tables.push_back(b);
  }
  if (r.remaining() != 0) throw Error("environment visibility has trailing bytes");
  for (uint32_t region = 0; region < region_count(); ++region)
    delete sums_[region].exchange(sums[region].release(), std::memory_order_relaxed);
  frames_ = frames;
  dormant_ = dormant != 0;
  table_of_ = std::move(table_of);
  share_of_ = std::move(share_of);
  tables_ = std::move(tables);
}

}  // namespace pxf
