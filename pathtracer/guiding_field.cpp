#include "pathtracer/guiding_field.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "core/error.h"
#include "pathtracer/byte_io.h"

namespace pxf {

struct GuidingField::RecordBuffers {
  tbb::enumerable_thread_specific<std::vector<GuidingRecord>> per_thread;
};

namespace {

constexpr double kTwoPi = 6.283185307179586476925;
constexpr double kInvFourPi = 0.0795774715459476678844;
constexpr size_t kMaxDirectionalNodes = 65536;  // child indices are 16-bit and 0 is the root
constexpr int kMaxDirectionalDepth = 20;
constexpr int kMaxSpatialDepth = 60;  // 20 halvings per axis: cells of a millionth of the box
constexpr double kBelowOne = 0x1.fffffffffffffp-1;
constexpr float kBelowOneF = 0x1.fffffep-1f;
constexpr char kMagic[8] = {'P', 'X', 'F', 'G', 'U', 'I', 'D', 'E'};
constexpr uint32_t kFormatVersion = 3;
constexpr int kMaxIterations = 1 << 20;

static_assert(sizeof(GuidingSamplingNode) == 24 && sizeof(GuidingBuildingNode) == 40, "the paper's compact nodes");
static_assert(GuidingField::kMinBytes ==
                  sizeof(GuidingSpatialNode) + sizeof(GuidingLeaf) + sizeof(GuidingSamplingNode) + sizeof(GuidingBuildingNode),
              "kMinBytes is one leaf with one node per tree");

// [0,1) for any input, NaN included (to 0): u of a caller, or a remapped u that rounded up to 1.
double unit_interval(double x) { return x >= 0.0 ? std::min(x, kBelowOne) : 0.0; }

// The direction's point on the square, u = (cos theta + 1) / 2, v = phi / 2 pi; false for a zero or
// non-finite direction.
bool square_of(const glm::vec3& d, glm::dvec2* uv) {
  const double x = d.x, y = d.y, z = d.z;
  const double length = std::sqrt(x * x + y * y + z * z);
  if (!(length > 0.0) || !std::isfinite(length)) return false;
  double phi = std::atan2(y, x);
  if (phi < 0.0) phi += kTwoPi;
  *uv = glm::dvec2(unit_interval(0.5 * (z / length + 1.0)), unit_interval(phi / kTwoPi));
  return true;
}

glm::vec3 direction_of(glm::dvec2 uv) {
  const double z = 2.0 * uv.x - 1.0;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = kTwoPi * uv.y;
  return glm::vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
}

template <class T>
double sum4(const T (&v)[4]) {
  return (double(v[0]) + double(v[1])) + (double(v[2]) + double(v[3]));
}

// The density over the square of the tree's distribution at uv: the product over the levels of
// 4 * (the quadrant's share of its node). A node without energy is uniform (factor 1).
double tree_density(const std::vector<GuidingSamplingNode>& tree, glm::dvec2 uv) {
  double density = 1.0;
  size_t node = 0;
  for (;;) {  // ends: every child index is above its parent's (checked when a tree is read)
    const GuidingSamplingNode& n = tree[node];
    const int qx = uv.x >= 0.5, qy = uv.y >= 0.5, q = qx + 2 * qy;
    const double total = sum4(n.share);
    if (total > 0.0) density *= 4.0 * n.share[q] / total;
    uv = glm::dvec2(2.0 * uv.x - qx, 2.0 * uv.y - qy);
    if (n.child[q] == 0) return density;
    node = n.child[q];
  }
}

// 0 with probability p (u < p), 1 otherwise; u is rescaled to [0,1) within the part it fell in.
int pick(double& u, double p) {
  if (u < p) {
    u = unit_interval(u / p);
    return 0;
  }
  u = unit_interval((u - p) / (1.0 - p));
  return 1;
}

// A leaf square of a directional tree.
struct Square {
  glm::dvec2 origin;
  double size;
  bool holds(glm::dvec2 uv) const {
    return uv.x >= origin.x && uv.x < origin.x + size && uv.y >= origin.y && uv.y < origin.y + size;
  }
};

// The paper's warp: at each node the column (x) by u.x, then the row (y) within the column by u.y,
// each u rescaled and reused below, so that strata of u stay together; uniform in the leaf square.
// Picks quadrant q with probability share[q] / total: the density tree_density() gives.
glm::dvec2 sample_tree(const std::vector<GuidingSamplingNode>& tree, glm::dvec2 u, Square* leaf) {
  *leaf = Square{glm::dvec2(0.0), 1.0};
  size_t node = 0;
  for (;;) {
    const GuidingSamplingNode& n = tree[node];
    const double s[4] = {n.share[0], n.share[1], n.share[2], n.share[3]};
    const double total = sum4(n.share);
    int qx, qy;
    if (total > 0.0) {
      qx = pick(u.x, (s[0] + s[2]) / total);
      const double column = s[qx] + s[qx + 2];
      qy = pick(u.y, column > 0.0 ? s[qx] / column : 0.5);
    } else {
      qx = pick(u.x, 0.5);
      qy = pick(u.y, 0.5);
    }
    leaf->size *= 0.5;
    leaf->origin += glm::dvec2(qx, qy) * leaf->size;
    const int q = qx + 2 * qy;
    if (n.child[q] == 0) return leaf->origin + u * leaf->size;
    node = n.child[q];
  }
}

// The float direction of a point near the edge of a small quadrant (2^-20 at the deepest level, a
// few dozen float steps of cos theta near the poles) may map back into the neighbouring quadrant, whose density can
// be orders of magnitude apart: a sample drawn for its high density would be weighted by the low
// one (a firefly). Moving such a point halfway to the quadrant's centre until its direction maps
// back into the quadrant keeps pdf() the density it was drawn with; only slivers about a float step
// wide at the quadrant's edges move, within the quadrant.
glm::vec3 direction_in(glm::dvec2 uv, const Square& leaf) {
  const glm::dvec2 centre = leaf.origin + 0.5 * leaf.size;
  glm::vec3 d = direction_of(uv);
  for (int i = 0; i < 24; ++i) {
    glm::dvec2 back;
    if (square_of(d, &back) && leaf.holds(back)) break;
    uv = 0.5 * (uv + centre);
    d = direction_of(uv);
  }
  return d;
}

// The solid-angle density of the mixture sample() draws from: (1 - a) tree + a uniform.
float direction_pdf(const std::vector<GuidingSamplingNode>& tree, double uniform_fraction, const glm::vec3& direction) {
  glm::dvec2 uv;
  if (!square_of(direction, &uv)) return 0.0f;
  return static_cast<float>(((1.0 - uniform_fraction) * tree_density(tree, uv) + uniform_fraction) * kInvFourPi);
}

void add_energy(std::vector<GuidingBuildingNode>& tree, const GuidingRecord& r) {
  double x = r.u, y = r.v;
  size_t node = 0;
  for (;;) {
    const int qx = x >= 0.5, qy = y >= 0.5, q = qx + 2 * qy;
    tree[node].energy[q] += r.energy;
    x = 2.0 * x - qx;
    y = 2.0 * y - qy;
    if (tree[node].child[q] == 0) return;
    node = tree[node].child[q];
  }
}

// What an iteration collected, as the next one's sampling distribution (the same structure).
std::vector<GuidingSamplingNode> sampling_tree(const std::vector<GuidingBuildingNode>& building, double total) {
  std::vector<GuidingSamplingNode> tree(building.size());
  for (size_t i = 0; i < building.size(); ++i)
    for (int q = 0; q < 4; ++q) {
      tree[i].share[q] = static_cast<float>(building[i].energy[q] / total);
      tree[i].child[q] = building[i].child[q];
    }
  return tree;
}

// The next iteration's collecting structure (Müller et al. 2017, section 3.3): a quadrant is
// subdivided while its share of the leaf's energy exceeds rho, one the collecting tree did not
// subdivide counting a quarter of its parent's energy per child; with no energy at all, quadrant
// shares are their areas (a uniform tree). Breadth-first, so that the node cap trims the deepest level.
std::vector<GuidingBuildingNode> refined_tree(const std::vector<GuidingBuildingNode>& stats, double rho, int max_level) {
  const double total = sum4(stats[0].energy);
  struct Origin {
    int64_t old;    // the node of `stats` over the same square, -1: none (it was a leaf there)
    double energy;  // of the square
    int level;      // of the square: its side is 2^-level
  };
  std::vector<GuidingBuildingNode> tree(1, GuidingBuildingNode{});
  std::vector<Origin> origins{{0, total, 0}};
  for (size_t n = 0; n < tree.size(); ++n) {
    const Origin o = origins[n];
    for (int q = 0; q < 4; ++q) {
      const double energy = o.old >= 0 ? stats[o.old].energy[q] : 0.25 * o.energy;
      const int level = o.level + 1;
      const double fraction = total > 0.0 ? energy / total : std::ldexp(1.0, -2 * level);
      if (level >= max_level || !(fraction > rho) || tree.size() >= kMaxDirectionalNodes) continue;
      const int64_t old_child = o.old >= 0 && stats[o.old].child[q] != 0 ? stats[o.old].child[q] : -1;
      tree[n].child[q] = static_cast<uint16_t>(tree.size());
      tree.push_back(GuidingBuildingNode{});
      origins.push_back({old_child, energy, level});
    }
  }
  tree.shrink_to_fit();  // memory_bytes() counts capacity
  return tree;
}

// The capacity of a leaf's reservoir of records whose light came through delta bounces.
size_t delta_records_capacity(const GuidingSettings& settings) {
  return settings.delta_lobes > 0 ? std::max<size_t>(settings.lobe_records / 2, kMinDeltaLobeRecords) : 0;
}

// What a leaf's lobes and reservoirs may take, counted whether they hold it yet or not (the lobes
// are refitted and the reservoirs fill every iteration).
size_t lobe_reserve_bytes(const GuidingSettings& settings) {
  return settings.parallax_lobes > 0 ? settings.parallax_lobes * sizeof(GuidingLobe) +
                                           (settings.lobe_records + delta_records_capacity(settings)) * sizeof(GuidingLobeRecord)
                                     : 0;
}

size_t leaf_bytes(const GuidingLeaf& leaf, const GuidingSettings& settings) {
  return sizeof(GuidingLeaf) + leaf.sampling.size() * sizeof(GuidingSamplingNode) +
         leaf.building.size() * sizeof(GuidingBuildingNode) + lobe_reserve_bytes(settings);
}

uint32_t float_bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}

// A total order: equal records are identical, so any order of arrival sorts to the same sequence.
bool record_before(const GuidingRecord& a, const GuidingRecord& b) {
  // (leaf, key) decides all but repeated keys; the full tuple is built only for those.
  if (a.leaf != b.leaf) return a.leaf < b.leaf;
  if (a.key != b.key) return a.key < b.key;
  const auto bits = [](const GuidingRecord& r) {
    return std::make_tuple(r.leaf, r.key, float_bits(r.u), float_bits(r.v), float_bits(r.energy), float_bits(r.position.x),
                           float_bits(r.position.y), float_bits(r.position.z), float_bits(r.source.x),
                           float_bits(r.source.y), float_bits(r.source.z), r.kind, float_bits(r.normal.x), float_bits(r.normal.y),
                           float_bits(r.normal.z), r.through_delta);
  };
  return bits(a) < bits(b);
}

bool non_negative_finite(double x) { return x >= 0.0 && std::isfinite(x); }

// Every node but the root is the child of exactly one node with a smaller index, no deeper than
// max_level: a tree, so every descent ends within max_level steps and a refinement visits each node once.
template <class Node>
void check_tree(const std::vector<Node>& tree, int max_level, const char* what) {
  std::vector<uint8_t> referenced(tree.size(), 0);
  std::vector<int> level(tree.size(), 0);
  for (size_t n = 0; n < tree.size(); ++n)
    for (int q = 0; q < 4; ++q) {
      const size_t c = tree[n].child[q];
      if (c == 0) continue;
      if (c <= n || c >= tree.size() || referenced[c])
        throw Error(std::string("guiding field has an invalid child index in a ") + what + " tree");
      referenced[c] = 1;
      level[c] = level[n] + 1;
      if (level[c] >= max_level) throw Error(std::string("guiding field has a ") + what + " tree deeper than its limit");
    }
  for (size_t n = 1; n < tree.size(); ++n)
    if (!referenced[n]) throw Error(std::string("guiding field has an unreachable node in a ") + what + " tree");
}

template <class Node>
void put_tree(ByteWriter& w, const std::vector<Node>& tree) {
  w.put(static_cast<uint64_t>(tree.size()));
  for (const Node& n : tree) {
    for (int q = 0; q < 4; ++q) w.put(n.child[q]);
    if constexpr (std::is_same_v<Node, GuidingSamplingNode>) {
      for (int q = 0; q < 4; ++q) w.put(n.share[q]);
    } else {
      for (int q = 0; q < 4; ++q) w.put(n.energy[q]);
    }
  }
}

template <class Node>
std::vector<Node> get_tree(ByteReader& r, int max_level, const char* what) {
  const size_t count = r.get_count(sizeof(Node), what);
  if (count == 0 || count > kMaxDirectionalNodes)
    throw Error(std::string("guiding field has a ") + what + " tree of " + std::to_string(count) + " nodes");
  std::vector<Node> tree(count);
  for (Node& n : tree) {
    for (int q = 0; q < 4; ++q) n.child[q] = r.get<uint16_t>(what);
    for (int q = 0; q < 4; ++q) {
      double value;
      if constexpr (std::is_same_v<Node, GuidingSamplingNode>) {
        value = n.share[q] = r.get<float>(what);
      } else {
        value = n.energy[q] = r.get<double>(what);
      }
      if (!non_negative_finite(value)) throw Error(std::string("guiding field has an invalid value in a ") + what + " tree");
    }
  }
  check_tree(tree, max_level, what);
  return tree;
}

void put_vec3(ByteWriter& w, const glm::vec3& v) {
  for (int a = 0; a < 3; ++a) w.put(v[a]);
}

glm::vec3 get_vec3(ByteReader& r, const char* what) {
  glm::vec3 v;
  for (int a = 0; a < 3; ++a) {
    v[a] = r.get<float>(what);
    if (!std::isfinite(v[a])) throw Error(std::string("guiding field has a non-finite point in its ") + what);
  }
  return v;
}

// Where a record (GuidingRecord or GuidingLobeRecord) arrived and where its light came from: the
// fields both kinds of record share, in the order both write them.
template <class Record>
void put_arrival(ByteWriter& w, const Record& rec) {
  put_vec3(w, rec.position);
  put_vec3(w, rec.source);
  w.put(rec.kind);
  put_vec3(w, rec.normal);
}

template <class Record>
void get_arrival(ByteReader& r, const char* what, Record* rec) {
  rec->position = get_vec3(r, what);
  rec->source = get_vec3(r, what);
  rec->kind = r.get<uint32_t>(what);
  rec->normal = get_vec3(r, what);
  if (rec->kind > kSourceAhead) throw Error(std::string("guiding field has an invalid source kind in its ") + what);
}

// A reservoir in key order: the bytes do not depend on arrival.
void put_reservoir(ByteWriter& w, const std::vector<GuidingLobeRecord>& unordered) {
  std::vector<GuidingLobeRecord> reservoir = unordered;
  std::sort(reservoir.begin(), reservoir.end(), [](const auto& a, const auto& b) { return a.key < b.key; });
  w.put(static_cast<uint64_t>(reservoir.size()));
  for (const GuidingLobeRecord& rec : reservoir) {
    w.put(rec.key);
    w.put(rec.priority);
    put_arrival(w, rec);
  }
}

std::vector<GuidingLobeRecord> get_reservoir(ByteReader& r, size_t capacity) {
  const size_t records = r.get_count(52, "lobe records");  // the bytes put_reservoir writes per record
  if (records > capacity) throw Error("guiding field has more lobe records than its settings allow");
  std::vector<GuidingLobeRecord> reservoir(records);
  for (GuidingLobeRecord& rec : reservoir) {
    rec.key = r.get<uint64_t>("lobe records");
    rec.priority = r.get<float>("lobe records");
    get_arrival(r, "lobe records", &rec);
    if (!(rec.priority <= 0.0f)) throw Error("guiding field has an invalid lobe record");
  }
  return reservoir;
}

void put_lobes(ByteWriter& w, const GuidingLeaf& leaf) {
  w.put(static_cast<uint64_t>(leaf.lobes.size()));
  for (const GuidingLobe& lobe : leaf.lobes) {
    put_vec3(w, lobe.direction);
    put_vec3(w, lobe.source);
    w.put(lobe.distance);
    w.put(lobe.kappa);
    w.put(lobe.share);
  }
  w.put(leaf.alpha);
  put_reservoir(w, leaf.reservoir);
  put_reservoir(w, leaf.delta_reservoir);
  w.put(leaf.energy);
  w.put(leaf.delta_energy);
}

void get_lobes(ByteReader& r, const GuidingSettings& settings, GuidingLeaf* leaf) {
  const size_t count = r.get_count(sizeof(GuidingLobe), "lobes");
  if (count > size_t(settings.parallax_lobes)) throw Error("guiding field has more lobes than its settings allow");
  leaf->lobes.resize(count);
  float total_share = 0.0f;
  for (GuidingLobe& lobe : leaf->lobes) {
    lobe.direction = get_vec3(r, "lobes");
    lobe.source = get_vec3(r, "lobes");
    lobe.distance = r.get<float>("lobes");
    lobe.kappa = r.get<float>("lobes");
    lobe.share = r.get<float>("lobes");
    if (std::abs(glm::length(lobe.direction) - 1.0f) > 1e-3f || !std::isfinite(lobe.distance) ||
        !(lobe.kappa > 0.0f && lobe.kappa <= kMaxLobeKappa) || !(lobe.share >= 0.0f && lobe.share <= 1.0f))
      throw Error("guiding field has an invalid lobe");
    total_share += lobe.share;
  }
  if (!(total_share <= 1.001f)) throw Error("guiding field has lobes whose shares add up to more than 1");
  leaf->alpha = r.get<float>("lobes");
  if (!(leaf->alpha >= 0.0f && leaf->alpha <= 1.0f)) throw Error("guiding field has an invalid guided share");
  leaf->reservoir = get_reservoir(r, settings.parallax_lobes > 0 ? settings.lobe_records : 0);
  leaf->delta_reservoir = get_reservoir(r, settings.parallax_lobes > 0 ? delta_records_capacity(settings) : 0);
  leaf->energy = r.get<double>("lobes");
  leaf->delta_energy = r.get<double>("lobes");
  if (!non_negative_finite(leaf->energy) || !non_negative_finite(leaf->delta_energy) ||
      leaf->delta_energy > leaf->energy)
    throw Error("guiding field has an invalid leaf energy");
}

}  // namespace

