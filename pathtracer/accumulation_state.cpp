#include "pathtracer/accumulation_state.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unistd.h>

#include "image/input_file.h"
#include "pathtracer/byte_io.h"
#include "pathtracer/guiding_field.h"
#include "scene/load.h"

namespace pxf {

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be three packed floats");

namespace {

constexpr char kMagic[8] = {'P', 'X', 'F', 'S', 'T', 'A', 'T', 'E'};
constexpr uint32_t kMaxSide = 1u << 15;     // a bound that keeps a corrupt header from allocating
constexpr uint32_t kMaxFrameRanges = 1u << 20;
constexpr uint32_t kMaxReplicates = 64;       // --replicates' bound
// A serialized guiding field: its trees are bounded by GuidingSettings::max_bytes (16 MiB by
// default) and its pending records are flushed after every frame, so this is far beyond any pxf writes.
constexpr uint64_t kMaxGuidingFieldBytes = uint64_t(1) << 30;
// A serialized EnvironmentVisibility: at most about 4 KiB for each of its 24576 regions.
constexpr uint64_t kMaxEnvironmentVisibilityBytes = uint64_t(1) << 28;

bool little_endian() {
  const uint16_t one = 1;
  uint8_t first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// The per-pixel arrays of an Accumulation, in file order, with their elements per pixel. A new
// field of Accumulation is one line here: the writer, the reader and the size check all go through
// this list. The replicate sums exist only with replicates (acc.replicates > 1, K per pixel), the
// even half only with acc.split_halves.
template <class Acc, class Visit>
void visit_arrays(Acc& acc, Visit&& visit) {
  visit(acc.lv_mean, 1);
  visit(acc.hv_mean, 1);
  visit(acc.hv_lum_mean, 1);
  visit(acc.hv_lum_m2, 1);
  visit(acc.samples, 1);
  visit(acc.albedo_mean, 1);
  visit(acc.lv_lum_mean, 1);
  visit(acc.lv_lum_m2, 1);
  const size_t replicate_slots = acc.replicates > 1 ? static_cast<size_t>(acc.replicates) : 0;
  visit(acc.replicate_lum_sum, replicate_slots);
  visit(acc.replicate_samples, replicate_slots);
  const size_t half_slots = acc.split_halves ? 1 : 0;
  visit(acc.even_hv_mean, half_slots);
  visit(acc.even_lum_mean, half_slots);
  visit(acc.even_lum_m2, half_slots);
  visit(acc.even_samples, half_slots);
}

// The per-pixel arrays of a state: the accumulation's, then the traced counts and, in an adaptive
// state, the allocation's credits and next mask.
template <class State, class Visit>
void visit_state_arrays(State& state, Visit&& visit) {
  visit_arrays(state.acc, visit);
  visit(state.traced, 1);
  const size_t allocation_slots = state.settings.adaptive ? 1 : 0;
  visit(state.rate, allocation_slots);
  visit(state.credit, allocation_slots);
  visit(state.next_active, allocation_slots);
}

// The replicates a state's accumulation has sums for.
int state_replicates(const SampleSettings& s) {
  return accumulated_replicates(static_cast<SamplerType>(s.sampler), static_cast<int>(s.replicates));
}

void put_settings(ByteWriter& w, const SampleSettings& s) {
  w.put(s.scene_hash);
  w.put(s.width);
  w.put(s.height);
  w.put(s.seed);
  w.put(s.max_vertices);
  w.put(s.rr_start_vertex);
  w.put(s.all_hv);
  w.put(s.sampler);
  w.put(s.replicates);
  w.put(s.specular_sampling);
  w.put(s.adaptive);
  w.put(s.guiding);
  w.put(s.environment_visibility);
  w.put(s.split_halves);
}

// The adaptive flag as a phrase (SampleSettings::adaptive).
std::string adaptive_name(uint32_t adaptive) {
  return adaptive == 0 ? "off" : adaptive == 1 ? "on" : "on until clean";
}

SampleSettings get_settings(ByteReader& r) {
  SampleSettings s;
  s.scene_hash = r.get<uint64_t>("header");
  s.width = r.get<uint32_t>("header");
  s.height = r.get<uint32_t>("header");
  s.seed = r.get<uint64_t>("header");
  s.max_vertices = r.get<int32_t>("header");
  s.rr_start_vertex = r.get<int32_t>("header");
  s.all_hv = r.get<uint32_t>("header");
  s.sampler = r.get<uint32_t>("header");
  s.replicates = r.get<uint32_t>("header");
  s.specular_sampling = r.get<uint32_t>("header");
  s.adaptive = r.get<uint32_t>("header");
  s.guiding = r.get<uint32_t>("header");
  s.environment_visibility = r.get<uint32_t>("header");
  s.split_halves = r.get<uint32_t>("header");
  if (s.all_hv > 1 || s.specular_sampling > static_cast<uint32_t>(SpecularSamplingMode::Chains) || s.sampler > 1 ||
      s.adaptive > 2 || s.guiding > 2 || s.environment_visibility > 1 || s.split_halves > 1)
    throw Error("state file has an invalid setting flag (all-hv, sampler, specular sampling, adaptive, guiding, "
                "env-visibility or split decision)");
  if (s.replicates < 1 || s.replicates > kMaxReplicates)
    throw Error("state file has an invalid replicate count " + std::to_string(s.replicates));
  if (s.width == 0 || s.height == 0 || s.width > kMaxSide || s.height > kMaxSide)
    throw Error("state file has an invalid image size " + std::to_string(s.width) + "x" + std::to_string(s.height));
  return s;
}

// The frames of the ranges in all, in 64 bits: no sum of uint32 counts can wrap.
uint64_t total_frames(const std::vector<FrameRange>& ranges) {
  uint64_t n = 0;
  for (const FrameRange& r : ranges) n += r.count();
  return n;
}

// Refuses a frame total beyond kMaxStateFrames; `what` begins the message ("state file has").
void check_frame_total(uint64_t frames, const std::string& what) {
  if (frames > kMaxStateFrames)
    throw Error(what + " " + std::to_string(frames) + " frames, more than the " + std::to_string(kMaxStateFrames) +
                " a state can hold");
}

void check_frame_ranges(const std::vector<FrameRange>& ranges, bool adaptive) {
  for (size_t i = 0; i < ranges.size(); ++i) {
    if (ranges[i].begin >= ranges[i].end) throw Error("state file has an empty or reversed frame range");
    // A uniform writer joins adjacent ranges (a render writes one, a merge joins them), so adjacent
    // ranges are not a uniform state pxf wrote; refusing them keeps a decoded state canonical. An
    // adaptive merge keeps them apart (merge_states).
    if (i > 0 && (ranges[i].begin < ranges[i - 1].end || (!adaptive && ranges[i].begin == ranges[i - 1].end)))
      throw Error("state file has unsorted, overlapping or unjoined adjacent frame ranges");
  }
  check_frame_total(total_frames(ranges), "state file has");
}

void check_even_half(const Accumulation& acc, size_t i) {
  const glm::vec3 even = acc.even_hv_mean[i];
  if (!(std::isfinite(even.x) && std::isfinite(even.y) && std::isfinite(even.z) && std::isfinite(acc.even_lum_mean[i]) &&
        std::isfinite(acc.even_lum_m2[i]) && acc.even_lum_m2[i] >= 0.0))
    throw Error("state file has a non-finite or negative value at pixel " + std::to_string(i));
  if (acc.even_samples[i] > acc.samples[i])
    throw Error("state file has more even-index samples than samples at pixel " + std::to_string(i));
}

void check_pixels(const AccumulationState& state) {
  const Accumulation& acc = state.acc;
  const uint32_t frames = state.frame_count();
  for (size_t i = 0; i < acc.samples.size(); ++i) {
    // An adaptive frame traces a pixel at most kMaxPathsPerFrame times, every frame of a uniform
    // state every pixel once; non-finite samples are traced but dropped.
    const uint64_t most = static_cast<uint64_t>(frames) * (state.settings.adaptive ? kMaxPathsPerFrame : 1u);
    if (state.traced[i] > most || (!state.settings.adaptive && state.traced[i] != frames))
      throw Error("state file has a traced count that does not fit its frames at pixel " + std::to_string(i));
    if (acc.samples[i] > state.traced[i]) throw Error("state file has more samples in a pixel than it traced");
    if (state.settings.adaptive &&
        (!(state.rate[i] >= 0.0f && state.rate[i] <= static_cast<float>(kMaxPathsPerFrame)) ||
         !(state.credit[i] >= 0.0f && state.credit[i] < 1.0f) || state.next_active[i] > kMaxPathsPerFrame))
      throw Error("state file has an invalid adaptive allocation at pixel " + std::to_string(i));
    const glm::vec3 lv = acc.lv_mean[i], hv = acc.hv_mean[i], a = acc.albedo_mean[i];
    const bool finite = std::isfinite(lv.x) && std::isfinite(lv.y) && std::isfinite(lv.z) && std::isfinite(hv.x) &&
                        std::isfinite(hv.y) && std::isfinite(hv.z) && std::isfinite(a.x) && std::isfinite(a.y) &&
                        std::isfinite(a.z) && std::isfinite(acc.hv_lum_mean[i]) &&
                        std::isfinite(acc.hv_lum_m2[i]) && acc.hv_lum_m2[i] >= 0.0 &&
                        std::isfinite(acc.lv_lum_mean[i]) && std::isfinite(acc.lv_lum_m2[i]) && acc.lv_lum_m2[i] >= 0.0;
    if (!finite) throw Error("state file has a non-finite or negative value at pixel " + std::to_string(i));
    if (acc.split_halves) check_even_half(acc, i);
    if (acc.replicates < 2) continue;
    // The replicate sums split the pixel's samples: their counts add up to its count.
    uint64_t replicate_count = 0;
    for (size_t k = i * static_cast<size_t>(acc.replicates); k < (i + 1) * static_cast<size_t>(acc.replicates); ++k) {
      if (!std::isfinite(acc.replicate_lum_sum[k]))
        throw Error("state file has a non-finite replicate sum at pixel " + std::to_string(i));
      replicate_count += acc.replicate_samples[k];
    }
    if (replicate_count != acc.samples[i])
      throw Error("state file's replicate sample counts do not add up to the samples at pixel " + std::to_string(i));
  }
}

// Sample-count weighted mean of two means, in double, rounded once.
float combine_mean(float a, uint32_t na, float b, uint32_t nb, double n) {
  return static_cast<float>((static_cast<double>(a) * na + static_cast<double>(b) * nb) / n);
}

// Chan, Golub and LeVeque's pairwise update of a Welford state (mean, M2) of na samples by one of nb.
void combine_welford(double& mean, double& m2, uint32_t na, double from_mean, double from_m2, uint32_t nb, double n) {
  const double delta = from_mean - mean;
  mean += delta * nb / n;
  m2 += from_m2 + delta * delta * (static_cast<double>(na) * nb / n);
}

// The even halves of pixel i combine like the whole (sample indices, and so their parities, are the
// same wherever a frame is traced).
void merge_even_half(Accumulation& into, const Accumulation& from, size_t i) {
  if (!into.split_halves) return;
  const uint32_t na = into.even_samples[i], nb = from.even_samples[i];
  if (nb == 0) return;
  if (na == 0) {
    into.even_hv_mean[i] = from.even_hv_mean[i];
    into.even_lum_mean[i] = from.even_lum_mean[i];
    into.even_lum_m2[i] = from.even_lum_m2[i];
    into.even_samples[i] = nb;
    return;
  }
  const double n = static_cast<double>(na) + nb;
  for (int c = 0; c < 3; ++c)
    into.even_hv_mean[i][c] = combine_mean(into.even_hv_mean[i][c], na, from.even_hv_mean[i][c], nb, n);
  combine_welford(into.even_lum_mean[i], into.even_lum_m2[i], na, from.even_lum_mean[i], from.even_lum_m2[i], nb, n);
  into.even_samples[i] = na + nb;
}

void merge_into(Accumulation& into, const Accumulation& from) {
  for (size_t i = 0; i < into.samples.size(); ++i) {
    const uint32_t na = into.samples[i], nb = from.samples[i];
    if (nb == 0) continue;
    if (na == 0) {
      into.lv_mean[i] = from.lv_mean[i];
      into.hv_mean[i] = from.hv_mean[i];
      into.albedo_mean[i] = from.albedo_mean[i];
      into.hv_lum_mean[i] = from.hv_lum_mean[i];
      into.hv_lum_m2[i] = from.hv_lum_m2[i];
      into.lv_lum_mean[i] = from.lv_lum_mean[i];
      into.lv_lum_m2[i] = from.lv_lum_m2[i];
      into.samples[i] = nb;
      merge_even_half(into, from, i);
      continue;
    }
    const double n = static_cast<double>(na) + nb;
    for (int c = 0; c < 3; ++c) {
      into.lv_mean[i][c] = combine_mean(into.lv_mean[i][c], na, from.lv_mean[i][c], nb, n);
      into.hv_mean[i][c] = combine_mean(into.hv_mean[i][c], na, from.hv_mean[i][c], nb, n);
      into.albedo_mean[i][c] = combine_mean(into.albedo_mean[i][c], na, from.albedo_mean[i][c], nb, n);
    }
    combine_welford(into.hv_lum_mean[i], into.hv_lum_m2[i], na, from.hv_lum_mean[i], from.hv_lum_m2[i], nb, n);
    combine_welford(into.lv_lum_mean[i], into.lv_lum_m2[i], na, from.lv_lum_mean[i], from.lv_lum_m2[i], nb, n);
    into.samples[i] = na + nb;
    merge_even_half(into, from, i);
  }
  // Each replicate's samples of disjoint frame ranges add up (frame k is in replicate k mod K).
  for (size_t k = 0; k < into.replicate_samples.size(); ++k) {
    into.replicate_lum_sum[k] += from.replicate_lum_sum[k];
    into.replicate_samples[k] += from.replicate_samples[k];
  }
}

}  // namespace

bool SampleSettings::operator==(const SampleSettings& o) const { return difference(o).empty(); }

std::string SampleSettings::difference(const SampleSettings& o) const {
  auto diff = [](const char* name, auto a, auto b) {
    std::ostringstream s;
    s << name << " " << a << " vs " << b;
    return s.str();
  };
  if (scene_hash != o.scene_hash) return "scene content (hash) differs";
  if (width != o.width || height != o.height)
    return "image size " + std::to_string(width) + "x" + std::to_string(height) + " vs " + std::to_string(o.width) +
           "x" + std::to_string(o.height);
  if (seed != o.seed) return diff("seed", seed, o.seed);
  if (max_vertices != o.max_vertices) return diff("max vertices", max_vertices, o.max_vertices);
  if (rr_start_vertex != o.rr_start_vertex) return diff("Russian roulette start", rr_start_vertex, o.rr_start_vertex);
  if (all_hv != o.all_hv) return diff("all-hv", all_hv, o.all_hv);
  if (sampler != o.sampler) return diff("sampler", sampler_type_names()[sampler], sampler_type_names()[o.sampler]);
  if (replicates != o.replicates) return diff("replicates", replicates, o.replicates);
  if (specular_sampling != o.specular_sampling) return diff("specular sampling", specular_sampling, o.specular_sampling);
  if (adaptive != o.adaptive) return "adaptive sampling " + adaptive_name(adaptive) + " vs " + adaptive_name(o.adaptive);
  if (guiding != o.guiding) return "guiding " + guiding_mode_names()[guiding] + " vs " + guiding_mode_names()[o.guiding];
  if (environment_visibility != o.environment_visibility)
    return std::string("env-visibility ") + (environment_visibility ? "on" : "off") + " vs " +
           (o.environment_visibility ? "on" : "off");
  if (split_halves != o.split_halves)
    return std::string("split decision ") + (split_halves ? "on" : "off") + " vs " + (o.split_halves ? "on" : "off");
  return "";
}

uint32_t AccumulationState::frame_count() const {
  return static_cast<uint32_t>(std::min<uint64_t>(total_frames(frames), UINT32_MAX));
}

SampleSettings sample_settings(uint64_t scene_hash, int width, int height, const TraceParams& params) {
  SampleSettings s;
  s.scene_hash = scene_hash;
  s.width = static_cast<uint32_t>(width);
  s.height = static_cast<uint32_t>(height);
  s.seed = params.seed;
  s.max_vertices = params.max_vertices;
  s.rr_start_vertex = params.rr_start_vertex;
  s.all_hv = params.all_hv ? 1u : 0u;
  s.sampler = static_cast<uint32_t>(params.sampler);
  s.replicates = static_cast<uint32_t>(std::max(params.replicates, 1));
  s.specular_sampling = static_cast<uint32_t>(specular_sampling_mode(params));
  s.guiding = static_cast<uint32_t>(params.guiding);
  s.environment_visibility = params.environment_visibility ? 1u : 0u;
  s.split_halves = params.split_halves ? 1u : 0u;
  return s;
}

namespace {
// `max_bytes`: the bound of the reader that loads the file.
uint64_t hash_file(const std::string& path, uint64_t max_bytes, uint64_t hash) {
  const std::vector<unsigned char> bytes = read_input_file(path, max_bytes);
  return fnv1a64(bytes.data(), bytes.size(), hash);
}
}  // namespace

uint64_t scene_content_hash(const std::string& scene, const std::string& env_path, float env_strength) {
  std::string path = scene;
  for (const BuiltinScene& b : builtin_scenes())
    if (b.name == scene) path = b.path;
  uint64_t hash = hash_file(path, kMaxGltfFileBytes, fnv1a64(nullptr, 0));
  if (!env_path.empty()) hash = hash_file(env_path, std::max(kMaxExrFileBytes, kMaxStbImageFileBytes), hash);
  return fnv1a64(&env_strength, sizeof(env_strength), hash);
}

std::vector<uint8_t> encode_state(const AccumulationState& state) {
  if (!little_endian()) throw Error("state files are little-endian; this machine is not");
  ByteWriter w;
  w.put_bytes(kMagic, sizeof(kMagic));
  w.put(kStateFormatVersion);
  put_settings(w, state.settings);
  w.put(static_cast<uint32_t>(state.frames.size()));
  for (const FrameRange& r : state.frames) {
    w.put(r.begin);
    w.put(r.end);
  }
  if (state.acc.replicates != state_replicates(state.settings))
    throw Error("cannot save a state whose accumulation has " + std::to_string(state.acc.replicates) +
                " replicates under settings with " + std::to_string(state_replicates(state.settings)));
  if (state.acc.split_halves != (state.settings.split_halves != 0))
    throw Error("cannot save a state whose accumulation's halves do not match its split decision setting");
  const size_t pixels = static_cast<size_t>(state.settings.width) * state.settings.height;
  visit_state_arrays(state, [&](const auto& array, size_t per_pixel) {
    if (array.size() != pixels * per_pixel) throw Error("cannot save a state with a per-pixel array of the wrong size");
    w.put_array(array);
  });
  if (state.settings.guiding) {  // the field, length-prefixed (0: none)
    if (state.guiding_field.size() > kMaxGuidingFieldBytes) throw Error("cannot save a guiding field this large");
    w.put(static_cast<uint64_t>(state.guiding_field.size()));
    w.put_array(state.guiding_field);
  } else if (!state.guiding_field.empty()) {
    throw Error("cannot save a guiding field in a state without guiding");
  }
  if (state.settings.environment_visibility) {  // length-prefixed (0: none)
    if (state.environment_visibility.size() > kMaxEnvironmentVisibilityBytes)
      throw Error("cannot save an environment visibility this large");
    w.put(static_cast<uint64_t>(state.environment_visibility.size()));
    w.put_array(state.environment_visibility);
  } else if (!state.environment_visibility.empty()) {
    throw Error("cannot save an environment visibility in a state without it");
  }
  w.put(fnv1a64(w.bytes.data(), w.bytes.size()));
  return std::move(w.bytes);
}

AccumulationState decode_state(const uint8_t* data, size_t size) {
  if (!little_endian()) throw Error("state files are little-endian; this machine is not");
  ByteReader r(data, size, "state file");
  char magic[sizeof(kMagic)];
  r.get_bytes(magic, sizeof(magic), "the magic number");
  if (std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) throw Error("not a pxf state file (bad magic number)");
  const uint32_t version = r.get<uint32_t>("header");
  if (version != kStateFormatVersion)
    throw Error("state file format version " + std::to_string(version) + " is not supported (this pxf reads version " +
                std::to_string(kStateFormatVersion) + ")");
  // The checksum covers everything before it: check it before trusting any count.
  if (size < sizeof(uint64_t) + r.pos()) throw Error("state file truncated");
  uint64_t stored;
  std::memcpy(&stored, data + size - sizeof(uint64_t), sizeof(uint64_t));
  if (stored != fnv1a64(data, size - sizeof(uint64_t))) throw Error("state file is corrupt or truncated (checksum mismatch)");

  AccumulationState state;
  state.settings = get_settings(r);
  const uint32_t range_count = r.get<uint32_t>("header");
  if (range_count == 0 || range_count > kMaxFrameRanges) throw Error("state file has an invalid frame range count");
  if (range_count > r.remaining() / (2 * sizeof(uint32_t))) throw Error("state file truncated in the frame ranges");
  state.frames.resize(range_count);
  for (FrameRange& range : state.frames) {
    range.begin = r.get<uint32_t>("the frame ranges");
    range.end = r.get<uint32_t>("the frame ranges");
  }
  check_frame_ranges(state.frames, state.settings.adaptive != 0);
  const size_t pixels = static_cast<size_t>(state.settings.width) * state.settings.height;
  state.acc.width = static_cast<int>(state.settings.width);
  state.acc.height = static_cast<int>(state.settings.height);
  state.acc.replicates = state_replicates(state.settings);
  state.acc.split_halves = state.settings.split_halves != 0;
  visit_state_arrays(state, [&](auto& array, size_t per_pixel) {
    r.get_array(array, pixels * per_pixel, per_pixel > 1 ? "the replicate arrays" : "the pixel arrays");
  });
  if (state.settings.guiding) {
    const uint64_t bytes = r.get<uint64_t>("the guiding field");
    if (bytes > kMaxGuidingFieldBytes || bytes > r.remaining()) throw Error("state file has an invalid guiding field size");
    r.get_array(state.guiding_field, static_cast<size_t>(bytes), "the guiding field");
    if (!state.guiding_field.empty()) {
      try {  // validated here, so that a decoded state always restores
        GuidingField::deserialize(state.guiding_field.data(), state.guiding_field.size());
      } catch (const Error& e) {
        throw Error(std::string("state file has an invalid guiding field: ") + e.what());
      }
    }
  }
  if (state.settings.environment_visibility) {
    const uint64_t bytes = r.get<uint64_t>("the environment visibility");
    if (bytes > kMaxEnvironmentVisibilityBytes || bytes > r.remaining())
      throw Error("state file has an invalid environment visibility size");
    r.get_array(state.environment_visibility, static_cast<size_t>(bytes), "the environment visibility");
  }
  if (r.remaining() != sizeof(uint64_t)) throw Error("state file has trailing bytes");
  check_pixels(state);
  return state;
}

void write_state_file(const std::string& path, const AccumulationState& state) {
  const std::vector<uint8_t> bytes = encode_state(state);
  write_file_atomically(path, [&](const std::string& tmp) {
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw Error(path + ": cannot write state: " + std::strerror(errno));
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const int err = errno;
        ::close(fd);
        throw Error(path + ": cannot write state: " + std::strerror(err));
      }
      done += static_cast<size_t>(n);
    }
    // The data must be on disk before the rename makes it the state: a crash then leaves the old
    // state or the new one, never a torn one.
    const bool synced = ::fsync(fd) == 0;
    ::close(fd);
    if (!synced) throw Error(path + ": cannot write state: fsync failed");
  });
}

