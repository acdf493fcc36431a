// ProgressiveRenderer: one path per active pixel per frame, in chunks of tiles on a oneTBB arena; accumulation.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "pathtracer/environment_visibility.h"
#include "pathtracer/guiding_field.h"
#include <cstdio>
#include "pathtracer/integrator.h"
#include "pathtracer/pathtracer.h"

namespace pxf {
namespace {

constexpr int kTileSize = 16;
constexpr int kChunk = kTileSize * kTileSize;  // jobs per batch that one thread traces

// Path guiding's training (docs/guiding.md): after each frame, a sixteenth of a
// photon per pixel, but at least kGuidingMinPhotonsPerFrame (the field's resolution depends on the
// scene, not on the image), and no iteration (2^k frames) traces more than
// kGuidingPhotonsPerIteration, so the training's cost per frame falls once the field has that
// many: a leaf's lobes are fitted to a reservoir of 128 records. A lower minimum saves a little
// time in closed scenes but leaves an open scene, whose photons mostly miss or land where direct
// light is not recorded, with too few records, and its error rises. The field's spatial leaves split at
// c = 100 records (x sqrt(2^k)), not the paper's 12000, which left a Cornell box wall in one leaf
// at these photon counts.
constexpr double kGuidingPhotonsPerPixel = 0.0625;
constexpr double kGuidingMinPhotonsPerFrame = 8192;
constexpr double kGuidingPhotonsPerIteration = double(1 << 16);
constexpr float kGuidingSpatialThreshold = 100.0f;
// The directional model: at most 8 parallax-aware lobes per leaf (docs/guiding.md), not the quadtree.
constexpr int kGuidingLobes = 8;
// Of those, the lobes fitted to the light that came through delta bounces (GuidingSettings::delta_lobes):
// half: in one reservoir the caustic's few records are outweighed by the leaf's other light and
// get no lobe; with their own, the caustic's second moment and HV's fall (docs/guiding.md).
constexpr int kGuidingDeltaLobes = 4;

int guiding_photons_per_frame(int width, int height, int iteration) {
  const double wanted = std::max(kGuidingMinPhotonsPerFrame, kGuidingPhotonsPerPixel * width * height);
  const double per_frame = std::min(wanted, kGuidingPhotonsPerIteration / std::ldexp(1.0, std::min(iteration, 60)));
  return static_cast<int>(std::ceil(per_frame));
}

// The box path guiding's field covers: the scene's triangles, a little larger (points on the
// boundary stay inside), or a unit box without any.
void guiding_box(const Scene& scene, glm::vec3* lo, glm::vec3* hi) {
  *lo = glm::vec3(std::numeric_limits<float>::max());
  *hi = glm::vec3(-std::numeric_limits<float>::max());
  for (const Mesh& mesh : scene.meshes)
    for (const glm::vec3& p : mesh.positions) {
      *lo = glm::min(*lo, p);
      *hi = glm::max(*hi, p);
    }
  if (!(lo->x <= hi->x) || !std::isfinite(lo->x + lo->y + lo->z + hi->x + hi->y + hi->z)) {
    *lo = glm::vec3(-0.5f);
    *hi = glm::vec3(0.5f);
  }
  const glm::vec3 margin = 1e-3f * (*hi - *lo) + glm::vec3(1e-6f);
  *lo -= margin;
  *hi += margin;
}

}  // namespace

struct ProgressiveRenderer::Impl {
  const Scene& scene;  // the caller's, not copied: the Embree scene and the light sampler point into it
  Camera camera;
  TraceParams params;
  int width, height;
  std::unique_ptr<PathTracer> tracer;
  std::unique_ptr<tbb::task_arena> arena;  // kept across frames: its worker threads stay warm
  std::atomic<bool> cancel{false};
  Accumulation acc;
  TraceStats stats;
  std::atomic<int> frames{0};  // read by the explorer's UI thread while a worker traces
  uint32_t first_frame = 0;
  uint32_t sample_stride = 1;  // frame f's first sample index is f * sample_stride
  std::vector<uint32_t> pixel_frames;  // paths traced into each pixel since the reset
  std::vector<PixelSampleJob> jobs;    // the frame's paths (build_jobs), kept to reuse the memory
  std::vector<size_t> chunk_starts;    // where each batch of at most kChunk jobs starts, then the end
  // Path guiding (params.guiding): learned since it started, read by the tracing threads.
  std::unique_ptr<GuidingField> guiding;
  // The frame count at which the field started: 0 under GuidingMode::On, the frame of the
  // visibility field's verdict under Auto. Its iterations count from there.
  uint64_t guiding_start = 0;
  // Light through openings (params.environment_visibility, a scene with an environment).
  std::unique_ptr<EnvironmentVisibility> visibility;