GuidingField::GuidingField() : buffers_(std::make_unique<RecordBuffers>()) {}

GuidingField::GuidingField(glm::vec3 lo, glm::vec3 hi, const GuidingSettings& settings) : GuidingField() {
  settings_ = settings;
  validate_settings();
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || !(lo[a] <= hi[a]))
      throw Error("guiding field box is not finite or has lo above hi");
  // A cube around the box: the cyclic halving then gives near-cubic cells, whatever the box's shape.
  const glm::vec3 extent = hi - lo;
  float side = std::max(extent.x, std::max(extent.y, extent.z));
  if (!(side > 0.0f)) side = 1.0f;
  const glm::vec3 centre = 0.5f * lo + 0.5f * hi;
  box_lo_ = centre - 0.5f * side;
  box_hi_ = centre + 0.5f * side;
  if (!std::isfinite(side) || !(box_lo_.x < box_hi_.x && box_lo_.y < box_hi_.y && box_lo_.z < box_hi_.z))
    throw Error("guiding field box is too large or too small for floats");
  nodes_.assign(1, GuidingSpatialNode{});
  leaves_.resize(1);
  leaves_[0].sampling.assign(1, GuidingSamplingNode{});  // no energy: uniform
  leaves_[0].building.assign(1, GuidingBuildingNode{});
  refine_directions();  // the uniform collecting tree of the first iteration
}