namespace {
// The largest file decode_state can accept, every count at its bound: the header, kMaxFrameRanges
// frame ranges, kMaxSide^2 pixels with kMaxReplicates replicate slots each, the largest guiding
// field and environment visibility, the checksum. About
// 824 GiB: no practical size, but a bound on what is read, derived from the format itself.
uint64_t max_state_file_bytes() {
  ByteWriter header;
  header.put_bytes(kMagic, sizeof(kMagic));
  header.put(kStateFormatVersion);
  put_settings(header, SampleSettings{});
  header.put(uint32_t{0});  // the range count
  AccumulationState pixel;
  pixel.acc.replicates = kMaxReplicates;
  pixel.settings.adaptive = 1;
  uint64_t per_pixel = 0;
  visit_state_arrays(pixel, [&](const auto& array, size_t slots) {
    per_pixel += slots * sizeof(typename std::decay_t<decltype(array)>::value_type);
  });
  return header.bytes.size() + uint64_t{kMaxFrameRanges} * 2 * sizeof(uint32_t) +
         uint64_t{kMaxSide} * kMaxSide * per_pixel + sizeof(uint64_t) + kMaxGuidingFieldBytes + sizeof(uint64_t) +
         kMaxEnvironmentVisibilityBytes + sizeof(uint64_t);
}
}  // namespace

