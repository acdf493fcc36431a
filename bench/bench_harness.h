// The measurement harness every `pxf bench` mode shares (bench/bench_command.cpp lists the modes):
// the scene and preview options (--threshold and the rest, preview/setting_table.h), --out, the
// reference options, the loaded scene with its filtered and unfiltered settings, the GL context,
// the cached reference image, and how figures are written. Each mode is a small entry point that
// declares only its own options beside these, with its own defaults.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "app/cli.h"
#include "app/options.h"
#include "gl/context.h"
#include "image/image.h"
#include "preview/preview.h"
#include "scene/scene.h"

namespace pxf {

// A loaded bench scene: the settings as given (filtered) and the same without a filter (plain).
struct BenchSetup {
  Scene scene;
  std::string scene_name;  // the file's stem or the built-in's name (cache and CSV names)
  PreviewSettings filtered, plain;
  int width = 0, height = 0;
  std::string out;
};

class BenchHarness {
 public:
  // `mode`: the mode's name ("" for the default); `summary`: its --help text.
  BenchHarness(const std::string& mode, const std::string& summary);

  CommandLine& cli() { return cli_; }
  // --reference FILE and --reference-spp N (default `default_spp`), for modes that judge against one.
  void add_reference_options(int default_spp);
  // Parses (false: --help was printed, or the scene list: nothing else to do) and applies the GL timing.
  bool parse(const std::vector<std::string>& args);

  // Loads the scene and creates --out. `needs_filter`: --filter none is a usage error (the mode
  // compares filtered against unfiltered).
  BenchSetup setup(bool needs_filter);
  // The same for another scene and light than the command line's (`env` "" for the scene's own),
  // named `name` in the cache and the CSV.
  BenchSetup setup_scene(const std::string& scene, const std::string& env, const std::string& name,
                         bool needs_filter) const;
  std::unique_ptr<GlContext> gl_context() const;
  // --reference, else a --reference-spp plain render of another seed, cached in --out. `layer`
  // "hv": the HV buffer alone (layer hv of a given file). Throws pxf::Error on another size.
  Image reference(const BenchSetup& b, const std::string& layer = "") const;
  // A second --reference-spp render of yet another seed, cached beside the first: how far two
  // references disagree measures the reference's own error (the files bench's --reference-floor).
  // Not with --reference.
  Image second_reference(const BenchSetup& b) const;

  const SceneOptions& scene_options() const { return scene_; }
  const std::string& out() const { return out_; }
  const PreviewSettings& settings() const { return settings_; }
  int reference_spp() const { return reference_spp_; }

 private:
  // The --reference-spp render of seed + seed_offset, cached in --out as PREFIX_NAME_WxH_Nspp.exr,
  // its HV buffer as PREFIX_hv_...; `layer` "hv" reads that one.
  Image cached_reference(const BenchSetup& b, const std::string& layer, uint64_t seed_offset,
                         const std::string& prefix) const;

  CommandLine cli_;
  SceneOptions scene_;
  PreviewSettings settings_;
  std::string out_ = "bench-out";
  std::string reference_path_;
  int reference_spp_ = 2048;
};

// A comma-separated list of counts (1 .. 65536); UsageError names the option.
std::vector<int> parse_counts(const std::string& option, const std::string& text);
// Writes a bench's CSV or text file whole (no partial file on failure).
void write_bench_text(const std::string& path, const std::string& text);

}  // namespace pxf