GuidingField::~GuidingField() = default;
GuidingField::GuidingField(GuidingField&&) noexcept = default;
GuidingField& GuidingField::operator=(GuidingField&&) noexcept = default;

void GuidingField::validate_settings() const {
  const GuidingSettings& s = settings_;
  if (!(s.spatial_threshold > 0.0f) || !std::isfinite(s.spatial_threshold))
    throw Error("guiding field spatial threshold must be positive");
  if (!(s.energy_threshold > 0.0f && s.energy_threshold <= 1.0f))
    throw Error("guiding field energy threshold must be in (0, 1]");
  if (s.max_directional_depth < 1 || s.max_directional_depth > kMaxDirectionalDepth)
    throw Error("guiding field directional depth must be in 1.." + std::to_string(kMaxDirectionalDepth));
  if (s.delta_lobes < 0 || (s.parallax_lobes > 0 ? s.delta_lobes >= s.parallax_lobes : s.delta_lobes != 0))
    throw Error("guiding field delta lobes must be below its parallax lobes (0 without lobes)");
  if (s.max_bytes < kMinBytes + lobe_reserve_bytes(s))
    throw Error("guiding field memory bound " + std::to_string(s.max_bytes) + " is below the minimum " +
                std::to_string(kMinBytes + lobe_reserve_bytes(s)));
  if (!(s.uniform_fraction > 0.0f && s.uniform_fraction < 1.0f))
    throw Error("guiding field uniform fraction must be in (0, 1)");
  if (!(s.min_lobe_kappa >= 0.0f && s.min_lobe_kappa <= kMaxLobeKappa))
    throw Error("guiding field minimum lobe kappa must be in [0, " + std::to_string(int(kMaxLobeKappa)) + "]");
  if (s.parallax_lobes < 0 || s.parallax_lobes > kMaxGuidingLobes)
    throw Error("guiding field lobe count must be in 0.." + std::to_string(kMaxGuidingLobes));
  if (s.parallax_lobes > 0 && (s.lobe_records < kMinLobeRecords || s.lobe_records > (1u << 20)))
    throw Error("guiding field lobe records must be in " + std::to_string(kMinLobeRecords) + ".." +
                std::to_string(1u << 20));
}