  Impl(const Scene& s, const TraceParams& p, int w, int h) : scene(s), camera(s.camera), params(p), width(w), height(h) {
    if (w <= 0 || h <= 0) throw Error("path tracer: image size must be positive");
    tracer = std::make_unique<PathTracer>(scene);
    resize_accumulation(acc, w, h, accumulation_replicates(), params.split_halves);
    pixel_frames.assign(static_cast<size_t>(w) * h, 0u);
    make_arena();
    reset_guiding();
    reset_visibility();
  }

  // After a complete frame: what the frame found goes into the field; a dormant field (a scene
  // that sees most of its sky) is no longer asked.
  void learn_visibility() {
    if (!visibility) return;
    visibility->end_frame();
    attach_visibility();
  }

  // The tracer asks the field unless there is none or it went dormant.
  void attach_visibility() {
    tracer->set_environment_visibility(visibility && !visibility->dormant() ? visibility.get() : nullptr);
  }

  // A new field that has learned nothing (with an environment and params.environment_visibility).
  void reset_visibility() {
    visibility.reset();
    if (params.environment_visibility && tracer->lights().has_environment()) {
      glm::vec3 lo, hi;
      guiding_box(scene, &lo, &hi);
      visibility = std::make_unique<EnvironmentVisibility>(*scene.environment, lo, hi);
    }
    attach_visibility();
  }

  // A new, untrained field under GuidingMode::On; none otherwise (Auto starts one later, or never).
  void reset_guiding() {
    guiding.reset();
    guiding_start = 0;
    if (params.guiding == GuidingMode::On) start_guiding();
    tracer->set_guiding(guiding.get());
  }

  // A new, untrained field that learns from the next frame on.
  void start_guiding() {
    glm::vec3 lo, hi;
    guiding_box(scene, &lo, &hi);
    GuidingSettings settings;
    settings.spatial_threshold = kGuidingSpatialThreshold;
    settings.parallax_lobes = kGuidingLobes;
    settings.delta_lobes = kGuidingDeltaLobes;
    guiding = std::make_unique<GuidingField>(lo, hi, settings);
    guiding_start = static_cast<uint64_t>(frames.load());
    tracer->set_guiding(guiding.get());
  }

  // GuidingMode::Auto: guiding starts after the frame at which the visibility field judged the
  // scene lit through openings (it sees at most half of its sky), and never elsewhere.
  void start_auto_guiding() {
    if (params.guiding == GuidingMode::Auto && !guiding && lit_through_openings()) start_guiding();
  }
  bool lit_through_openings() const { return visibility && visibility->judged() && !visibility->dormant(); }

  // After a complete frame (single-threaded): the frame's records go into the field, and at the
  // end of each iteration of doubling length (GuidingField::iteration_ends_after) the field
  // becomes what the iteration learned.
  void learn_guiding() {
    if (!guiding) return;
    const uint32_t frame = static_cast<uint32_t>(frames.load() - 1);
    const int photons = guiding_photons_per_frame(width, height, guiding->iteration());
    arena->execute([&] {
      tracer->trace_guiding_photons(frame, photons, params);
      guiding->apply_records();
      const uint64_t learned_frames = static_cast<uint64_t>(frames.load()) - guiding_start;
      if (GuidingField::iteration_ends_after(learned_frames)) guiding->end_iteration();
    });
  }