AccumulationState read_state_file(const std::string& path) {
  const std::vector<unsigned char> bytes = read_input_file(path, max_state_file_bytes());
  try {
    return decode_state(bytes.data(), bytes.size());
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
}

AccumulationState merge_states(const std::vector<AccumulationState>& states) {
  if (states.empty()) throw Error("no state to merge");
  uint64_t frames = 0;  // checked before any pixel is combined: per-pixel counts stay below it
  for (const AccumulationState& state : states) frames += total_frames(state.frames);
  check_frame_total(frames, "the states to merge hold");
  AccumulationState merged = states.front();
  for (size_t i = 1; i < states.size(); ++i) {
    const std::string diff = states[i].settings.difference(merged.settings);
    if (!diff.empty()) throw Error("state " + std::to_string(i + 1) + " was rendered with other settings: " + diff);
    merged.frames.insert(merged.frames.end(), states[i].frames.begin(), states[i].frames.end());
    merge_into(merged.acc, states[i].acc);
    for (size_t p = 0; p < merged.traced.size(); ++p) merged.traced[p] += states[i].traced[p];
  }
  if (merged.settings.adaptive) {  // no allocation to continue: a merged state is not resumed
    std::fill(merged.rate.begin(), merged.rate.end(), 0.0f);
    std::fill(merged.credit.begin(), merged.credit.end(), 0.0f);
    std::fill(merged.next_active.begin(), merged.next_active.end(), uint8_t{1});
  }
  // Each shard learned its own guiding field; their samples average exactly, but no field continues
  // them: a merged guided state keeps none and is not resumed (Checkpointer refuses it).
  // The same for what light through openings learned: a merged state resumes learning anew.
  if (states.size() > 1) {
    merged.guiding_field.clear();
    merged.environment_visibility.clear();
  }
  std::sort(merged.frames.begin(), merged.frames.end(),
            [](const FrameRange& a, const FrameRange& b) { return a.begin < b.begin; });
  for (size_t i = 1; i < merged.frames.size(); ++i)
    if (merged.frames[i].begin < merged.frames[i - 1].end)
      throw Error("frame ranges overlap (" + frame_ranges_text(merged.frames) + "): a frame would count twice");
  // Adjacent ranges become one, so the shards of 0:N merge into the state of a plain 0:N render.
  // Not in an adaptive merge: there a pixel's samples of 0:A and A:B are the first traced[p] of each
  // range, no prefix of 0:B, and a resume from one joined range would trace some indices twice.
  std::vector<FrameRange> joined;
  for (const FrameRange& r : merged.frames) {
    if (!joined.empty() && joined.back().end == r.begin && !merged.settings.adaptive)
      joined.back().end = r.end;
    else
      joined.push_back(r);
  }
  merged.frames = joined;
  return merged;
}

std::string frame_ranges_text(const std::vector<FrameRange>& ranges) {
  std::string text;
  for (const FrameRange& r : ranges)
    text += (text.empty() ? "" : ",") + std::to_string(r.begin) + ":" + std::to_string(r.end);
  return text;
}

}  // namespace pxf