uint32_t GuidingField::find_leaf(const glm::vec3& position, Box* leaf_box) const {
  Box box{box_lo_, box_hi_};
  uint32_t node = 0;
  // A point outside the box (or a NaN coordinate) takes the side it is on (the upper one for NaN),
  // so it lands in the leaf nearest to it.
  for (int axis = 0; nodes_[node].children != 0; axis = axis == 2 ? 0 : axis + 1) {
    const float mid = 0.5f * (box.lo[axis] + box.hi[axis]);
    if (position[axis] < mid) {
      node = nodes_[node].children;
      box.hi[axis] = mid;
    } else {
      node = nodes_[node].children + 1;
      box.lo[axis] = mid;
    }
  }
  if (leaf_box) *leaf_box = box;
  return nodes_[node].leaf;
}

GuidingField::Box GuidingField::leaf_box(const glm::vec3& position) const {
  Box box;
  find_leaf(position, &box);
  return box;
}

void GuidingField::record(uint64_t key, const glm::vec3& position, const glm::vec3& direction, float radiance,
                          float weight, float distance, const glm::vec3& normal, bool through_delta) {
  if (!(radiance >= 0.0f) || !(weight >= 0.0f) || !std::isfinite(radiance) || !std::isfinite(weight)) return;
  if (!std::isfinite(position.x) || !std::isfinite(position.y) || !std::isfinite(position.z)) return;
  glm::dvec2 uv;
  if (!square_of(direction, &uv)) return;
  const float energy = static_cast<float>(std::min(double(radiance) * double(weight), double(FLT_MAX)));
  // float(uv) may round up to 1: kept below, the square's half-open range.
  const float u = std::min(static_cast<float>(uv.x), kBelowOneF), v = std::min(static_cast<float>(uv.y), kBelowOneF);
  const glm::vec3 unit = glm::vec3(direction_of(uv));
  Box box;
  const uint32_t leaf = find_leaf(position, &box);
  // A focus ahead of the record nearer than its leaf is wide (a lens's caustic on the surface it
  // converges to) moves with the receiving point: from elsewhere in the leaf it lies in another
  // direction altogether, so only the light's direction is kept.
  const bool near_focus = distance < 0.0f && -distance < glm::length(box.hi - box.lo);
  const bool at_infinity = distance == 0.0f || !std::isfinite(distance) || near_focus;
  const glm::vec3 source = at_infinity ? unit : position + distance * glm::normalize(direction);
  if (!std::isfinite(source.x) || !std::isfinite(source.y) || !std::isfinite(source.z)) return;
  const uint32_t kind = at_infinity ? kSourceAtInfinity : distance > 0.0f ? kSourceBehind : kSourceAhead;
  const float normal_length = glm::length(normal);
  const glm::vec3 unit_normal = normal_length > 0.0f && std::isfinite(normal_length) ? normal / normal_length : glm::vec3(0.0f);
  buffers_->per_thread.local().push_back(
      {key, leaf, u, v, energy, position, source, kind, unit_normal, through_delta && settings_.delta_lobes > 0 ? 1u : 0u});
}

