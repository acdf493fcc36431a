// pxf diff: image metrics between two images (docs/metrics.md), the same code the tests use:
// HDR metrics, then display-space NRMSE and LDR-FLIP, each also with the emitters masked out.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include <nlohmann/json.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "core/json_depth.h"
#include "gl/cpu_reference.h"
#include "image/image.h"
#include "image/input_file.h"
#include "image/metrics.h"
#include "preview/setting_table.h"

namespace pxf {

namespace {
bool has_rgb(const Image& image) {
  for (const char* c : {"R", "G", "B"})
    if (image.channel_index(c) < 0) return false;
  return true;
}

bool has_layer(const std::vector<Layer>& layers, const std::string& name) {
  for (const Layer& l : layers)
    if (l.name == name) return true;
  return false;
}

// The stats.json a render wrote beside an image, read through one checked reader: read like every
// named input (a FIFO there is refused, not waited on) up to 16 MiB (pxf writes a few KB); every
// value pxf diff uses is checked for its type and range, and any problem is one line naming the
// file. nullopt where there is none, or where it records no settings.
constexpr uint64_t kMaxStatsJsonBytes = uint64_t{16} << 20;
constexpr double kMaxStatsSpp = 2147483647.0;  // a state's frame cap
std::string stats_path_beside(const std::string& image_path) {
  return (std::filesystem::path(image_path).parent_path() / "stats.json").string();
}
struct StatsJson {
  std::string path;
  PreviewSettings settings;  // what it records (read_settings_json), the defaults for the rest
  double settings_spp = 0;   // settings.spp; 0: none
  nlohmann::json compared;   // scene, width, height, the settings and spp (time_budget.spp_reached
                             // where the run had a budget), as checked
};
std::optional<StatsJson> read_stats_beside(const std::string& image_path) {
  StatsJson stats;
  stats.path = stats_path_beside(image_path);
  const std::string& path = stats.path;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  const std::vector<unsigned char> bytes = read_input_file(path, kMaxStatsJsonBytes);
  // dump() recurses when a setting is quoted in an error: a deep file is refused before parsing.
  check_json_depth(reinterpret_cast<const char*>(bytes.data()), bytes.size(), path);
  const nlohmann::json json = nlohmann::json::parse(bytes.begin(), bytes.end(), nullptr, false);
  const auto fail = [&](const std::string& problem) { return Error(path + ": " + problem); };
  if (json.is_discarded()) throw fail("not valid JSON");
  if (!json.is_object()) throw fail("not a JSON object");
  if (!json.contains("settings")) return std::nullopt;
  const nlohmann::json& settings = json["settings"];
  if (!settings.is_object()) throw fail("\"settings\" is not an object");
  try {
    read_settings_json(settings, stats.settings);
  } catch (const Error& e) {
    std::string what = e.what();
    if (what.rfind("stats.json ", 0) == 0) what.erase(0, 11);  // the file is named already
    throw fail(what);
  }
  const auto count = [&](const nlohmann::json& object, const char* key, const std::string& where, double max) {
    if (!object.contains(key)) return -1.0;
    const nlohmann::json& v = object[key];
    const double d = v.is_number() ? v.get<double>() : -1.0;
    if (!(d >= 0 && d <= max && d == std::floor(d)))
      throw fail(where + key + " (" + v.dump() + ") is not a count from 0 to " + std::to_string(static_cast<uint64_t>(max)));
    return d;
  };
  stats.compared = nlohmann::json::object();
  for (const SettingDescriptor& d : setting_table())
    if (settings.contains(d.key)) stats.compared[d.key] = settings[d.key];
  if (settings.contains("scene")) {
    if (!settings["scene"].is_string()) throw fail("settings.scene is not a string");
    stats.compared["scene"] = settings["scene"];
  }
  for (const char* key : {"width", "height"}) {
    const double v = count(settings, key, "settings.", 16384);
    if (v >= 0) stats.compared[key] = v;
  }
  const double spp = count(settings, "spp", "settings.", kMaxStatsSpp);
  stats.settings_spp = std::max(0.0, spp);
  if (spp >= 0) stats.compared["spp"] = spp;
  if (json.contains("time_budget")) {
    if (!json["time_budget"].is_object()) throw fail("\"time_budget\" is not an object");
    const double reached = count(json["time_budget"], "spp_reached", "time_budget.", kMaxStatsSpp);
    stats.compared["spp"] = reached >= 0 ? reached : std::max(0.0, spp);
  }
  return stats;
}

// The emitter mask: --mask FILE's "emitter" layer, else the reference's own when it is a
// buffers.exr that has one (said on stdout), else none.
std::optional<Image> emitter_mask(const std::string& mask_path, const std::string& reference_path) {
  if (!mask_path.empty()) return read_exr(mask_path, "emitter");
  if (!has_layer(read_exr_layers(reference_path), "emitter")) return std::nullopt;
  std::printf("mask: the emitter layer of %s\n", reference_path.c_str());
  return read_exr(reference_path, "emitter");
}

size_t masked_pixels(const Image& mask) {
  size_t n = 0;
  for (size_t p = 0; p < mask.pixel_count(); ++p) n += mask.pixels[p * mask.channels.size()] > 0;
  return n;
}

// compare_images, its errors naming the reference file (the one a user has to fix).
ImageMetrics compare_against(const Image& test, const Image& reference, const std::string& reference_path) {
  try {
    return compare_images(test, reference);
  } catch (const Error& e) {
    throw Error(reference_path + ": " + e.what());
  }
}

// DIR/test.png, DIR/reference.png (both tone-mapped like the display metrics) and DIR/error.png,
// |test - reference| of the display values times 4: where the display error sits.
void write_display_images(const std::string& dir, const Image& test, const Image& reference, float key) {
  const DisplayImages display = tonemap_like_reference(test, reference, key);
  Image error = display.test;
  for (size_t i = 0; i < error.pixels.size(); ++i)
    error.pixels[i] = std::min(1.0f, 4.0f * std::abs(display.test.pixels[i] - display.reference.pixels[i]));
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create the folder for --images: " + ec.message());
  write_png(dir + "/test.png", display.test);
  write_png(dir + "/reference.png", display.reference);
  write_png(dir + "/error.png", error);
  std::printf("wrote %s/test.png, reference.png, error.png (4 x |display difference|)\n", dir.c_str());
}

// The blend's settings of the render that wrote TEST (its stats.json beside it: threshold t and the
// range sigmas of the variance pooling), else the defaults.
struct BlendSettings {
  PreviewSettings settings;  // what stats.json records (read_settings_json), the defaults for the rest
  float frames = 0.0f;       // the run's sample count n (stats.json "spp"); 0: unknown
  std::string source = "the defaults";
};
BlendSettings blend_settings_of(const std::string& buffers_path) {
  BlendSettings b;
  const std::optional<StatsJson> stats = read_stats_beside(buffers_path);
  if (!stats) return b;
  b.settings = stats->settings;
  b.frames = static_cast<float>(stats->settings_spp);
  b.source = stats->path;
  return b;
}

const Image& layer_of(const std::vector<Layer>& layers, const std::string& name, const std::string& path) {
  try {
    return layer_image(layers, name);
  } catch (const Error&) {
    throw Error(path + ": no '" + name + "' layer (--perfect-filter needs the buffers.exr of a render)");
  }
}

void print_error_line(const char* label, const Image& test, const Image& reference, const DisplayMetricOptions& o) {
  const DisplayMetrics m = compare_display(test, reference, nullptr, o);
  std::printf("%s: HDR NRMSE %.4f %%  display NRMSE %.4f %%\n", label, m.hdr.nrmse_percent, m.display_nrmse_percent);
}

// L_lv with each pixel's threshold factor as its alpha, as the preview uploads it for an adaptive
// render (Preview::upload): the pixel's threshold t_{n_p} (its own count, the samples layer)
// against the run's t_n.
Image with_threshold_factors(const Image& lv, const Image& samples, float threshold, float t_run) {
  Image out = Image::rgba(lv.width, lv.height);
  for (int y = 0; y < lv.height; ++y)
    for (int x = 0; x < lv.width; ++x) {
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = lv.at(x, y, c);
      const float t_pixel = effective_threshold(threshold, static_cast<uint64_t>(samples.at(x, y, 0)));
      out.at(x, y, 3) = t_run > 0.0f ? t_pixel / t_run : 1.0f;
    }
  return out;
}

// --perfect-filter: where TEST's error comes from. The blend is run again on TEST's own buffers
// with a perfect filter, L_f = REFERENCE's HV and Var[L_f] = 0, at TEST's threshold and sample
// count: what remains is the noise the blend keeps at t and LV's error, the least any filter could
// leave under this blend. Beside it TEST unfiltered (lv + hv) and TEST's LV with REFERENCE's HV
// (LV's error alone), all against REFERENCE's final. Without the bias guard (BlendParams'
// default): a perfect L_f has no bias for it to find, only L_u's noise to mistake for one.
void print_perfect_filter(const std::string& test_path, const std::string& reference_path,
                          const DisplayMetricOptions& display) {
  const std::vector<Layer> test = read_exr_layers(test_path), reference = read_exr_layers(reference_path);
  const Image& lv = layer_of(test, "lv", test_path);
  const Image& hv = layer_of(test, "hv", test_path);
  const Image& samples = layer_of(test, "samples", test_path);
  const Image& ref_final = layer_of(reference, "final", reference_path);
  const Image& ref_hv = layer_of(reference, "hv", reference_path);
  if (ref_hv.width != hv.width || ref_hv.height != hv.height)
    throw Error(reference_path + ": " + std::to_string(ref_hv.width) + "x" + std::to_string(ref_hv.height) +
                ", " + test_path + ": " + std::to_string(hv.width) + "x" + std::to_string(hv.height));
  const BlendSettings read = blend_settings_of(test_path);
  const PreviewSettings& settings = read.settings;
  const float spp = read.frames > 0.0f ? read.frames
                    : samples.pixels.empty() ? 0.0f
                                             : *std::max_element(samples.pixels.begin(), samples.pixels.end());
  const float t = effective_threshold(settings.threshold, static_cast<uint64_t>(spp));
  FilterOutput perfect;
  perfect.filtered = ref_hv;
  perfect.variance = Image::gray(hv.width, hv.height);
  const Image lv_with_factors = settings.adaptive ? with_threshold_factors(lv, samples, settings.threshold, t) : lv;
  const BlendOutput blended = cpu_blend(lv_with_factors, hv, layer_of(test, "var_u", test_path), &perfect, t,
                                        BlendParams{range_weights(settings.filter), false, spp},
                                        &layer_of(test, "range_color", test_path), &layer_of(test, "depth", test_path));
  std::printf("perfect filter: t %g (%g at %.0f spp), sigma_c %g, sigma_d %g from %s\n", settings.threshold, t, spp,
              settings.filter.sigma_c, settings.filter.sigma_d, read.source.c_str());
  print_error_line("blend with a perfect filter", blended.final_rgb, ref_final, display);
  print_error_line("unfiltered (lv + hv)", sum_of(lv, hv), ref_final, display);
  print_error_line("lv + reference hv", sum_of(lv, ref_hv), ref_final, display);
}

// --second-reference: the correction holds only for a second reference rendered like the first with
// independent noise. Where both have a stats.json beside them, a second reference of the same seed
// (the same noise), of another sample count (another noise level) or of another scene or size is
// an error (a setting only one of them records, like the sampler before stats.json had it, is not
// compared); without them nothing can be checked, which is said.
void check_second_reference(const std::string& reference_path, const std::string& second_path) {
  auto settings_of = [](const std::string& path) -> std::optional<nlohmann::json> {
    const std::optional<StatsJson> stats = read_stats_beside(path);
    if (!stats) return std::nullopt;
    return stats->compared;
  };
  const std::optional<nlohmann::json> first = settings_of(reference_path), second = settings_of(second_path);
  if (!first || !second) {
    std::printf("second reference: no stats.json beside both references; they must be renders of the same\n"
                "  scene with the same sample count and different seeds, which cannot be checked here\n");
    return;
  }
  // The scene, size and sample count, and every setting that changes the samples but the seed.
  std::vector<std::string> keys{"scene", "width", "height", "spp"};
  for (const SettingDescriptor& d : setting_table())
    if (d.effect == SettingEffect::Retrace && std::string(d.key) != "seed") keys.push_back(d.key);
  for (const std::string& key : keys)
    if (first->contains(key) && second->contains(key) && (*first)[key] != (*second)[key])
      throw Error(second_path + ": its " + key + " (" + (*second)[key].dump() +
                  ") differs from the reference's (" + (*first)[key].dump() +
                  "); --second-reference needs a render like the reference's with another seed");
  if (first->value("seed", -1) == second->value("seed", -1))
    throw Error(second_path + ": the same seed as the reference, so the same noise; --second-reference needs "
                "another seed");
}

// The error against the truth from two references (correct_for_reference_noise), on all pixels.
void print_noise_corrected(const Image& test, const Image& reference, const Image& second,
                           const DisplayMetricOptions& o) {
  const DisplayMetrics raw = compare_display(test, reference, nullptr, o);
  const DisplayMetrics references = compare_display(second, reference, nullptr, o);
  const ReferenceNoiseCorrection hdr =
      correct_for_reference_noise(raw.hdr.nrmse_percent, references.hdr.nrmse_percent);
  const ReferenceNoiseCorrection display =
      correct_for_reference_noise(raw.display_nrmse_percent, references.display_nrmse_percent);
  std::printf("reference noise: HDR NRMSE %.4f %%  display NRMSE %.4f %%\n", hdr.reference_noise_percent,
              display.reference_noise_percent);
  std::printf("noise-corrected: HDR NRMSE %.4f %%  display NRMSE %.4f %%%s\n", hdr.corrected_percent,
              display.corrected_percent,
              hdr.within_reference_noise || display.within_reference_noise
                  ? "  (0: within the reference's noise, no error can be told)"
                  : "");
}

void print_display(const char* label, const DisplayMetrics& m, const OutlierMetrics& o) {
  std::printf("%s: HDR NRMSE %.4f %%  display NRMSE %.4f %%  FLIP %.6f  outliers (Y > 5x reference) %zu (%.4f %%)\n",
              label, m.hdr.nrmse_percent, m.display_nrmse_percent, m.flip_mean, o.outliers, 100.0 * o.fraction);
}
}  // namespace

int run_diff(const Args& args) {
  std::string test_path, reference_path, second_path, layer, reference_layer, mask_path, images_dir;
  double max_nrmse = -1, max_flip = -1;
  bool perfect_filter = false;
  DisplayMetricOptions display;
  CommandLine cli("diff", "TEST.exr REFERENCE.exr [options]",
                  "Prints NRMSE (% of the reference mean), RMSE, relative MSE, max |difference|, the mean\n"
                  "ratio (test / reference) and the NaN/Inf count of TEST against REFERENCE over their shared\n"
                  "color channels. For RGB images\n"
                  "also the display-space NRMSE (both tone-mapped with the reference's Reinhard key and\n"
                  "log-average luminance, compared as sRGB values) and the mean LDR-FLIP of those display\n"
                  "images and the count of outlier pixels (luminance above 5x the reference's, the reference floored\n"
                  "at 1 % of its mean luminance), each again with the emitters masked out when a mask is known.");
  cli.positional("TEST.exr", &test_path, "image to judge (EXR)");
  cli.positional("REFERENCE.exr", &reference_path, "reference image (EXR)");
  cli.option("--layer", &layer, "NAME", "layer of TEST to compare (default: the unnamed layer, else the first)");
  cli.option("--reference-layer", &reference_layer, "NAME", "layer of REFERENCE (default: same as --layer)");
  cli.option("--mask", &mask_path, "FILE.exr",
             "leave out pixels whose 'emitter' layer is > 0 (default: REFERENCE's own emitter layer, if any)");
  cli.option("--key", &display.key, "Reinhard key of the display tone map", 1e-4f, 100.0f);
  cli.option("--ppd", &display.pixels_per_degree, "FLIP's pixels per degree of visual angle", 1.0, 1000.0);
  cli.option("--max-nrmse", &max_nrmse, "exit with code 1 when the HDR NRMSE (%) is above this", 0.0, 1e9);
  cli.option("--max-flip", &max_flip, "exit with code 1 when the mean FLIP (all pixels) is above this", 0.0, 1.0);
  cli.option("--images", &images_dir, "DIR",
             "write DIR/test.png, reference.png (display values) and error.png (4 x |difference|)");
  cli.flag("--perfect-filter", &perfect_filter,
           "TEST and REFERENCE are a render's and a reference render's buffers.exr: also the error of\n"
           "TEST blended again with a perfect filter (L_f = REFERENCE's hv, Var[L_f] = 0; t and sigmas\n"
           "from TEST's stats.json), of TEST unfiltered, and of TEST's lv with REFERENCE's hv");
  cli.option("--second-reference", &second_path, "FILE.exr",
             "a second reference, rendered like REFERENCE with another seed: also REFERENCE's own noise\n"
             "(their NRMSE / sqrt 2) and TEST's error against the truth with that noise taken out,\n"
             "NRMSE^2(TEST, REFERENCE) - NRMSE^2(SECOND, REFERENCE) / 2 (HDR and display, all pixels)");
  if (!cli.parse(args)) return 0;
  if (!cli.given("--reference-layer")) reference_layer = layer;

  const Image test = read_exr(test_path, layer);
  const Image reference = read_exr(reference_path, reference_layer);
  check_reference(reference, reference_path);
  const ImageMetrics m = compare_against(test, reference, reference_path);
  std::printf("%s\n", format_metrics(m).c_str());
  if (m.nan_count + m.inf_count > 0) {
    std::fprintf(stderr, "pxf diff: %s has %zu non-finite samples\n", test_path.c_str(), m.nan_count + m.inf_count);
    return 1;
  }
  double flip = -1;
  if (has_rgb(test) && has_rgb(reference)) {
    const std::optional<Image> mask = emitter_mask(mask_path, reference_path);
    const DisplayMetrics all = compare_display(test, reference, nullptr, display);
    print_display("all pixels", all, count_outliers(test, reference));
    flip = all.flip_mean;
    if (!images_dir.empty()) write_display_images(images_dir, test, reference, display.key);
    if (mask) {
      const DisplayMetrics masked = compare_display(test, reference, &*mask, display);
      char label[64];
      std::snprintf(label, sizeof label, "emitters masked (%zu pixels)", masked_pixels(*mask));
      print_display(label, masked, count_outliers(test, reference, &*mask));
    }
  } else {
    std::printf("display metrics: skipped, the images have no R,G,B channels\n");
  }
  if (!second_path.empty()) {
    if (!has_rgb(test) || !has_rgb(reference)) throw Error("--second-reference needs R,G,B images");
    check_second_reference(reference_path, second_path);
    const Image second = read_exr(second_path, reference_layer);
    check_reference(second, second_path);
    print_noise_corrected(test, reference, second, display);
  }
  if (perfect_filter) print_perfect_filter(test_path, reference_path, display);
  if (max_nrmse >= 0 && m.nrmse_percent > max_nrmse) {
    std::fprintf(stderr, "pxf diff: NRMSE %.4f %% is above --max-nrmse %.4f %%\n", m.nrmse_percent, max_nrmse);
    return 1;
  }
  if (max_flip >= 0 && flip < 0) {
    std::fprintf(stderr, "pxf diff: --max-flip needs R,G,B images\n");
    return 1;
  }
  if (max_flip >= 0 && flip > max_flip) {
    std::fprintf(stderr, "pxf diff: FLIP %.6f is above --max-flip %.6f\n", flip, max_flip);
    return 1;
  }
  return 0;
}

}  // namespace pxf
