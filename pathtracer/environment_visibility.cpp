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
  build_bin_interiors(environment);
}

EnvironmentVisibility::~EnvironmentVisibility() {
  for (uint32_t r = 0; r < region_count(); ++r) delete sums_[r].load(std::memory_order_relaxed);
}

// Each bin's inside: the environment's luminance x sin theta averaged over the texels whose centres
// fall in each of its kSubcells^2 cells (at the cell's centre where none does), and the
// fixed-point unit: 2^-24 of the environment's luminance integrated over the sphere.
void EnvironmentVisibility::build_bin_interiors(const Environment& environment) {
  const Texture& image = environment.image;
  const int width = kBinsU * kSubcells, height = kBinsV * kSubcells;
  std::vector<double> sums(static_cast<size_t>(width) * height, 0.0);
  std::vector<int> counts(sums.size(), 0);
  double integral = 0.0;
  for (int y = 0; y < image.height; ++y) {
    const double sin_theta = std::sin(kPi * (y + 0.5) / image.height);
    for (int x = 0; x < image.width; ++x) {
      const double l = luminance(glm::vec3(image.texels[static_cast<size_t>(y) * image.width + x])) * environment.strength;
      if (!(std::isfinite(l) && l > 0.0)) continue;
      const size_t cx = static_cast<size_t>((2 * x + 1) * static_cast<int64_t>(width) / (2 * image.width));
      const size_t cy = static_cast<size_t>((2 * y + 1) * static_cast<int64_t>(height) / (2 * image.height));
      sums[cy * width + cx] += l * sin_theta;
      ++counts[cy * width + cx];
      integral += l * sin_theta * 2.0 * kPi * kPi / (static_cast<double>(image.width) * image.height);
    }
  }
  unit_ = integral > 0.0 && std::isfinite(integral) ? integral / 16777216.0 : 1.0;
  interiors_.clear();
  interiors_.reserve(kBins);
  std::vector<float> weights(kSubcells * kSubcells);
  for (int bin = 0; bin < kBins; ++bin) {
    const int bx = bin % kBinsU, by = bin / kBinsU;
    for (int j = 0; j < kSubcells; ++j)
      for (int i = 0; i < kSubcells; ++i) {
        const int x = bx * kSubcells + i, y = by * kSubcells + j;
        const size_t c = static_cast<size_t>(y) * width + x;
        double w = counts[c] > 0 ? sums[c] / counts[c] : 0.0;
        if (counts[c] == 0 && !image.texels.empty()) {
          const glm::vec2 uv((x + 0.5f) / width, (y + 0.5f) / height);
          w = luminance(glm::vec3(sample_texture(image, uv))) * environment.strength * std::sin(kPi * uv.y);
        }
        weights[static_cast<size_t>(j) * kSubcells + i] = std::isfinite(w) && w > 0.0 ? static_cast<float>(w) : 0.0f;
      }
    Distribution2D inside(weights, kSubcells, kSubcells);
    if (!inside.valid()) inside = Distribution2D(std::vector<float>(weights.size(), 1.0f), kSubcells, kSubcells);
    interiors_.push_back(std::move(inside));
  }
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
  if (region >= region_count() || table_of_[region] < 0) return s;
  s.field_ = this;
  s.bins_ = &tables_[static_cast<size_t>(table_of_[region])];
  s.region_ = region;
  s.share_ = shares_[static_cast<size_t>(table_of_[region])];
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
  if ((frames_ & (frames_ - 1)) != 0) return;
  std::vector<float> weights(kBins);
  std::vector<double> sums(kBins);
  for (uint32_t r = 0; r < region_count(); ++r) {
    const Sums* s = sums_[r].load(std::memory_order_relaxed);
    if (!s || s->records.load(std::memory_order_relaxed) < kMinRecords) continue;
    for (int b = 0; b < kBins; ++b) sums[b] = static_cast<double>(s->bins[b].load(std::memory_order_relaxed));
    blur_bins(sums.data(), weights.data());
    const Distribution1D built(weights);
    if (!built.valid()) continue;
    // Rebuilt from its own pmf, which is what the state file keeps: a resumed render rebuilds it
    // from the same floats and samples bit for bit what this one does.
    for (int b = 0; b < kBins; ++b) weights[b] = built.pmf(static_cast<size_t>(b));
    const uint64_t offered = s->offered.load(std::memory_order_relaxed);
    const double visible = offered > 0 ? static_cast<double>(s->visible.load(std::memory_order_relaxed)) / offered : 0.0;
    if (table_of_[r] < 0) {
      table_of_[r] = static_cast<int32_t>(tables_.size());
      tables_.emplace_back();
      shares_.push_back(0.0f);
    }
    tables_[static_cast<size_t>(table_of_[r])] = Distribution1D(weights);
    shares_[static_cast<size_t>(table_of_[r])] = learned_share(visible);
  }
}

size_t EnvironmentVisibility::learned_regions() const { return tables_.size(); }