size_t GuidingField::pending_records() const {
  size_t count = pending_.size();
  for (const std::vector<GuidingRecord>& buffer : buffers_->per_thread) count += buffer.size();
  return count;
}

std::vector<GuidingRecord> GuidingField::sorted_pending() const {
  std::vector<GuidingRecord> records = pending_;
  for (const std::vector<GuidingRecord>& buffer : buffers_->per_thread)
    records.insert(records.end(), buffer.begin(), buffer.end());
  tbb::parallel_sort(records.begin(), records.end(), record_before);
  return records;
}

void GuidingField::apply_records() {
  for (std::vector<GuidingRecord>& buffer : buffers_->per_thread) {
    pending_.insert(pending_.end(), buffer.begin(), buffer.end());
    buffer.clear();  // its capacity stays for the next frame's records
  }
  if (pending_.empty()) return;
  tbb::parallel_sort(pending_.begin(), pending_.end(), record_before);
  // The records of a leaf are contiguous now, in key order: leaves can take theirs in parallel.
  std::vector<size_t> starts;
  for (size_t i = 0; i < pending_.size(); ++i)
    if (i == 0 || pending_[i].leaf != pending_[i - 1].leaf) starts.push_back(i);
  starts.push_back(pending_.size());
  tbb::parallel_for(size_t(0), starts.size() - 1, [&](size_t group) {
    GuidingLeaf& leaf = leaves_[pending_[starts[group]].leaf];
    leaf.records += starts[group + 1] - starts[group];
    for (size_t i = starts[group]; i < starts[group + 1]; ++i) add_energy(leaf.building, pending_[i]);
    if (settings_.parallax_lobes > 0) {
      std::vector<GuidingLobeRecord> incoming, incoming_delta;
      for (size_t i = starts[group]; i < starts[group + 1]; ++i) {
        const GuidingRecord& r = pending_[i];
        if (!(r.energy > 0.0f)) continue;
        (r.through_delta ? incoming_delta : incoming)
            .push_back({r.key, lobe_record_priority(r.key, r.energy), r.position, r.source, r.kind, r.normal});
        leaf.energy += r.energy;
        if (r.through_delta) leaf.delta_energy += r.energy;
      }
      merge_into_reservoir(leaf.reservoir, incoming, settings_.lobe_records);
      if (!incoming_delta.empty()) merge_into_reservoir(leaf.delta_reservoir, incoming_delta, delta_records_capacity(settings_));
    }
  });
  std::vector<GuidingRecord>().swap(pending_);
}