  // A resumed render's field (after its visibility field and frame count are restored). Empty: a
  // new one under On (a merge's state), none yet under Auto, which may then start one as usual.
  void restore_guiding(const std::vector<uint8_t>& field) {
    guiding.reset();
    guiding_start = 0;
    if (params.guiding != GuidingMode::Off && !field.empty()) {
      guiding = std::make_unique<GuidingField>(GuidingField::deserialize(field.data(), field.size()));
      // Auto's field started at the visibility field's verdict, kDormantCheckFrame frames after
      // the visibility field started.
      if (params.guiding == GuidingMode::Auto && visibility) {
        const uint64_t visibility_start = static_cast<uint64_t>(frames.load()) - visibility->frames();
        guiding_start = visibility_start + EnvironmentVisibility::kDormantCheckFrame;
      }
    } else if (params.guiding == GuidingMode::On) {
      start_guiding();
    } else {
      start_auto_guiding();
    }
    tracer->set_guiding(guiding.get());
  }

  int accumulation_replicates() const { return accumulated_replicates(params.sampler, params.replicates); }

  void make_arena() {
    int threads = params.threads > 0 ? params.threads : static_cast<int>(tbb::task_arena::automatic);
    arena = std::make_unique<tbb::task_arena>(threads);
  }

  // The paths a frame traces, as jobs in tile order (16x16 tiles, row-major inside each): with
  // every pixel active a chunk of kChunk jobs is one tile, as the camera rays' coherence wants; with
  // a mask the active pixels' paths are compacted, so that chunks are nearly full batches. A pixel
  // with count k traces k consecutive jobs, the next k indices of its sequence, all in one chunk:
  // one thread then adds them in index order, so the sums do not depend on the thread count.
  // Each job's sample index is the pixel's own count, so a pixel's samples do not depend on which
  // other pixels a frame traces, nor on the chunking or the thread.
  uint32_t first_sample() const { return first_frame * sample_stride; }

  void build_jobs(const uint8_t* counts) {
    jobs.clear();
    chunk_starts.assign(1, 0);
    const int tiles_x = (width + kTileSize - 1) / kTileSize, tiles_y = (height + kTileSize - 1) / kTileSize;
    for (int ty = 0; ty < tiles_y; ++ty)
      for (int tx = 0; tx < tiles_x; ++tx)
        for (int y = ty * kTileSize; y < std::min((ty + 1) * kTileSize, height); ++y)
          for (int x = tx * kTileSize; x < std::min((tx + 1) * kTileSize, width); ++x) {
            const size_t p = static_cast<size_t>(y) * width + x;
            const uint32_t k = counts ? counts[p] : 1u;
            if (k == 0) continue;
            if (k > kMaxPathsPerFrame) throw Error("a pixel's path count of " + std::to_string(k) + " is over " +
                                                   std::to_string(kMaxPathsPerFrame) + " a frame");
            if (jobs.size() - chunk_starts.back() + k > static_cast<size_t>(kChunk)) chunk_starts.push_back(jobs.size());
            for (uint32_t i = 0; i < k; ++i) jobs.push_back(PixelSampleJob{x, y, first_sample() + pixel_frames[p] + i});
          }
    chunk_starts.push_back(jobs.size());
  }

