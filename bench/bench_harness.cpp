#include "bench/bench_harness.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/timing.h"

namespace pxf {

BenchHarness::BenchHarness(const std::string& mode, const std::string& summary)
    : cli_(mode.empty() ? "bench" : "bench " + mode, "[options]", summary) {
  scene_.stage_timing = GlTiming::Finish;  // exact per-stage figures
  add_scene_options(cli_, scene_, /*headless=*/true);
  add_preview_options(cli_, settings_);
  cli_.option("--out", &out_, "DIR", "folder for CSV, plots and the cached reference (default bench-out)");
}

void BenchHarness::add_reference_options(int default_spp) {
  reference_spp_ = default_spp;
  cli_.option("--reference", &reference_path_, "REF.exr", "reference image (default: render and cache one)");
  cli_.option("--reference-spp", &reference_spp_,
              "samples of the rendered reference (default " + std::to_string(default_spp) + ")", 1, 1 << 20);
}

bool BenchHarness::parse(const std::vector<std::string>& args) {
  if (!cli_.parse(args)) return false;
  if (print_scene_list_if_asked(scene_)) return false;
  set_gl_timing(scene_.stage_timing);
  return true;
}

BenchSetup BenchHarness::setup(bool needs_filter) {
  BenchSetup b = setup_scene(scene_.scene, scene_.env, std::filesystem::path(scene_.scene).stem().string(), needs_filter);
  scene_.width = b.width;  // the scene's own size where --size was not given
  scene_.height = b.height;
  return b;
}

BenchSetup BenchHarness::setup_scene(const std::string& scene, const std::string& env, const std::string& name,
                                     bool needs_filter) const {
  SceneOptions options = scene_;
  options.scene = scene;
  options.env = env;
  BenchSetup b;
  b.filtered = settings_;
  b.scene = load_scene_for(options, b.filtered, cli_);
  b.scene_name = name;
  b.width = options.width;
  b.height = options.height;
  b.out = out_;
  if (needs_filter && !b.filtered.filtering()) throw UsageError("--filter none: nothing to compare against");
  b.plain = b.filtered;
  b.plain.filter.kind = FilterKind::None;
  std::filesystem::create_directories(out_);
  return b;
}

std::unique_ptr<GlContext> BenchHarness::gl_context() const { return create_gl_context(parse_gl_backend(scene_.gl)); }

Image BenchHarness::reference(const BenchSetup& b, const std::string& layer) const {
  if (reference_path_.empty()) return cached_reference(b, layer, 7919, "reference");  // independent of the runs judged
  Image image = read_exr(reference_path_, layer);
  check_reference(image, reference_path_);  // as pxf diff checks its reference
  if (image.width != b.width || image.height != b.height) throw Error("reference size differs from --size");
  return image;
}

Image BenchHarness::second_reference(const BenchSetup& b) const {
  if (!reference_path_.empty()) throw UsageError("--reference: a given reference has no second of another seed");
  return cached_reference(b, "", 7919 + 104729, "reference2");
}

Image BenchHarness::cached_reference(const BenchSetup& b, const std::string& layer, uint64_t seed_offset,
                                     const std::string& prefix) const {
  const auto cache_name = [&](const std::string& kind) {
    return b.out + "/" + prefix + kind + b.scene_name + "_" + std::to_string(b.width) + "x" + std::to_string(b.height) +
           "_" + std::to_string(reference_spp_) + "spp.exr";
  };
  const std::string cache = cache_name(layer == "hv" ? "_hv_" : "_");
  if (std::filesystem::exists(cache)) {
    std::printf("reference: %s (cached)\n", cache.c_str());
  } else {
    TraceParams params = b.plain.trace;
    params.seed = b.plain.trace.seed + seed_offset;
    ProgressiveRenderer renderer(b.scene, params, b.width, b.height);
    const auto start = BenchClock::now();
    for (int i = 0; i < reference_spp_; ++i) {
      renderer.add_frame();
      if ((i + 1) % 256 == 0 || i + 1 == reference_spp_)
        std::fprintf(stderr, "reference: %d/%d spp, %.0f s\n", i + 1, reference_spp_, elapsed_ms(start) / 1000);
    }
    write_exr(cache_name("_"), renderer.unfiltered_image());  // both cached: one render serves both
    write_exr(cache_name("_hv_"), renderer.hv_image());
    std::printf("reference: wrote %s (%d spp, %.1f s)\n", cache.c_str(), reference_spp_, elapsed_ms(start) / 1000);
  }
  Image image = read_exr(cache);
  if (image.width != b.width || image.height != b.height) throw Error("reference size differs from --size");
  return image;
}

std::vector<int> parse_counts(const std::string& option, const std::string& text) {
  std::vector<int> counts;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end || v < 1 || v > 1 << 16) throw UsageError(option + ": '" + item + "' is not a count");
    counts.push_back(static_cast<int>(v));
  }
  return counts;
}

void write_bench_text(const std::string& path, const std::string& text) {
  write_file_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw Error(path + ": cannot write");
  });
}

}  // namespace pxf