// The lobes of the next iteration from this one's reservoirs, and the guided share the lobes of this
// one earn on records they were not fitted to.
void GuidingField::end_lobe_iteration(GuidingLeaf& leaf) const {
  // Each reservoir is an energy-weighted sample of its own kind of light, so a record stands for its
  // kind's energy over its reservoir's size. Without delta records (or delta_lobes = 0) the one
  // reservoir's records weigh alike and its lobes take every share.
  const double delta_share = leaf.energy > 0.0 ? leaf.delta_energy / leaf.energy : 0.0;
  std::vector<GuidingLobeRecord> records = leaf.reservoir;
  std::vector<double> weights;
  if (!leaf.delta_reservoir.empty()) {
    records.insert(records.end(), leaf.delta_reservoir.begin(), leaf.delta_reservoir.end());
    weights.assign(leaf.reservoir.size(), (1.0 - delta_share) / double(leaf.reservoir.size()));
    weights.resize(records.size(), delta_share / double(leaf.delta_reservoir.size()));
  }
  if (!leaf.lobes.empty())  // judged on records the lobes were not fitted to
    leaf.alpha = best_guided_share(leaf.lobes, records, settings_.uniform_fraction, settings_.min_lobe_kappa, leaf.alpha,
                                   weights);
  std::vector<GuidingLobe> lobes = fit_guiding_lobes(leaf.reservoir, settings_.parallax_lobes - settings_.delta_lobes);
  std::vector<GuidingLobe> delta = fit_guiding_lobes(leaf.delta_reservoir, settings_.delta_lobes, kMinDeltaLobeRecords);
  for (GuidingLobe& lobe : lobes) lobe.share *= static_cast<float>(1.0 - delta_share);
  for (GuidingLobe& lobe : delta) lobe.share *= static_cast<float>(delta_share);
  lobes.insert(lobes.end(), delta.begin(), delta.end());
  if (!lobes.empty()) leaf.lobes = std::move(lobes);  // too few records: the leaf keeps what it knew
  leaf.reservoir.clear();
  leaf.delta_reservoir.clear();
  leaf.energy = leaf.delta_energy = 0.0;
}

void GuidingField::end_iteration() {
  apply_records();
  for (GuidingLeaf& leaf : leaves_) {
    const double total = sum4(leaf.building[0].energy);
    // A leaf that received no energy this time (dark, or rarely reached) keeps what it knew.
    if (total > 0.0) leaf.sampling = sampling_tree(leaf.building, total);
  }
  if (settings_.parallax_lobes > 0) {
    tbb::parallel_for(size_t(0), leaves_.size(), [&](size_t i) { end_lobe_iteration(leaves_[i]); });
  }
  refine_directions();
  split_leaves(double(settings_.spatial_threshold) * std::pow(2.0, 0.5 * iteration_));
  for (GuidingLeaf& leaf : leaves_) leaf.records = 0;
  if (iteration_ < kMaxIterations) ++iteration_;
}

// New, empty collecting trees from the statistics in the building trees. If they do not fit beside
// the sampling trees, rho doubles until they do; at rho >= 1 each is one node, which always fits:
// a leaf's sampling tree is its last collecting tree (24 bytes a node where that took 40) or the one
// it kept, so with one-node collecting trees no leaf takes more than it did before.
void GuidingField::refine_directions() {
  size_t fixed = nodes_.size() * sizeof(GuidingSpatialNode) +
                 leaves_.size() * (sizeof(GuidingLeaf) + lobe_reserve_bytes(settings_));
  for (const GuidingLeaf& leaf : leaves_) fixed += leaf.sampling.size() * sizeof(GuidingSamplingNode);
  std::vector<std::vector<GuidingBuildingNode>> refined(leaves_.size());
  for (double rho = settings_.energy_threshold;; rho *= 2.0) {
    tbb::parallel_for(size_t(0), leaves_.size(), [&](size_t i) {
      refined[i] = rho < 1.0 ? refined_tree(leaves_[i].building, rho, settings_.max_directional_depth)
                             : std::vector<GuidingBuildingNode>(1, GuidingBuildingNode{});
    });
    size_t bytes = fixed;
    for (const auto& tree : refined) bytes += tree.size() * sizeof(GuidingBuildingNode);
    if (bytes <= settings_.max_bytes || rho >= 1.0) break;
  }
  for (size_t i = 0; i < leaves_.size(); ++i) leaves_[i].building = std::move(refined[i]);
}

size_t GuidingField::planned_bytes() const {
  size_t bytes = nodes_.size() * sizeof(GuidingSpatialNode);
  for (const GuidingLeaf& leaf : leaves_) bytes += leaf_bytes(leaf, settings_);
  return bytes;
}

// Splits the leaves with more records than the threshold at their midpoint along the next axis;
// both halves copy the leaf's trees and take half its records (the paper's estimate: where in the
// leaf the records fell is not kept), and split again while that is above the threshold.
// Breadth-first while the memory bound allows, so that a tight bound refines everywhere a little.
void GuidingField::split_leaves(double threshold) {
  std::vector<int> depth(nodes_.size(), 0);
  for (size_t n = 0; n < nodes_.size(); ++n)
    if (nodes_[n].children != 0) depth[nodes_[n].children] = depth[nodes_[n].children + 1] = depth[n] + 1;
  std::vector<std::pair<uint32_t, int>> queue;  // spatial node, its depth
  for (size_t n = 0; n < nodes_.size(); ++n)
    if (nodes_[n].children == 0 && double(leaves_[nodes_[n].leaf].records) > threshold)
      queue.emplace_back(static_cast<uint32_t>(n), depth[n]);
  size_t bytes = planned_bytes();
  for (size_t head = 0; head < queue.size(); ++head) {
    const auto [node, node_depth] = queue[head];
    const uint32_t lower_leaf = nodes_[node].leaf;
    const size_t cost = 2 * sizeof(GuidingSpatialNode) + leaf_bytes(leaves_[lower_leaf], settings_);
    if (node_depth >= kMaxSpatialDepth || bytes + cost > settings_.max_bytes || nodes_.size() + 2 > UINT32_MAX) continue;
    bytes += cost;
    const uint32_t first = static_cast<uint32_t>(nodes_.size()), upper_leaf = static_cast<uint32_t>(leaves_.size());
    leaves_[lower_leaf].records /= 2;
    GuidingLeaf upper = leaves_[lower_leaf];  // vector copies allocate exactly their size
    leaves_.push_back(std::move(upper));
    nodes_[node] = GuidingSpatialNode{first, 0};
    nodes_.push_back(GuidingSpatialNode{0, lower_leaf});
    nodes_.push_back(GuidingSpatialNode{0, upper_leaf});
    if (double(leaves_[lower_leaf].records) > threshold) {
      queue.emplace_back(first, node_depth + 1);
      queue.emplace_back(first + 1, node_depth + 1);
    }
  }
  nodes_.shrink_to_fit();
  leaves_.shrink_to_fit();
}