  void render_frame() {
    const int chunks = static_cast<int>(chunk_starts.size()) - 1;
    std::atomic<uint64_t> rays{0}, paths{0}, dropped{0};
    auto render_chunks = [&](const tbb::blocked_range<int>& range) {
      uint64_t chunk_rays = 0, chunk_paths = 0, chunk_dropped = 0;
      for (int chunk = range.begin(); chunk != range.end(); ++chunk) {
        if (cancel.load(std::memory_order_relaxed)) break;
        const size_t first = chunk_starts[chunk];
        const int count = static_cast<int>(chunk_starts[chunk + 1] - first);
        PathSample samples[kChunk];
        tracer->trace_jobs(camera, width, height, &jobs[first], count, params, samples);
        for (int i = 0; i < count; ++i) {
          const PathSample& sample = samples[i];
          const PixelSampleJob& job = jobs[first + i];
          chunk_rays += sample.rays;
          ++chunk_paths;
          if (!sample.finite()) {  // LV and HV of a path are dropped together
            ++chunk_dropped;
            continue;
          }
          accumulate_sample(acc, static_cast<size_t>(job.y) * width + job.x, sample.lv, sample.hv,
                            job.index, sample.albedo);
        }
      }
      rays += chunk_rays;
      paths += chunk_paths;
      dropped += chunk_dropped;
    };
    arena->execute([&] { tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), render_chunks); });
    stats.rays += rays;
    stats.paths += paths;
    stats.nan_samples_dropped += dropped;
  }

  // A dark scene is black: every traced pixel gets an exact zero sample without tracing.
  void add_dark_frame() {
    for (const PixelSampleJob& job : jobs)
      accumulate_sample(acc, static_cast<size_t>(job.y) * width + job.x, glm::vec3(0.0f), glm::vec3(0.0f),
                        job.index);
  }

  // Every traced pixel's count moves on: its next path takes the next index of its sequence.
  void count_traced_pixels() {
    for (const PixelSampleJob& job : jobs) ++pixel_frames[static_cast<size_t>(job.y) * width + job.x];
  }
};

ProgressiveRenderer::ProgressiveRenderer(const Scene& scene, const TraceParams& params, int width, int height)
    : impl_(std::make_unique<Impl>(scene, params, width, height)) {}
ProgressiveRenderer::~ProgressiveRenderer() = default;

void ProgressiveRenderer::reset() {
  impl_->cancel.store(false);  // a cancel meant for a frame that finished first
  resize_accumulation(impl_->acc, impl_->width, impl_->height, impl_->accumulation_replicates(),
                      impl_->params.split_halves);
  impl_->pixel_frames.assign(impl_->pixel_frames.size(), 0u);
  impl_->stats = TraceStats{};
  impl_->frames = 0;
  impl_->reset_guiding();
  impl_->reset_visibility();
}

void ProgressiveRenderer::set_camera(const Camera& camera) {
  impl_->camera = camera;
  reset();
}

void ProgressiveRenderer::set_params(const TraceParams& params) {
  impl_->params = params;
  impl_->make_arena();
  reset();
}

bool ProgressiveRenderer::add_frame() { return add_frame_of(nullptr); }

bool ProgressiveRenderer::add_frame(const std::vector<uint8_t>& active) {
  if (active.size() != impl_->pixel_frames.size())
    throw Error("path counts have " + std::to_string(active.size()) + " entries, the image " +
                std::to_string(impl_->pixel_frames.size()) + " pixels");
  return add_frame_of(active.data());
}

bool ProgressiveRenderer::add_frame_of(const uint8_t* active) {
  auto start = std::chrono::steady_clock::now();
  impl_->build_jobs(active);
  if (impl_->tracer->dark())
    impl_->add_dark_frame();
  else
    impl_->render_frame();
  if (impl_->cancel.exchange(false)) {  // some tiles were left out: the frame cannot be kept
    reset();
    return false;
  }
  impl_->count_traced_pixels();
  ++impl_->frames;
  impl_->learn_guiding();
  impl_->learn_visibility();
  impl_->start_auto_guiding();
  impl_->stats.last_frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return true;
}

void ProgressiveRenderer::cancel_frame() { impl_->cancel.store(true); }