size_t EnvironmentVisibility::memory_bytes() const {
  size_t allocated = 0;
  for (uint32_t r = 0; r < region_count(); ++r)
    if (sums_[r].load(std::memory_order_relaxed)) ++allocated;
  return allocated * sizeof(Sums) + tables_.size() * (2 * kBins + 1) * sizeof(float) +
         region_count() * (sizeof(Sums*) + sizeof(int32_t)) + interiors_.size() * kSubcells * (kSubcells + 2) * 2 * sizeof(float);
}

float EnvironmentVisibility::bin_density(int bin, glm::vec2 local) const { return interiors_[bin].pdf(local); }

glm::vec3 VisibleSky::sample(glm::vec2 u, float* pdf) const {
  float bin_u, bin_pmf;
  const int bin = static_cast<int>(bins_->sample(u.x, &bin_u, &bin_pmf));
  float inside_pdf;
  const glm::vec2 local = field_->interiors_[bin].sample(glm::vec2(bin_u, u.y), &inside_pdf);
  const glm::vec2 uv((bin % EnvironmentVisibility::kBinsU + local.x) / EnvironmentVisibility::kBinsU,
                     (bin / EnvironmentVisibility::kBinsU + local.y) / EnvironmentVisibility::kBinsV);
  const glm::vec3 d = equirect_direction(uv);
  *pdf = solid_angle_density(bin_pmf * inside_pdf * EnvironmentVisibility::kBins, d);
  return d;
}

float VisibleSky::pdf(const glm::vec3& direction) const {
  glm::vec2 local;
  const int bin = bin_of(equirect_uv(direction), &local);
  const float pmf = bins_->pmf(static_cast<size_t>(bin));
  if (!(pmf > 0.0f)) return 0.0f;
  return solid_angle_density(pmf * field_->bin_density(bin, local) * EnvironmentVisibility::kBins, direction);
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
    const Distribution1D& t = tables_[static_cast<size_t>(table_of_[r])];
    w.put(r);
    w.put(shares_[static_cast<size_t>(table_of_[r])]);
    for (int b = 0; b < kBins; ++b) w.put(t.pmf(static_cast<size_t>(b)));
  }
  w.put(fnv1a64(w.bytes.data(), w.bytes.size()));
  return std::move(w.bytes);
}

void EnvironmentVisibility::deserialize(const uint8_t* data, size_t size) {
  if (data == nullptr || size < sizeof(kMagic) + sizeof(uint64_t))
    throw Error("environment visibility truncated (" + std::to_string(size) + " bytes)");
  uint64_t checksum;
  std::memcpy(&checksum, data + size - sizeof checksum, sizeof checksum);
  ByteReader r(data, size - sizeof checksum, "environment visibility");
  for (char c : kMagic)
    if (r.get<char>("header") != c) throw Error("not an environment visibility (bad magic)");
  if (r.get<uint32_t>("header") != kFormatVersion) throw Error("environment visibility format version is not supported");
  if (checksum != fnv1a64(data, size - sizeof checksum)) throw Error("environment visibility is corrupted (checksum mismatch)");
  for (int a = 0; a < 3; ++a)
    if (r.get<int32_t>("grid") != dims_[a]) throw Error("environment visibility was learned on another scene's grid");
  for (const glm::vec3* corner : {&lo_, &hi_})
    for (int a = 0; a < 3; ++a)
      if (r.get<float>("grid") != (*corner)[a]) throw Error("environment visibility was learned on another scene's box");
  if (r.get<double>("header") != unit_) throw Error("environment visibility was learned under another environment");
  const uint64_t frames = r.get<uint64_t>("header");
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
  std::vector<Distribution1D> tables;
  std::vector<float> shares;
  const size_t count = r.get_count(sizeof(uint32_t) + sizeof(float) * (kBins + 1), "distributions");
  std::vector<float> weights(kBins);
  for (size_t i = 0; i < count; ++i) {
    const uint32_t region = r.get<uint32_t>("distributions");
    if (region >= region_count() || table_of[region] >= 0) throw Error("environment visibility has an invalid region");
    const float share = r.get<float>("distributions");
    if (!(share >= 0.0f && share <= kMaxLearnedShare)) throw Error("environment visibility has an invalid share");
    shares.push_back(share);
    for (float& w : weights) w = r.get<float>("distributions");
    Distribution1D table(weights);
    if (!table.valid()) throw Error("environment visibility has an empty distribution");
    table_of[region] = static_cast<int32_t>(tables.size());
    tables.push_back(std::move(table));
  }
  if (r.remaining() != 0) throw Error("environment visibility has trailing bytes");
  for (uint32_t region = 0; region < region_count(); ++region)
    delete sums_[region].exchange(sums[region].release(), std::memory_order_relaxed);
  frames_ = frames;
  table_of_ = std::move(table_of);
  tables_ = std::move(tables);
  shares_ = std::move(shares);
}

}  // namespace pxf