GuidingField::Distribution GuidingField::distribution(const glm::vec3& position, const glm::vec3& normal) const {
  const GuidingLeaf& leaf = leaves_[find_leaf(position)];
  if (settings_.parallax_lobes > 0) {
    if (leaf.alpha == 0.0f) return Distribution(LobeMixture(), 0.0f);  // learned not to guide: not learned()
    return Distribution(LobeMixture(leaf.lobes, position, settings_.uniform_fraction, normal, settings_.min_lobe_kappa),
                        leaf.alpha);
  }
  return Distribution(leaf.sampling, settings_.uniform_fraction, leaf.alpha);
}

glm::vec3 GuidingField::Distribution::sample(glm::vec2 u, float* pdf_out) const {
  if (use_lobes_) return lobes_.sample(u, pdf_out);
  glm::dvec2 w(unit_interval(u.x), unit_interval(u.y));
  const double uniform = uniform_fraction_;
  glm::vec3 direction;
  if (w.x < uniform) {
    direction = direction_of(glm::dvec2(unit_interval(w.x / uniform), w.y));
  } else {
    w.x = unit_interval((w.x - uniform) / (1.0 - uniform));
    Square square;
    const glm::dvec2 uv = sample_tree(*tree_, w, &square);
    direction = direction_in(uv, square);
  }
  // pdf() of the direction, not a density carried down the descent: the two could differ in the
  // last bits, and MIS weights of the same direction must agree whichever technique drew it.
  if (pdf_out) *pdf_out = pdf(direction);
  return direction;
}

bool GuidingField::Distribution::learned() const {
  return use_lobes_ ? !lobes_.empty() : tree_ && sum4((*tree_)[0].share) > 0.0;
}

float GuidingField::Distribution::pdf(const glm::vec3& direction) const {
  return use_lobes_ ? lobes_.pdf(direction) : direction_pdf(*tree_, uniform_fraction_, direction);
}

size_t GuidingField::memory_bytes() const {
  size_t bytes = nodes_.capacity() * sizeof(GuidingSpatialNode) + leaves_.capacity() * sizeof(GuidingLeaf);
  for (const GuidingLeaf& leaf : leaves_)
    bytes += leaf.sampling.capacity() * sizeof(GuidingSamplingNode) + leaf.building.capacity() * sizeof(GuidingBuildingNode) +
             std::max(leaf.lobes.capacity() * sizeof(GuidingLobe) + leaf.reservoir.capacity() * sizeof(GuidingLobeRecord),
                      lobe_reserve_bytes(settings_));
  return bytes;
}

GuidingField::Stats GuidingField::stats() const {
  Stats s;
  s.spatial_leaves = leaves_.size();
  for (const GuidingLeaf& leaf : leaves_) {
    s.sampling_nodes += leaf.sampling.size();
    s.building_nodes += leaf.building.size();
    std::vector<int> level(leaf.sampling.size(), 0);  // of the node's square
    for (size_t n = 0; n < leaf.sampling.size(); ++n) {
      s.max_sampling_level = std::max(s.max_sampling_level, level[n] + 1);  // its quadrants
      for (int q = 0; q < 4; ++q)
        if (leaf.sampling[n].child[q] != 0) level[leaf.sampling[n].child[q]] = level[n] + 1;
    }
  }
  return s;
}

std::vector<uint8_t> GuidingField::serialize() const {
  ByteWriter w;
  for (char c : kMagic) w.put(c);
  w.put(kFormatVersion);
  w.put(settings_.spatial_threshold);
  w.put(settings_.energy_threshold);
  w.put(static_cast<int32_t>(settings_.max_directional_depth));
  w.put(settings_.max_bytes);
  w.put(settings_.uniform_fraction);
  w.put(static_cast<int32_t>(settings_.parallax_lobes));
  w.put(settings_.lobe_records);
  w.put(settings_.min_lobe_kappa);
  w.put(static_cast<int32_t>(settings_.delta_lobes));
  for (int a = 0; a < 3; ++a) w.put(box_lo_[a]);
  for (int a = 0; a < 3; ++a) w.put(box_hi_[a]);
  w.put(static_cast<int32_t>(iteration_));
  w.put(static_cast<uint64_t>(nodes_.size()));
  for (const GuidingSpatialNode& n : nodes_) {
    w.put(n.children);
    w.put(n.leaf);
  }
  w.put(static_cast<uint64_t>(leaves_.size()));
  for (const GuidingLeaf& leaf : leaves_) {
    w.put(leaf.records);
    put_tree(w, leaf.sampling);
    put_tree(w, leaf.building);
    put_lobes(w, leaf);
  }
  const std::vector<GuidingRecord> records = sorted_pending();  // sorted: the bytes do not depend on threads
  w.put(static_cast<uint64_t>(records.size()));
  for (const GuidingRecord& r : records) {
    w.put(r.key);
    w.put(r.leaf);
    w.put(r.u);
    w.put(r.v);
    w.put(r.energy);
    put_arrival(w, r);
    w.put(r.through_delta);
  }
  w.put(fnv1a64(w.bytes.data(), w.bytes.size()));
  return std::move(w.bytes);
}