int ProgressiveRenderer::frames() const { return impl_->frames; }
const std::vector<uint32_t>& ProgressiveRenderer::pixel_frames() const { return impl_->pixel_frames; }
uint32_t ProgressiveRenderer::first_frame() const { return impl_->first_frame; }

void ProgressiveRenderer::set_first_frame(uint32_t first) {
  impl_->first_frame = first;
  reset();
}

void ProgressiveRenderer::set_sample_stride(uint32_t stride) {
  if (stride < 1 || stride > kMaxPathsPerFrame) throw Error("sample stride " + std::to_string(stride) + " out of range");
  impl_->sample_stride = stride;
}

void ProgressiveRenderer::restore(const Accumulation& acc, uint32_t first, int frames,
                                  const std::vector<uint32_t>& traced, const std::vector<uint8_t>& guiding_field,
                                  const std::vector<uint8_t>& environment_visibility) {
  if (acc.width != impl_->width || acc.height != impl_->height || acc.samples.size() != impl_->acc.samples.size())
    throw Error("saved accumulation is " + std::to_string(acc.width) + "x" + std::to_string(acc.height) +
                ", the render " + std::to_string(impl_->width) + "x" + std::to_string(impl_->height));
  if (acc.replicates != impl_->accumulation_replicates())
    throw Error("saved accumulation has " + std::to_string(acc.replicates) + " replicates, the render " +
                std::to_string(impl_->accumulation_replicates()));
  if (acc.split_halves != impl_->params.split_halves)
    throw Error(std::string("saved accumulation has the split decision's halves ") + (acc.split_halves ? "on" : "off") +
                ", the render " + (impl_->params.split_halves ? "on" : "off"));
  if (!traced.empty() && traced.size() != impl_->pixel_frames.size())
    throw Error("saved traced counts have " + std::to_string(traced.size()) + " entries, the image " +
                std::to_string(impl_->pixel_frames.size()) + " pixels");
  impl_->reset_visibility();
  if (impl_->visibility && !environment_visibility.empty()) {
    impl_->visibility->deserialize(environment_visibility.data(), environment_visibility.size());
    impl_->attach_visibility();
  }
  impl_->frames = frames;
  impl_->restore_guiding(guiding_field);
  impl_->acc = acc;
  impl_->first_frame = first;
  if (traced.empty())
    impl_->pixel_frames.assign(impl_->pixel_frames.size(), static_cast<uint32_t>(frames));
  else
    impl_->pixel_frames = traced;
  impl_->stats = TraceStats{};
}
std::vector<uint8_t> ProgressiveRenderer::guiding_field() const {
  return impl_->guiding ? impl_->guiding->serialize() : std::vector<uint8_t>{};
}
bool ProgressiveRenderer::guiding_active() const { return impl_->guiding != nullptr; }
size_t ProgressiveRenderer::guiding_memory_bytes() const { return impl_->guiding ? impl_->guiding->memory_bytes() : 0; }
std::vector<uint8_t> ProgressiveRenderer::environment_visibility() const {
  return impl_->visibility ? impl_->visibility->serialize() : std::vector<uint8_t>{};
}
size_t ProgressiveRenderer::environment_visibility_regions() const {
  return impl_->visibility ? impl_->visibility->learned_regions() : 0;
}
const Accumulation& ProgressiveRenderer::accumulation() const { return impl_->acc; }
const TraceStats& ProgressiveRenderer::stats() const { return impl_->stats; }
void ProgressiveRenderer::set_ray_recorder(RayRecorder* recorder) { impl_->tracer->set_ray_recorder(recorder); }
const PathTracer& ProgressiveRenderer::tracer() const { return *impl_->tracer; }
const Scene& ProgressiveRenderer::scene() const { return impl_->scene; }
const Camera& ProgressiveRenderer::camera() const { return impl_->camera; }
const TraceParams& ProgressiveRenderer::params() const { return impl_->params; }
int ProgressiveRenderer::width() const { return impl_->width; }
int ProgressiveRenderer::height() const { return impl_->height; }

namespace {
Image rgb_image(const std::vector<glm::vec3>& values, int width, int height) {
  Image image = Image::rgb(width, height);
  for (size_t i = 0; i < values.size(); ++i) {
    image.pixels[3 * i + 0] = values[i].r;
    image.pixels[3 * i + 1] = values[i].g;
    image.pixels[3 * i + 2] = values[i].b;
  }
  return image;
}
}  // namespace

Image ProgressiveRenderer::lv_image() const { return rgb_image(impl_->acc.lv_mean, impl_->width, impl_->height); }
Image ProgressiveRenderer::hv_image() const { return rgb_image(impl_->acc.hv_mean, impl_->width, impl_->height); }
Image ProgressiveRenderer::albedo_image() const { return rgb_image(impl_->acc.albedo_mean, impl_->width, impl_->height); }

Image ProgressiveRenderer::variance_image() const {
  Image image = Image::gray(impl_->width, impl_->height);
  const std::vector<float> variance = impl_->acc.variance_of_mean_image();
  for (size_t i = 0; i < variance.size(); ++i) image.pixels[i] = std::max(0.0f, variance[i]);
  return image;
}

Image ProgressiveRenderer::unfiltered_image() const { return sum_of(lv_image(), hv_image()); }

Image ProgressiveRenderer::samples_image() const {
  Image image = Image::gray(impl_->width, impl_->height);
  for (size_t i = 0; i < impl_->acc.samples.size(); ++i) image.pixels[i] = static_cast<float>(impl_->acc.samples[i]);
  return image;
}

Image ProgressiveRenderer::emitter_coverage_image() const {
  const int w = impl_->width, h = impl_->height, n = kEmitterRaysPerSide;
  Image image = Image::gray(w, h);
  auto trace_rows = [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < w; ++x) {
        int emissive = 0;
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i)
            emissive += impl_->tracer->first_hit_is_emissive(
                camera_ray(impl_->camera, w, h, x + (i + 0.5f) / n, y + (j + 0.5f) / n));
        image.at(x, y, 0) = static_cast<float>(emissive) / (n * n);
      }
  };
  impl_->arena->execute([&] { tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), trace_rows); });
  return image;
}

std::vector<float> ProgressiveRenderer::variance_of_mean() const {
  return impl_->acc.variance_of_mean_image();
}

bool ProgressiveRenderer::scene_has_perfect_specular() const { return impl_->tracer->has_perfect_specular(); }
bool ProgressiveRenderer::scene_is_dark() const { return impl_->tracer->dark(); }

SurfaceMaterial ProgressiveRenderer::surface_material(int x, int y) const {
  const int w = impl_->width, h = impl_->height;
  if (x < 0 || y < 0 || x >= w || y >= h) return SurfaceMaterial{};
  return impl_->tracer->surface_material(
      camera_ray(impl_->camera, w, h, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f));
}

std::vector<SpecularChainHit> ProgressiveRenderer::trace_specular_chains(const std::vector<uint32_t>& pixels,
                                                                         glm::vec2 jitter) const {
  std::vector<SpecularChainHit> hits(pixels.size());
  const int w = impl_->width, h = impl_->height;
  auto trace_range = [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      uint32_t p = pixels[i];
      if (p >= static_cast<uint32_t>(w) * static_cast<uint32_t>(h)) continue;
      float x = static_cast<float>(p % w) + jitter.x, y = static_cast<float>(p / w) + jitter.y;
      hits[i] = impl_->tracer->trace_specular_chain(camera_ray(impl_->camera, w, h, x, y));
    }
  };
  impl_->arena->execute([&] { tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels.size(), 256), trace_range); });
  return hits;
}

}  // namespace pxf