GuidingField GuidingField::deserialize(const uint8_t* data, size_t size) {
  bool checksum_ok;
  ByteReader r = open_checksummed(data, size, kMagic, "guiding field", &checksum_ok);
  const uint32_t version = r.get<uint32_t>("header");
  if (version != kFormatVersion)
    throw Error("guiding field format version " + std::to_string(version) + " is not supported (expected " +
                std::to_string(kFormatVersion) + ")");
  if (!checksum_ok) throw Error("guiding field is corrupted (checksum mismatch)");

  GuidingField f;
  f.settings_.spatial_threshold = r.get<float>("settings");
  f.settings_.energy_threshold = r.get<float>("settings");
  f.settings_.max_directional_depth = r.get<int32_t>("settings");
  f.settings_.max_bytes = r.get<uint64_t>("settings");
  f.settings_.uniform_fraction = r.get<float>("settings");
  f.settings_.parallax_lobes = r.get<int32_t>("settings");
  f.settings_.lobe_records = r.get<uint32_t>("settings");
  f.settings_.min_lobe_kappa = r.get<float>("settings");
  f.settings_.delta_lobes = r.get<int32_t>("settings");
  f.validate_settings();
  for (int a = 0; a < 3; ++a) f.box_lo_[a] = r.get<float>("box");
  for (int a = 0; a < 3; ++a) f.box_hi_[a] = r.get<float>("box");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(f.box_lo_[a]) || !std::isfinite(f.box_hi_[a]) || !(f.box_lo_[a] < f.box_hi_[a]))
      throw Error("guiding field has an invalid box");
  f.iteration_ = r.get<int32_t>("header");
  if (f.iteration_ < 0 || f.iteration_ > kMaxIterations)
    throw Error("guiding field has an invalid iteration " + std::to_string(f.iteration_));

  f.nodes_.resize(r.get_count(sizeof(GuidingSpatialNode), "spatial tree"));
  for (GuidingSpatialNode& n : f.nodes_) {
    n.children = r.get<uint32_t>("spatial tree");
    n.leaf = r.get<uint32_t>("spatial tree");
  }
  const size_t leaf_count = r.get_count(3 * sizeof(uint64_t), "leaves");
  if (f.nodes_.empty() || leaf_count == 0) throw Error("guiding field has no spatial tree");
  // Every node but the root is one child of one node with a smaller index, every leaf node owns one
  // leaf of its own: a tree whose descents end.
  std::vector<uint8_t> node_seen(f.nodes_.size(), 0), leaf_seen(leaf_count, 0);
  std::vector<int> depth(f.nodes_.size(), 0);
  for (size_t n = 0; n < f.nodes_.size(); ++n) {
    const GuidingSpatialNode& node = f.nodes_[n];
    if (node.children == 0) {
      if (node.leaf >= leaf_count || leaf_seen[node.leaf]) throw Error("guiding field has an invalid leaf index");
      leaf_seen[node.leaf] = 1;
      continue;
    }
    if (node.leaf != 0 || node.children <= n || node.children >= f.nodes_.size() - 1 || node_seen[node.children] ||
        node_seen[node.children + 1])
      throw Error("guiding field has an invalid spatial child index");
    node_seen[node.children] = node_seen[node.children + 1] = 1;
    depth[node.children] = depth[node.children + 1] = depth[n] + 1;
    if (depth[n] + 1 > kMaxSpatialDepth) throw Error("guiding field has a spatial tree deeper than its limit");
  }
  for (size_t n = 1; n < f.nodes_.size(); ++n)
    if (!node_seen[n]) throw Error("guiding field has an unreachable spatial node");
  for (uint8_t seen : leaf_seen)
    if (!seen) throw Error("guiding field has a leaf no spatial node owns");

  f.leaves_.resize(leaf_count);
  for (GuidingLeaf& leaf : f.leaves_) {
    leaf.records = r.get<uint64_t>("leaves");
    leaf.sampling = get_tree<GuidingSamplingNode>(r, f.settings_.max_directional_depth, "sampling");
    leaf.building = get_tree<GuidingBuildingNode>(r, f.settings_.max_directional_depth, "building");
    get_lobes(r, f.settings_, &leaf);
  }
  f.pending_.resize(r.get_count(68, "records"));  // the bytes serialize() writes per record
  for (GuidingRecord& rec : f.pending_) {
    rec.key = r.get<uint64_t>("records");
    rec.leaf = r.get<uint32_t>("records");
    rec.u = r.get<float>("records");
    rec.v = r.get<float>("records");
    rec.energy = r.get<float>("records");
    get_arrival(r, "records", &rec);
    rec.through_delta = r.get<uint32_t>("records");
    if (rec.through_delta > (f.settings_.delta_lobes > 0 ? 1u : 0u)) throw Error("guiding field has an invalid record");
    if (rec.leaf >= leaf_count || !(rec.u >= 0.0f && rec.u < 1.0f) || !(rec.v >= 0.0f && rec.v < 1.0f) ||
        !non_negative_finite(rec.energy))
      throw Error("guiding field has an invalid record");
  }
  if (r.remaining() != 0) throw Error("guiding field has " + std::to_string(r.remaining()) + " trailing bytes");
  if (f.memory_bytes() > f.settings_.max_bytes) throw Error("guiding field exceeds its own memory bound");
  return f;
}

}  // namespace pxf
