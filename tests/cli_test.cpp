// The pxf command line end to end: exit codes, one-line errors,
// no partial output, Ctrl-C, and `pxf diff` on EXRs written by another writer.
#include <gtest/gtest.h>

#include <OpenEXR/ImfRgbaFile.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/output_set.h"
#include "gl/pass_params.h"
#include "image/image.h"
#include "image/metrics.h"
#include "pathtracer/pathtracer.h"
#include "scene/load.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {

using Result = test_support::PxfResult;

std::string temp_dir(const std::string& name) { return test_support::temp_dir("cli", name); }
using test_support::slurp;

Result run(const std::string& args) { return test_support::run_pxf(args, "cli"); }

size_t lines(const std::string& text) { return std::count(text.begin(), text.end(), '\n'); }

void write_half_rgba(const std::string& path, const std::vector<float>& rgb, int w, int h) {
  std::vector<Imf::Rgba> pixels(w * h);
  for (int i = 0; i < w * h; ++i) pixels[i] = Imf::Rgba(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2], 1.0f);
  Imf::RgbaOutputFile file(path.c_str(), w, h, Imf::WRITE_RGBA);
  file.setFrameBuffer(pixels.data(), 1, w);
  file.writePixels(h);
}

}  // namespace

TEST(Cli, UsageErrorsExitWithCode2AndOneLine) {
  for (const char* args : {"", "bogus", "render --nope", "render --spp 0", "render --spp", "render --size 3",
                           "render --threshold -1", "render --filter gauss", "render --gl window", "bench --budgets 4,x",
                           "bench variants --subsampled-taps 0", "bench adaptive motion", "bench bogus",
                           "bench pathtracer --clean-cap 3", "bench --adaptive maybe",
                           "diff only-one.exr", "explore --sigma-s abc", "render --time 0", "render --time -3",
                           "render --time nan", "render --time 1e99", "render --time soon", "render --schedule x"}) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    if (std::string(args).find(' ') != std::string::npos) {
      EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
    }
  }
}

TEST(Cli, EveryCommandHasHelp) {
  for (const char* command : {"render", "explore", "bench", "diff"}) {
    const Result r = run(std::string(command) + " --help");
    EXPECT_EQ(r.code, 0) << command;
    EXPECT_NE(r.out.find("usage: pxf " + std::string(command)), std::string::npos) << command;
  }
  EXPECT_EQ(run("--help").code, 0);
}

// Each bench mode is its own entry point (bench/bench_command.cpp), named by a word that is no
// setting: pxf bench --help lists them, a mode's --help shows its own options and not another's,
// and an option of another mode is an error. --adaptive is the setting in every mode.
TEST(Cli, BenchModesHaveTheirOwnOptions) {
  const Result list = run("bench --help");
  ASSERT_EQ(list.code, 0);
  for (const char* mode : {"pathtracer", "sampler-error", "variance-ratio", "variants", "stage-table",
                           "threshold-fidelity", "guiding-ab", "guiding-bound", "adaptive", "demodulation-ab", "motion"})
    EXPECT_NE(list.out.find(std::string("\n  ") + mode + " "), std::string::npos) << mode;
  const Result adaptive = run("bench adaptive --help");
  ASSERT_EQ(adaptive.code, 0);
  EXPECT_NE(adaptive.out.find("usage: pxf bench adaptive"), std::string::npos);
  for (const char* own : {"--clean-cap", "--budgets", "--rounds", "--threshold", "--reference", "--adaptive"})
    EXPECT_NE(adaptive.out.find(own), std::string::npos) << own;
  for (const char* other : {"--variant-spp", "--motion-frames", "--timed-frames"})
    EXPECT_EQ(adaptive.out.find(other), std::string::npos) << other;
  EXPECT_NE(run("bench adaptive --variant-spp 3").err.find("--variant-spp"), std::string::npos);
  const Result setting = run("bench --adaptive on --help");
  ASSERT_EQ(setting.code, 0) << setting.err;
  EXPECT_NE(setting.out.find("usage: pxf bench [options]"), std::string::npos) << setting.out;
}

// The guiding bound end to end, tiny: every point's row in the CSV, the summary and the image's
// bound printed; an odd cell count is refused in one line.
TEST(Cli, GuidingBoundWritesItsTable) {
  const std::string out = temp_dir("guiding_bound");
  const Result r = run("bench guiding-bound --scene atrium --size 32x18 --points 3 --cells 4 --paths 2 --frames 1 "
                       "--floor-directions 4 --floor-paths 2 --spp 2 --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("floor of any guide"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("at least"), std::string::npos) << r.out;
  EXPECT_EQ(lines(slurp(out + "/guiding_bound.csv")), 4u);  // the header and 3 points
  const Result odd = run("bench guiding-bound --cells 5 --out " + out);
  EXPECT_EQ(odd.code, 2);
  EXPECT_EQ(lines(odd.err), 1u) << odd.err;
}

// The files bench end to end, tiny: a row per file and budget in the CSV, a contact sheet of a row
// per file and two columns per budget plus the reference; a bad list is refused in one line.
// The first data row of a CSV, by the header's column names (empty fields kept).
std::map<std::string, std::string> csv_first_row(const std::string& csv) {
  const auto fields = [](const std::string& line) {
    std::vector<std::string> out;
    std::stringstream in(line);
    for (std::string f; std::getline(in, f, ',');) out.push_back(f);
    if (!line.empty() && line.back() == ',') out.push_back("");
    return out;
  };
  std::stringstream in(csv);
  std::string header, first;
  std::getline(in, header);
  std::getline(in, first);
  const std::vector<std::string> names = fields(header), values = fields(first);
  std::map<std::string, std::string> row;
  for (size_t i = 0; i < names.size(); ++i) row[names[i]] = i < values.size() ? values[i] : "?";
  return row;
}

// `pxf bench files` at 16x12 with 4-spp references over the list `list`, in a new folder `name`;
// returns the folder.
std::string run_files_bench(const std::string& name, const std::string& list, const std::string& options) {
  const std::string out = temp_dir(name);
  fs::create_directories(out);
  std::ofstream(out + "/list.txt") << list;
  const Result r = run("bench files --list " + out + "/list.txt --size 16x12 --reference-spp 4 " + options +
                       " --out " + out);
  EXPECT_EQ(r.code, 0) << r.err;
  return out;
}

TEST(Cli, FilesBenchWritesItsTableAndSheet) {
  const std::string out =
      run_files_bench("files_bench", "# name scene [env]\ncornell cornell\nbox cornell -\n", "--times 0.2,0.3 --rounds 2");
  const std::string csv = slurp(out + "/files.csv");
  EXPECT_EQ(lines(csv), 5u);  // the header, 2 files x 2 budgets
  // The filtered image's mean bias against its own samples is a finite percentage; without
  // --reference-floor the floor's columns are empty.
  const std::map<std::string, std::string> row = csv_first_row(csv);
  const double bias = std::stod(row.at("filtered_mean_bias_percent"));
  EXPECT_TRUE(std::isfinite(bias) && std::abs(bias) < 100.0) << bias;
  EXPECT_EQ(row.at("reference_display_floor_percent"), "");
  EXPECT_EQ(row.at("display_ratio_above_floor"), "");
  const Image sheet = read_ldr_or_hdr(out + "/files_sheet.png");
  EXPECT_EQ(sheet.width, 5 * (16 + 2));
  EXPECT_EQ(sheet.height, 2 * (12 + 2));
  std::ofstream(out + "/bad.txt") << "a cornell\na cornell\n";
  const Result bad = run("bench files --list " + out + "/bad.txt --out " + out);
  EXPECT_EQ(bad.code, 1);
  EXPECT_EQ(lines(bad.err), 1u) << bad.err;
  EXPECT_NE(bad.err.find("bad.txt:2: the name 'a' is used twice"), std::string::npos) << bad.err;
}

// --reference-floor: the reference's own error is its difference from a second reference of
// another seed over sqrt 2, and the ratio above it takes that off both arms' squared errors.
TEST(Cli, FilesBenchReferenceFloorIsTheTwoReferencesDifference) {
  const std::string out = run_files_bench("files_floor", "cornell cornell\n", "--times 0.3 --rounds 1 --reference-floor");
  const std::map<std::string, std::string> row = csv_first_row(slurp(out + "/files.csv"));
  const Image reference = read_exr(out + "/reference_cornell_16x12_4spp.exr");
  const Image second = read_exr(out + "/reference2_cornell_16x12_4spp.exr");
  const DisplayMetrics pair = compare_display(second, reference);
  const double display_floor = std::stod(row.at("reference_display_floor_percent"));
  EXPECT_GT(display_floor, 0.1);  // 4 spp of another seed: the references differ
  EXPECT_NEAR(display_floor, pair.display_nrmse_percent / std::sqrt(2.0), 1e-4 * display_floor);
  const double hdr_floor = std::stod(row.at("reference_hdr_floor_percent"));
  EXPECT_NEAR(hdr_floor, pair.hdr.nrmse_percent / std::sqrt(2.0), 1e-4 * hdr_floor);
  EXPECT_NEAR(std::stod(row.at("reference_pair_flip")), pair.flip_mean, 1e-4 * pair.flip_mean);
  const double u = std::stod(row.at("unfiltered_display_nrmse_percent"));
  const double f = std::stod(row.at("filtered_display_nrmse_percent"));
  const std::string above = row.at("display_ratio_above_floor");
  if (u > display_floor)
    EXPECT_NEAR(std::stod(above), std::sqrt(std::max(0.0, f * f - display_floor * display_floor) /
                                            (u * u - display_floor * display_floor)), 1e-3);
  else
    EXPECT_EQ(above, "nan");
}

TEST(Cli, SceneListPrintsTheBuiltins) {
  const Result r = run("render --scene list");
  EXPECT_EQ(r.code, 0);
  for (const char* name : {"cornell", "atrium", "kitchen", "envmap", "product", "window"}) EXPECT_NE(r.out.find(name), std::string::npos);
}

TEST(Cli, BadSceneIsOneLineNamingTheFileAndWritesNothing) {
  const std::string out = temp_dir("bad_scene");
  const std::string scene = temp_dir("x") + "/broken.gltf";
  fs::create_directories(fs::path(scene).parent_path());
  std::ofstream(scene) << "{ \"asset\": { \"version\": \"2.0\" }, \"meshes\": [ {";  // malformed JSON
  const Result r = run("render --scene " + scene + " --out " + out);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("broken.gltf"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  const Result missing = run("render --scene /nonexistent/scene.gltf --out " + out);
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("/nonexistent/scene.gltf"), std::string::npos) << missing.err;
}

TEST(Cli, TriangleCapIsAFlagOfRenderAndBench) {
  const std::string dir = temp_dir("triangle_cap");
  const std::string scene = test_support::write_bare_triangle(dir);
  const std::string out = dir + "/out";
  for (const char* command : {"render", "bench"}) {
    const Result r = run(std::string(command) + " --scene " + scene + " --max-triangles 1 --max-triangles 0 --out " + out);
    EXPECT_EQ(r.code, 2) << command << ": " << r.err;  // 0 is outside the flag's range
  }
  EXPECT_NE(run("render --help").out.find("--max-texture-size"), std::string::npos);
  const std::string two = dir + "/two.gltf";
  {
    std::ifstream in(scene);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto replace = [&](const std::string& from, const std::string& to) { text.replace(text.find(from), from.size(), to); };
    replace(R"("nodes":[0])", R"("nodes":[0,1])");
    replace(R"("nodes":[{"mesh":0}])", R"("nodes":[{"mesh":0},{"mesh":0}])");
    std::ofstream(two) << text;
  }
  const Result r = run("render --scene " + two + " --max-triangles 1 --size 16x16 --spp 1 --out " + out);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("the scene instances 2 triangles, over the limit of 1 (raise it with --max-triangles)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(run("render --scene " + two + " --max-triangles 2 --size 16x16 --spp 1 --out " + out).code, 0);
}

TEST(Cli, SceneWithoutLightsIsLitByDefaultAndNoneWarnsOfBlack) {
  const std::string dir = temp_dir("bare");
  const std::string scene = test_support::write_bare_triangle(dir);
  const Result lit = run("render --scene " + scene + " --size 16x16 --spp 2 --filter none --quiet --out " + dir + "/lit");
  ASSERT_EQ(lit.code, 0) << lit.err;
  EXPECT_NE(lit.err.find("lit by the built-in sky"), std::string::npos) << lit.err;
  const Image image = read_exr(dir + "/lit/final.exr");
  float peak = 0.0f;
  for (float v : image.pixels) peak = std::max(peak, v);
  EXPECT_GT(peak, 0.05f);
  const Result dark = run("render --scene " + scene + " --default-light none --size 16x16 --spp 2 --quiet --out " + dir + "/dark");
  ASSERT_EQ(dark.code, 0) << dark.err;
  EXPECT_NE(dark.err.find("warning"), std::string::npos) << dark.err;
  EXPECT_NE(dark.err.find("will be black"), std::string::npos) << dark.err;
  // An environment image given as the scene: one line naming it, exit code 1.
  write_exr(dir + "/sky.exr", Image::rgb(4, 2, 1.0f));
  const Result wrong = run("render --scene " + dir + "/sky.exr --quiet --out " + dir + "/wrong");
  EXPECT_EQ(wrong.code, 1);
  EXPECT_EQ(lines(wrong.err), 1u) << wrong.err;
  EXPECT_NE(wrong.err.find("not a scene"), std::string::npos) << wrong.err;
}

TEST(Cli, AllHvAndEnvironmentLitRendersDefaultToAtrousUnlessFilterIsGiven) {
  const std::string out = temp_dir("allhv");
  const Result r = run("render --scene envmap --all-hv --size 24x16 --spp 2 --quiet --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("filter atrous"), std::string::npos) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(out + "/stats.json"))["settings"]["filter"], "atrous");
  const Result chosen = run("render --scene envmap --all-hv --size 24x16 --spp 2 --quiet --filter grid --out " + out);
  ASSERT_EQ(chosen.code, 0) << chosen.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(out + "/stats.json"))["settings"]["filter"], "grid");
  // envmap, lit by its environment alone, takes it without all_hv; cornell, lit by an emitter, keeps
  // the default (docs/measurements.md, "Environment-lit scenes").
  const Result plain = run("render --scene envmap --size 24x16 --spp 2 --quiet --out " + out);
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_NE(plain.err.find("lit mostly by its environment: filter atrous"), std::string::npos) << plain.err;
  const nlohmann::json stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_EQ(stats["settings"]["filter"], "atrous");
  EXPECT_EQ(stats["settings"]["all_hv"], false);
  const Result emitter = run("render --scene cornell --size 24x16 --spp 2 --quiet --out " + out);
  ASSERT_EQ(emitter.code, 0) << emitter.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(out + "/stats.json"))["settings"]["filter"], "grid");
}

// --adaptive on: off by default, recorded in stats.json with the paths per pixel; after
// the 16 uniform warm-up frames the pixels' counts part, the same with one thread and two. (Its
// states: tests/checkpoint_test.cpp.)
TEST(Cli, AdaptiveRenderRecordsItsPixelCounts) {
  const std::string out = temp_dir("adaptive");
  ASSERT_EQ(run("render --size 32x24 --spp 4 --quiet --out " + out).code, 0);
  const auto uniform = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_EQ(uniform["settings"]["adaptive"], false);
  EXPECT_EQ(uniform["samples_per_pixel"]["mean"].get<double>(), 4.0);
  EXPECT_EQ(uniform["samples_per_pixel"]["max"], 4);
  const Result r = run("render --size 32x24 --spp 48 --threshold 0.05 --adaptive on --quiet --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto adaptive = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_EQ(adaptive["settings"]["adaptive"], true);
  // A frame traces as many paths as a uniform one, placed where they are needed: the mean stays at
  // the frames, the counts part from the warm-up's 16 on, down to the floor's and up past the frames.
  EXPECT_NEAR(adaptive["samples_per_pixel"]["mean"].get<double>(), 48.0, 1.0);
  EXPECT_GT(adaptive["samples_per_pixel"]["max"].get<int>(), 48);
  EXPECT_GE(adaptive["samples_per_pixel"]["min"].get<int>(), 16 + (48 - 16) / 16);  // warm-up, then the floor
  EXPECT_LT(adaptive["samples_per_pixel"]["min"].get<int>(), 48);
  // The whole adaptive render (allocation, its guide, the masked frames) does not depend on the
  // thread count: the same samples, bit for bit, with one thread and with two.
  std::vector<Layer> by_threads[2];
  for (int threads = 1; threads <= 2; ++threads) {
    const std::string dir = out + "_threads" + std::to_string(threads);
    ASSERT_EQ(run("render --size 32x24 --spp 40 --threshold 0.05 --adaptive on --quiet --threads " +
                  std::to_string(threads) + " --out " + dir).code, 0);
    by_threads[threads - 1] = read_exr_layers(dir + "/buffers.exr");
  }
  for (const char* layer : {"lv", "hv", "var_u", "samples", "final"})
    EXPECT_EQ(layer_image(by_threads[0], layer).pixels, layer_image(by_threads[1], layer).pixels) << layer;
}

TEST(Cli, RenderWritesEveryOutput) {
  const std::string out = temp_dir("render");
  const Result r = run("render --size 32x24 --spp 4 --schedule pow2 --quiet --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* file : {"final.png", "final.exr", "buffers.exr", "stats.json"}) EXPECT_TRUE(fs::exists(out + "/" + file));
  std::vector<std::string> names;
  for (const Layer& l : read_exr_layers(out + "/buffers.exr")) names.push_back(l.name);
  for (const char* layer :
       {"final", "lv", "hv", "hv_filtered", "var_u", "var_f", "blend", "range_color", "depth", "emitter", "albedo"})
    EXPECT_NE(std::find(names.begin(), names.end(), layer), names.end()) << layer;
  const auto stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_EQ(stats["settings"]["spp"], 4);
  EXPECT_EQ(stats["filter_runs"], 3);  // 1, 2, 4
  EXPECT_EQ(stats["settings"]["demodulate"], true);
  EXPECT_EQ(stats["settings"]["bias_guard"], true);
  EXPECT_EQ(stats["settings"]["sampler"], "sobol");
  EXPECT_TRUE(stats["blend_case_pixels"].contains("bias_guard"));
  EXPECT_EQ(stats["filter_runs_skipped_low_hv"], 0);
  EXPECT_GT(stats["hv_energy_share"].get<double>(), 0.01);
  for (const char* stage : {"path_tracing", "upload", "range", "filter", "blend", "tonemap"})
    EXPECT_TRUE(stats["stage_ms_total"].contains(stage)) << stage;
  EXPECT_GT(stats["paths_per_second"].get<double>(), 0.0);
  EXPECT_GT(stats["load_ms"].get<double>(), 0.0);
  EXPECT_GT(stats["peak_memory_mib"].get<double>(), 1.0);  // at least the program itself
  // A reference render, then NRMSE against it.
  const std::string ref = temp_dir("reference");
  ASSERT_EQ(run("render --size 32x24 --spp 64 --filter none --seed 9 --quiet --out " + ref).code, 0);
  const Result with_ref = run("render --size 32x24 --spp 4 --quiet --reference " + ref + "/final.exr --out " + out);
  ASSERT_EQ(with_ref.code, 0) << with_ref.err;
  const auto stats2 = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_GT(stats2["final_vs_reference"]["nrmse_percent"].get<double>(), 0.0);
  // --demodulate off is recorded; a bad value is a usage error.
  ASSERT_EQ(run("render --size 32x24 --spp 2 --demodulate off --quiet --out " + out).code, 0);
  EXPECT_EQ(nlohmann::json::parse(slurp(out + "/stats.json"))["settings"]["demodulate"], false);
  EXPECT_EQ(run("render --size 32x24 --spp 2 --demodulate maybe --quiet --out " + out).code, 2);
  // So is --bias-guard off.
  ASSERT_EQ(run("render --size 32x24 --spp 2 --bias-guard off --quiet --out " + out).code, 0);
  EXPECT_EQ(nlohmann::json::parse(slurp(out + "/stats.json"))["settings"]["bias_guard"], false);
  EXPECT_EQ(run("render --size 32x24 --spp 2 --bias-guard maybe --quiet --out " + out).code, 2);
  // The filter's sigma_s shrinks to the noise (--sigma-shrink on, the default): the full 8 px up to
  // 4 spp, between 2 and 8 px later, less at 256 spp than at 16; --sigma-shrink off keeps 8 px.
  // stats.json records the setting and the last run's sigma_s.
  EXPECT_EQ(stats["settings"]["sigma_shrink"], true);
  EXPECT_EQ(stats["filter_last_sigma_s"].get<double>(), 8.0);
  auto last_sigma = [&](const std::string& flags) {
    EXPECT_EQ(run("render --size 32x24 --quiet " + flags + " --out " + out).code, 0);
    return nlohmann::json::parse(slurp(out + "/stats.json"))["filter_last_sigma_s"].get<double>();
  };
  const double at_16 = last_sigma("--spp 16"), at_256 = last_sigma("--spp 256");
  EXPECT_GE(at_256, 2.0);
  EXPECT_LT(at_256, at_16);
  EXPECT_LE(at_16, 8.0);
  EXPECT_EQ(last_sigma("--spp 256 --sigma-shrink off"), 8.0);
  EXPECT_EQ(nlohmann::json::parse(slurp(out + "/stats.json"))["settings"]["sigma_shrink"], false);
  EXPECT_EQ(run("render --size 32x24 --spp 2 --sigma-shrink maybe --quiet --out " + out).code, 2);
  // Specular sampling is off unless asked for, the specular chains on unless turned off, and
  // stats.json says which.
  EXPECT_EQ(stats2["settings"]["specular_sampling"], false);
  EXPECT_EQ(stats2["settings"]["specular_chains"], true);
  ASSERT_EQ(run("render --size 32x24 --spp 2 --specular-sampling --specular-chains off --quiet --out " + out).code, 0);
  const auto stats3 = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_EQ(stats3["settings"]["specular_sampling"], true);
  EXPECT_EQ(stats3["settings"]["specular_chains"], false);
  EXPECT_EQ(run("render --size 32x24 --spp 2 --specular-chains maybe --quiet --out " + out).code, 2);
  // The option's earlier name is not taken.
  EXPECT_EQ(run("render --size 32x24 --spp 2 --near-specular on --quiet --out " + out).code, 2);
  EXPECT_GT(stats2["unfiltered_vs_reference"]["nrmse_percent"].get<double>(), 0.0);
}

TEST(Cli, BenchVariantsTabulatesEveryFilterVariant) {
  // The reference's HV from the buffers.exr of an unfiltered render; a row and an image per variant.
  const std::string ref = temp_dir("variants_reference"), out = temp_dir("variants");
  ASSERT_EQ(run("render --size 24x16 --spp 32 --filter none --seed 9 --quiet --out " + ref).code, 0);
  const Result r = run("bench variants --size 24x16 --variant-rounds 1 --subsampled-taps 8 --reference " + ref +
                       "/buffers.exr --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = slurp(out + "/variants.csv");
  std::vector<std::string> rows = filter_kind_names();
  rows.push_back("subsampled-8");
  for (const std::string& name : rows) {
    EXPECT_NE(csv.find("\n" + name + ","), std::string::npos) << name;
    EXPECT_TRUE(fs::exists(out + "/variant_" + name + ".png")) << name;
  }
  EXPECT_EQ(lines(csv), rows.size() + 2);  // the header and the unfiltered row
  EXPECT_TRUE(fs::exists(out + "/variants.svg"));
}

// The sampler-error bench: a row per sampler and spp, and where the squared error sits (shares of the
// unfiltered image's: LV's, of which the emitter pixels', HV's, of which its worst 1 % of pixels').
TEST(Cli, BenchSamplerErrorSaysWhereTheErrorSits) {
  const std::string out = temp_dir("sampler_error");
  const Result r = run("bench sampler-error --size 24x24 --seeds 2 --spp 2,4 --reference-spp 32 "
                       "--rounds 1 --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("where the squared error sits"), std::string::npos) << r.out;
  std::istringstream csv(slurp(out + "/sampler_error_cornell.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.substr(line.rfind(',') + 1), "hv_worst1_share");
  int rows = 0;
  while (std::getline(csv, line)) {
    std::vector<double> v;
    std::istringstream fields(line.substr(line.find(',', line.find(',') + 1) + 1));  // after scene, sampler
    for (std::string f; std::getline(fields, f, ',');) v.push_back(std::stod(f));
    ASSERT_EQ(v.size(), 9u) << line;  // spp, seeds, 3 NRMSE, 4 shares
    const double lv = v[5], lv_emitters = v[6], hv = v[7], hv_worst = v[8];
    EXPECT_GT(lv_emitters, 0.0) << line;  // the ceiling light is in view, its edges are noisy
    EXPECT_LE(lv_emitters, lv + 1e-12) << line;
    EXPECT_GT(hv_worst, 0.0) << line;
    EXPECT_LE(hv_worst, hv + 1e-12) << line;
    EXPECT_LT(lv + hv, 1.5) << line;  // LV's and HV's error share the image's, up to their cross term
    ++rows;
  }
  EXPECT_EQ(rows, 4);  // two samplers at two sample counts
}

// The threshold-fidelity bench measures the --threshold it is given (by default both 0.001 and
// 0.01): every row of its CSV is at that threshold.
TEST(Cli, BenchThresholdFidelityTakesTheThreshold) {
  for (const std::string threshold : {"", "0.05"}) {
    SCOPED_TRACE(threshold);
    const std::string out = temp_dir("fidelity" + threshold);
    const Result r = run("bench threshold-fidelity --size 16x16 --seeds 2 --spp 16 " +
                         (threshold.empty() ? "" : "--threshold " + threshold + " ") + "--out " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    std::istringstream csv(slurp(out + "/threshold_fidelity_cornell.csv"));
    std::string line;
    std::getline(csv, line);
    const size_t t_column = [&] {
      size_t column = 0;
      std::istringstream header(line);
      for (std::string f; std::getline(header, f, ','); ++column)
        if (f == "t") return column;
      return size_t{99};
    }();
    ASSERT_NE(t_column, 99u) << line;
    std::set<std::string> seen;
    while (std::getline(csv, line)) {
      std::istringstream fields(line);
      std::string f;
      for (size_t c = 0; c <= t_column; ++c) std::getline(fields, f, ',');
      seen.insert(f);
    }
    const std::set<std::string> expected = threshold.empty() ? std::set<std::string>{"0.001", "0.01"} : std::set<std::string>{"0.05"};
    EXPECT_EQ(seen, expected);
  }
}

TEST(Cli, RenderWithTimeStopsByItselfAndFinishes) {
  // No --spp: only the budget stops it. The finish filters the last frame and writes everything.
  const std::string out = temp_dir("render_time");
  const Result r = run("render --size 32x24 --time 2 --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_EQ(stats["time_budget"]["budget_ms"].get<double>(), 2000.0);
  const int spp = stats["time_budget"]["spp_reached"].get<int>();
  EXPECT_GE(spp, 1);
  EXPECT_LT(spp, 1 << 24);
  EXPECT_EQ(stats["settings"]["spp"].get<int>(), spp);
  EXPECT_GE(stats["filter_runs"].get<int>(), 1);  // the finish's run at least
  EXPECT_GT(stats["time_budget"]["used_ms"].get<double>(), 0.0);
  const double share = stats["share_outside_path_tracing"].get<double>();
  EXPECT_TRUE(share >= 0.0 && share <= 1.0) << share;
  EXPECT_NE(r.out.find("time budget 2.00 s"), std::string::npos) << r.out;
  // With --spp too, whichever comes first: 3 spp arrive long before 60 s.
  const Result r2 = run("render --size 32x24 --time 60 --spp 3 --quiet --out " + out);
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(out + "/stats.json"))["time_budget"]["spp_reached"].get<int>(), 3);
}

TEST(Cli, NoFilterAndNoRangePassWhenTheHvBufferIsEmpty) {
  // Three vertices (camera, surface, light): only direct light, all of it LV.
  const std::string out = temp_dir("direct_only");
  ASSERT_EQ(run("render --size 32x32 --spp 8 --max-vertices 3 --quiet --out " + out).code, 0);
  const auto stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_EQ(stats["filter_runs"], 0);
  EXPECT_EQ(stats["stage_ms_total"]["filter"].get<double>(), 0.0);
  EXPECT_EQ(stats["stage_ms_total"]["range"].get<double>(), 0.0);
  EXPECT_EQ(stats["blend_case_pixels"]["no_filtered"], 32 * 32);
}

TEST(Cli, CtrlCFinishesTheFrameAndWritesEverything) {
  const std::string out = temp_dir("interrupted");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::freopen("/dev/null", "w", stderr);
    std::freopen("/dev/null", "w", stdout);
    execl(PXF_EXECUTABLE, "pxf", "render", "--size", "48x48", "--spp", "1000000", "--quiet", "--out", out.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  std::this_thread::sleep_for(std::chrono::seconds(3));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  for (const char* file : {"final.png", "final.exr", "buffers.exr", "stats.json"}) EXPECT_TRUE(fs::exists(out + "/" + file));
  const auto stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_TRUE(stats["interrupted"].get<bool>());
  EXPECT_GT(stats["settings"]["spp"].get<int>(), 0);
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST(Cli, DiffReadsForeignHalfFloatExrsAndGetsTheNumbersRight) {
  const std::string dir = temp_dir("diff");
  fs::create_directories(dir);
  // reference (1,2,3),(3,2,1); test (1,2,3),(4,2,0): RMSE sqrt(2/6), mean 2 -> NRMSE 28.8675 %
  write_half_rgba(dir + "/ref.exr", {1, 2, 3, 3, 2, 1}, 2, 1);
  write_half_rgba(dir + "/test.exr", {1, 2, 3, 4, 2, 0}, 2, 1);
  const Result r = run("diff " + dir + "/test.exr " + dir + "/ref.exr");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("NRMSE 28.8675 %"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("max|diff| 1"), std::string::npos) << r.out;
  EXPECT_EQ(run("diff " + dir + "/test.exr " + dir + "/ref.exr --max-nrmse 10").code, 1);
  EXPECT_EQ(run("diff " + dir + "/test.exr " + dir + "/ref.exr --max-nrmse 30").code, 0);
  const Result missing = run("diff " + dir + "/nope.exr " + dir + "/ref.exr");
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("nope.exr"), std::string::npos);
}

// A reference without finite values is an error, never NRMSE 0 and exit 0.
TEST(Cli, DiffRejectsANonFiniteReference) {
  const std::string dir = temp_dir("diff_nan");
  fs::create_directories(dir);
  write_half_rgba(dir + "/ref.exr", std::vector<float>(6, NAN), 2, 1);
  write_half_rgba(dir + "/test.exr", {1, 2, 3, 4, 2, 0}, 2, 1);
  const Result r = run("diff " + dir + "/test.exr " + dir + "/ref.exr --max-nrmse 1");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("ref.exr"), std::string::npos) << r.err;
  write_half_rgba(dir + "/partly.exr", {1, 2, NAN, 3, 2, 1}, 2, 1);
  EXPECT_EQ(run("diff " + dir + "/test.exr " + dir + "/partly.exr").code, 1);
}

namespace {
// The number after `label` on the line starting with `line_start` in `text`; NaN when absent.
double number_after(const std::string& text, const std::string& line_start, const std::string& label) {
  const size_t line = text.find(line_start);
  if (line == std::string::npos) return NAN;
  const size_t end = text.find('\n', line);
  const size_t at = text.find(label, line);
  if (at == std::string::npos || at > end) return NAN;
  return std::stod(text.substr(at + label.size()));
}
}  // namespace

// Display NRMSE and FLIP beside HDR NRMSE, with the emitters masked through the reference
// buffers.exr's own emitter layer or --mask; --max-flip gates like --max-nrmse.
TEST(Cli, DiffReportsDisplayMetricsWithAndWithoutEmitters) {
  const std::string test = temp_dir("diff_test"), ref = temp_dir("diff_ref");
  ASSERT_EQ(run("render --size 48x36 --spp 4 --quiet --out " + test).code, 0);
  ASSERT_EQ(run("render --size 48x36 --spp 64 --filter none --seed 9 --quiet --out " + ref).code, 0);
  const Result r = run("diff " + test + "/final.exr " + ref + "/buffers.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("mask: the emitter layer of " + ref + "/buffers.exr"), std::string::npos) << r.out;
  const double flip = number_after(r.out, "all pixels:", "FLIP ");
  const double display = number_after(r.out, "all pixels:", "display NRMSE ");
  const double masked_hdr = number_after(r.out, "emitters masked", "HDR NRMSE ");
  const double hdr = number_after(r.out, "all pixels:", "HDR NRMSE ");
  EXPECT_GT(flip, 0.0) << r.out;
  EXPECT_LT(flip, 0.5) << r.out;
  EXPECT_GT(display, 0.0) << r.out;
  EXPECT_GT(masked_hdr, 0.0) << r.out;
  EXPECT_NE(masked_hdr, hdr) << r.out;  // the ceiling light is in view of the default camera
  EXPECT_GT(number_after(r.out, "emitters masked", "masked ("), 0.0) << r.out;
  // The outlier count is printed on both lines; an image against itself has none.
  EXPECT_GE(number_after(r.out, "all pixels:", "reference) "), 0.0) << r.out;
  EXPECT_GE(number_after(r.out, "emitters masked", "reference) "), 0.0) << r.out;
  EXPECT_EQ(number_after(run("diff " + ref + "/final.exr " + ref + "/final.exr").out, "all pixels:", "reference) "), 0.0);
  // --mask names the file explicitly; one without an emitter layer is a clear error.
  const Result explicit_mask = run("diff " + test + "/final.exr " + ref + "/final.exr --mask " + test + "/buffers.exr");
  EXPECT_EQ(explicit_mask.code, 0) << explicit_mask.err;
  EXPECT_NE(explicit_mask.out.find("emitters masked"), std::string::npos) << explicit_mask.out;
  const Result no_layer = run("diff " + test + "/final.exr " + ref + "/final.exr --mask " + ref + "/final.exr");
  EXPECT_EQ(no_layer.code, 1);
  EXPECT_NE(no_layer.err.find("emitter"), std::string::npos) << no_layer.err;
  // --max-flip
  EXPECT_EQ(run("diff " + test + "/final.exr " + ref + "/final.exr --max-flip " + std::to_string(flip * 0.5)).code, 1);
  EXPECT_EQ(run("diff " + test + "/final.exr " + ref + "/final.exr --max-flip " + std::to_string(flip * 2)).code, 0);
  EXPECT_EQ(run("diff " + ref + "/final.exr " + ref + "/final.exr --max-flip 0").code, 0);
  // --images: the display images and the error image, black for identical images.
  const std::string images = temp_dir("diff_images");
  ASSERT_EQ(run("diff " + test + "/final.exr " + ref + "/final.exr --images " + images).code, 0);
  const Image error = read_ldr_or_hdr(images + "/error.png");
  EXPECT_EQ(error.width, 48);
  EXPECT_GT(*std::max_element(error.pixels.begin(), error.pixels.end()), 0.0f);
  EXPECT_EQ(read_ldr_or_hdr(images + "/test.png").width, 48);
  ASSERT_EQ(run("diff " + ref + "/final.exr " + ref + "/final.exr --images " + images).code, 0);
  const Image none = read_ldr_or_hdr(images + "/error.png");
  EXPECT_EQ(*std::max_element(none.pixels.begin(), none.pixels.end()), 0.0f);
  // A folder that cannot be made is a one-line error naming it.
  const Result bad = run("diff " + ref + "/final.exr " + ref + "/final.exr --images " + ref + "/final.exr/sub");
  EXPECT_EQ(bad.code, 1);
  EXPECT_EQ(lines(bad.err), 1u) << bad.err;
  EXPECT_NE(bad.err.find("--images"), std::string::npos) << bad.err;
}

// --perfect-filter blends TEST's own buffers again with L_f = REFERENCE's HV and Var[L_f] = 0, at
// the t of TEST's stats.json: with t huge every pixel keeps L_u (the unfiltered line), with t = 0
// every pixel takes L_f (the lv + reference hv line). Square, so that the default camera sees no
// background, where the blend's background rule keeps L_u = 0 whatever t.
TEST(Cli, DiffPerfectFilterBlendsTheTestBuffersWithTheReferenceHv) {
  const std::string keep = temp_dir("perfect_keep"), take = temp_dir("perfect_take"), ref = temp_dir("perfect_ref");
  ASSERT_EQ(run("render --size 40x40 --spp 16 --threshold 1e6 --quiet --out " + keep).code, 0);
  ASSERT_EQ(run("render --size 40x40 --spp 16 --threshold 0 --quiet --out " + take).code, 0);
  ASSERT_EQ(run("render --size 40x40 --spp 64 --filter none --seed 9 --quiet --out " + ref).code, 0);
  for (const std::string& dir : {keep, take}) {
    const Result r = run("diff " + dir + "/buffers.exr " + ref + "/buffers.exr --perfect-filter");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("from " + dir + "/stats.json"), std::string::npos) << r.out;
    const double perfect = number_after(r.out, "blend with a perfect filter:", "display NRMSE ");
    const double unfiltered = number_after(r.out, "unfiltered (lv + hv):", "display NRMSE ");
    const double lv_only = number_after(r.out, "lv + reference hv:", "display NRMSE ");
    EXPECT_GT(unfiltered, 2 * lv_only) << r.out;  // 16 spp of HV noise against LV's
    EXPECT_NEAR(perfect, dir == keep ? unfiltered : lv_only, 1e-4) << r.out;
    EXPECT_NEAR(number_after(r.out, "blend with a perfect filter:", "HDR NRMSE "),
                number_after(r.out, dir == keep ? "unfiltered (lv + hv):" : "lv + reference hv:", "HDR NRMSE "), 1e-4)
        << r.out;
  }
  // An adaptive render: the run's n is its frame count (stats.json), each pixel's threshold its own
  // count's, though the samples layer holds counts above n.
  const std::string adaptive = temp_dir("perfect_adaptive");
  ASSERT_EQ(run("render --size 40x40 --spp 48 --adaptive on --quiet --out " + adaptive).code, 0);
  const Image counts = read_exr(adaptive + "/buffers.exr", "samples");
  EXPECT_GT(*std::max_element(counts.pixels.begin(), counts.pixels.end()), 48.0f);
  const Result adaptive_run = run("diff " + adaptive + "/buffers.exr " + ref + "/buffers.exr --perfect-filter");
  ASSERT_EQ(adaptive_run.code, 0) << adaptive_run.err;
  EXPECT_NE(adaptive_run.out.find(" at 48 spp)"), std::string::npos) << adaptive_run.out;
  // A final.exr has no buffers: a clear error naming the file and the layer.
  const Result bad = run("diff " + keep + "/final.exr " + ref + "/buffers.exr --perfect-filter");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find(keep + "/final.exr: no 'lv' layer"), std::string::npos) << bad.err;
}

// --second-reference takes the reference's own noise out. TEST here is a render like the two
// references (unfiltered, unbiased, the same spp, a third seed), so its error against the truth is
// the references' noise itself: the corrected NRMSE is about the raw one / sqrt 2 and about the
// reference noise printed beside it. A second reference that cannot be independent is refused.
// 96x96: at 40x40 the three estimates were too noisy to compare (cornell's corrected/noise ratio
// read 0.64-1.43 over six seed triples; 0.89-1.09 at 96x96).
TEST(Cli, DiffSecondReferenceTakesOutTheReferencesNoise) {
  const std::string a = temp_dir("noise_a"), b = temp_dir("noise_b"), test = temp_dir("noise_test"),
                    other = temp_dir("noise_other");
  for (const auto& [dir, seed] : {std::pair{a, 9}, {b, 10}, {test, 11}})
    ASSERT_EQ(run("render --size 96x96 --spp 64 --filter none --quiet --seed " + std::to_string(seed) + " --out " + dir)
                  .code,
              0);
  const Result r = run("diff " + test + "/final.exr " + a + "/final.exr --second-reference " + b + "/final.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* value : {"HDR NRMSE ", "display NRMSE "}) {
    const double raw = number_after(r.out, "all pixels:", value);
    const double corrected = number_after(r.out, "noise-corrected:", value);
    const double noise = number_after(r.out, "reference noise:", value);
    EXPECT_NEAR(corrected, raw / std::sqrt(2.0), 0.2 * raw) << value << r.out;
    EXPECT_NEAR(corrected, noise, 0.25 * noise) << value << r.out;
  }
  const Result same_seed = run("diff " + test + "/final.exr " + a + "/final.exr --second-reference " + a + "/final.exr");
  EXPECT_EQ(same_seed.code, 1);
  EXPECT_NE(same_seed.err.find("seed"), std::string::npos) << same_seed.err;
  ASSERT_EQ(run("render --size 96x96 --spp 8 --filter none --quiet --seed 12 --out " + other).code, 0);
  const Result other_spp = run("diff " + test + "/final.exr " + a + "/final.exr --second-reference " + other + "/final.exr");
  EXPECT_EQ(other_spp.code, 1);
  EXPECT_NE(other_spp.err.find("spp"), std::string::npos) << other_spp.err;
  // A setting only one of them records (the sampler, in a stats.json written before it was) is not
  // compared; the settings both record still are.
  for (const std::string& dir : {b, other}) {
    auto stats = nlohmann::json::parse(slurp(dir + "/stats.json"));
    stats["settings"].erase("sampler");
    std::ofstream(dir + "/stats.json") << stats.dump();
  }
  const Result older = run("diff " + test + "/final.exr " + a + "/final.exr --second-reference " + b + "/final.exr");
  EXPECT_EQ(older.code, 0) << older.err;
  const Result older_other_spp =
      run("diff " + test + "/final.exr " + a + "/final.exr --second-reference " + other + "/final.exr");
  EXPECT_EQ(older_other_spp.code, 1);
  EXPECT_NE(older_other_spp.err.find("spp"), std::string::npos) << older_other_spp.err;
}

// ---------------------------------------------------------------------------------------------
// Very bright but finite input still gives a finished render with finite layers.

namespace {

// Every channel of every layer of DIR's buffers.exr and final.exr is finite.
void expect_outputs_finite(const std::string& dir, const std::string& what) {
  for (const char* file : {"buffers.exr", "final.exr"})
    for (const Layer& layer : read_exr_layers(dir + "/" + file))
      EXPECT_EQ(count_nonfinite(layer.image), 0u) << what << ": " << file << " layer '" << layer.name << "'";
}

// The Cornell box with its buffer uri made absolute, `edit` applied, written to DIR/scene.gltf.
std::string edited_cornell(const std::string& dir, const std::function<void(nlohmann::json&)>& edit) {
  std::string cornell;
  for (const BuiltinScene& s : builtin_scenes())
    if (s.name == "cornell") cornell = s.path;
  if (cornell.empty()) return "";
  auto doc = nlohmann::json::parse(slurp(cornell));
  for (auto& buffer : doc["buffers"])
    buffer["uri"] = (fs::path(cornell).parent_path() / buffer["uri"].get<std::string>()).string();
  edit(doc);
  fs::create_directories(dir);
  std::ofstream(dir + "/scene.gltf") << doc.dump();
  return dir + "/scene.gltf";
}

}  // namespace

TEST(Cli, VeryBrightFiniteInputGivesFiniteOutputs) {
  const std::string dir = temp_dir("bright");
  const std::string emissive = edited_cornell(dir + "/emissive", [](nlohmann::json& doc) {
    for (auto& m : doc["materials"])
      if (m.contains("emissiveFactor")) m["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", 1e20}};
  });
  if (emissive.empty()) GTEST_SKIP() << "assets/cornell not generated";
  const std::string point = edited_cornell(dir + "/point", [](nlohmann::json& doc) {
    doc["extensionsUsed"].push_back("KHR_lights_punctual");
    doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 1e20}}};
    doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}, {"translation", {0, 1, 0}}});
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
  });
  for (const std::string& scene : {emissive, point}) {
    const std::string out = dir + "/out";
    const Result r = run("render --scene " + scene + " --size 16x16 --spp 4 --quiet --out " + out);
    ASSERT_EQ(r.code, 0) << scene << ": " << r.err;
    expect_outputs_finite(out, scene);
  }
  for (float pixel : {1e38f, 3e38f}) {
    Image env(8, 4, {"R", "G", "B"});
    std::fill(env.pixels.begin(), env.pixels.end(), 1.0f);
    env.pixels[0] = env.pixels[1] = env.pixels[2] = pixel;
    write_exr(dir + "/env.exr", env);
    const std::string out = dir + "/env_out";
    const Result r = run("render --scene envmap --env " + dir + "/env.exr --size 16x16 --spp 4 --quiet --out " + out);
    ASSERT_EQ(r.code, 0) << pixel << ": " << r.err;
    expect_outputs_finite(out, "environment pixel " + std::to_string(pixel));
  }
}

// A closed box whose every face emits 1e30 (or 3.4e38) rendered black with no word: the emission is
// clamped to what can be represented, a warning names a material, and final.png shows the box.
TEST(Cli, UnrepresentableEmissionIsClampedWithAWarningAndRendersVisibly) {
  const std::string dir = temp_dir("huge_emission");
  for (double strength : {1e30, 3.4e38}) {
    const std::string scene = edited_cornell(dir + "/scene", [&](nlohmann::json& doc) {
      doc["extensionsUsed"].push_back("KHR_materials_emissive_strength");
      for (auto& m : doc["materials"]) {
        m["emissiveFactor"] = {1, 1, 1};
        m["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", strength}};
      }
    });
    if (scene.empty()) GTEST_SKIP() << "assets/cornell not generated";
    const std::string out = dir + "/out";
    const Result r = run("render --scene " + scene + " --size 16x16 --spp 2 --quiet --out " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("emits"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("clamped"), std::string::npos) << r.err;
    expect_outputs_finite(out, "emission " + std::to_string(strength));
    const Image png = read_ldr_or_hdr(out + "/final.png");
    double sum = 0;
    for (float v : png.pixels) sum += v;
    EXPECT_GT(sum / png.pixels.size(), 0.1) << strength << ": final.png is (nearly) black";
  }
}

// Radiance from 1e-30 to 1e30 in one scene, samples that overflow float among them: every layer of
// every output is finite, and stats.json counts exactly the samples the `samples` layer lacks.
TEST(Cli, ExtremeRadianceGivesFiniteOutputsAndAnExactDroppedSampleCount) {
  const std::string dir = temp_dir("extreme_radiance");
  const std::string scene = edited_cornell(dir, [](nlohmann::json& doc) {
    // A point light at the float limit just above the floor (its light overflows to Inf in many
    // samples), one wall emitting 1e-30 and another 1e30, beside the ceiling light.
    doc["extensionsUsed"].push_back("KHR_lights_punctual");
    doc["extensionsUsed"].push_back("KHR_materials_emissive_strength");
    doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 3.4e38}}};
    doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}, {"translation", {0, 0.05, 0}}});
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
    ASSERT_GE(doc["materials"].size(), 3u);
    doc["materials"][0]["emissiveFactor"] = {1, 1, 1};
    doc["materials"][0]["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", 1e-30}};
    doc["materials"][1]["emissiveFactor"] = {1, 1, 1};
    doc["materials"][1]["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", 1e30}};
  });
  if (scene.empty()) GTEST_SKIP() << "assets/cornell not generated";
  const int width = 24, height = 16, spp = 8;
  const std::string out = dir + "/out";
  const Result r = run("render --scene " + scene + " --size " + std::to_string(width) + "x" + std::to_string(height) +
                       " --spp " + std::to_string(spp) + " --quiet --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  expect_outputs_finite(out, "extreme radiance");
  double accepted = 0;
  for (const Layer& layer : read_exr_layers(out + "/buffers.exr"))
    if (layer.name == "samples")
      for (float n : layer.image.pixels) accepted += n;
  const auto stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  const double dropped = stats["nan_samples_dropped"].get<double>();
  EXPECT_GT(dropped, 0.0);
  EXPECT_EQ(accepted + dropped, double(width) * height * spp);
  EXPECT_LT(accepted, double(width) * height * spp);
}

// ---------------------------------------------------------------------------------------------
// The output set is replaced whole or not at all.

namespace {

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// pxf's temporaries left in `dir`: anything of its own names but the current set and its link.
std::vector<std::string> leftovers(const std::string& dir) {
  const std::string current = fs::is_symlink(dir + "/" + kCurrentSetLink)
                                  ? fs::read_symlink(dir + "/" + kCurrentSetLink).string() : "";
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if ((name.find(".tmp-") != std::string::npos || name.rfind(".pxf-", 0) == 0) && name != kCurrentSetLink &&
        name != current)
      names.push_back(name);
  }
  return names;
}

const char* const kOutputs[] = {"final.png", "final.exr", "buffers.exr", "stats.json"};

}  // namespace

// `pxf ARGS` under a file size limit of 4 KiB (8 blocks of 512 bytes), which stands in for a nearly
// full disk: writes past it fail with EFBIG. Its stderr is kept in temp_dir(`name`).
Result run_on_a_full_disk(const std::string& args, const std::string& name) {
  const std::string base = temp_dir(name);
  fs::create_directories(base);
  const std::string limited = "sh -c \"ulimit -f 8; trap '' XFSZ; exec " + std::string(PXF_EXECUTABLE) + " " + args + "\"";
  const int status = std::system((limited + " 2>" + base + "/err").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, "", slurp(base + "/err")};
}

TEST(Cli, FullDiskKeepsThePreviousOutputSetAndNamesTheFile) {
  const std::string out = temp_dir("full_disk");
  ASSERT_EQ(run("render --size 64x64 --spp 3 --quiet --out " + out).code, 0);
  std::map<std::string, std::string> before;
  for (const char* name : kOutputs) before[name] = file_bytes(out + "/" + name);
  const Result full = run_on_a_full_disk("render --size 64x64 --spp 3 --seed 7 --quiet --out " + out, "io_full");
  const std::string& err = full.err;
  EXPECT_EQ(full.code, 1) << err;
  EXPECT_EQ(lines(err), 1u) << err;
  EXPECT_NE(err.find("cannot write"), std::string::npos) << err;
  for (const char* name : kOutputs) EXPECT_EQ(file_bytes(out + "/" + name), before[name]) << name << " changed";
  EXPECT_TRUE(leftovers(out).empty());
}

// The same limit with a checkpoint: the final state write and the output write both fail, and
// each names its file on a line of its own.
TEST(Cli, FullDiskReportsBothTheStateAndTheOutputs) {
  const std::string out = temp_dir("full_disk_state");
  const Result full =
      run_on_a_full_disk("render --size 64x64 --spp 3 --checkpoint 1000 --quiet --out " + out, "io_full_state");
  const std::string& err = full.err;
  EXPECT_EQ(full.code, 1) << err;
  EXPECT_EQ(lines(err), 2u) << err;
  EXPECT_NE(err.find("state.pxfs"), std::string::npos) << err;
  EXPECT_NE(err.find("cannot write"), std::string::npos) << err;
}

TEST(Cli, StaleTemporariesOfDeadProcessesAreRemoved) {
  const std::string out = temp_dir("stale");
  fs::create_directories(out + "/.pxf-staging-999999999");  // an earlier pxf's staging folder
  std::ofstream(out + "/final.png.tmp-999999999") << "partial";
  fs::create_directories(out + "/" + set_folder_name(999999999, 0));
  std::ofstream(out + "/" + set_folder_name(999999999, 0) + "/final.exr") << "partial";
  std::ofstream(out + "/state.pxfs.tmp-999999999") << "partial";
  std::ofstream(out + "/notes.txt") << "kept";
  ASSERT_EQ(run("render --size 16x16 --spp 2 --quiet --out " + out).code, 0);
  EXPECT_TRUE(leftovers(out).empty());
  EXPECT_TRUE(fs::exists(out + "/notes.txt"));
}

TEST(Cli, ReferenceIsCheckedBeforeTracing) {
  const std::string out = temp_dir("bad_reference");
  const Result missing = run("render --size 16x16 --spp 64 --quiet --reference /nonexistent/ref.exr --out " + out);
  EXPECT_EQ(missing.code, 1);
  EXPECT_FALSE(fs::exists(out)) << "the render ran before the reference was checked";
  EXPECT_NE(missing.err.find("/nonexistent/ref.exr"), std::string::npos) << missing.err;
  ASSERT_EQ(run("render --size 16x16 --spp 1 --quiet --out " + out).code, 0);
  const Result wrong_size =
      run("render --size 24x16 --spp 64 --quiet --reference " + out + "/final.exr --out " + out + "/b");
  EXPECT_EQ(wrong_size.code, 1);
  EXPECT_NE(wrong_size.err.find(out + "/final.exr"), std::string::npos) << wrong_size.err;
  EXPECT_NE(wrong_size.err.find("16x16"), std::string::npos) << wrong_size.err;
  EXPECT_FALSE(fs::exists(out + "/b"));
}

TEST(Cli, IgnoredSigintStaysIgnored) {
  const std::string out = temp_dir("ignored_sigint");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    signal(SIGINT, SIG_IGN);  // as for a background job of a shell script
    std::freopen("/dev/null", "w", stderr);
    std::freopen("/dev/null", "w", stdout);
    execl(PXF_EXECUTABLE, "pxf", "render", "--size", "16x16", "--spp", "400", "--quiet", "--out", out.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);  // ran all 400 samples, not interrupted
  const auto stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_FALSE(stats["interrupted"].get<bool>());
  EXPECT_EQ(stats["settings"]["spp"].get<int>(), 400);
}

// SIGKILL or SIGINT at 50 random moments of renders of alternating sizes into one folder: every
// file under a final name is complete, and all of them come from the same run (same size).
TEST(Cli, KillsAtRandomMomentsNeverLeavePartialOrMixedOutputs) {
  const std::string out = temp_dir("kills");
  std::mt19937 rng(12);
  const int sizes[] = {16, 20, 24};
  for (int round = 0; round < 50; ++round) {
    const std::string size = std::to_string(sizes[round % 3]) + "x16";
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      std::freopen("/dev/null", "w", stderr);
      std::freopen("/dev/null", "w", stdout);
      execl(PXF_EXECUTABLE, "pxf", "render", "--size", size.c_str(), "--spp", "8", "--quiet", "--out", out.c_str(),
            static_cast<char*>(nullptr));
      _exit(127);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(0, 900000)(rng)));
    kill(pid, round % 2 ? SIGKILL : SIGINT);
    int status = 0;
    waitpid(pid, &status, 0);
    std::set<int> widths;
    for (const char* name : kOutputs) {
      const std::string path = out + "/" + name;
      if (!fs::exists(path)) continue;
      const std::string where = std::string(name) + " after round " + std::to_string(round);
      if (std::string(name) == "stats.json") {
        const auto stats = nlohmann::json::parse(slurp(path), nullptr, false);
        ASSERT_FALSE(stats.is_discarded()) << where;
        widths.insert(stats["settings"]["width"].get<int>());
      } else if (std::string(name) == "final.png") {
        widths.insert(read_ldr_or_hdr(path).width);
      } else {
        widths.insert(read_exr_layers(path).front().image.width);  // throws on a truncated file
      }
    }
    EXPECT_LE(widths.size(), 1u) << "a mix of two runs after round " << round;
  }
  // A later run cleans what the killed ones left.
  ASSERT_EQ(run("render --size 16x16 --spp 1 --quiet --out " + out).code, 0);
  EXPECT_TRUE(leftovers(out).empty());
}

// --until-clean: a diffuse-only box at a loose threshold gets clean and stops
// there, unbounded by --spp; cornell with its mirror and glass at a strict one stops at its cap.
TEST(Cli, UntilCleanStopsWhenEveryPixelIsCase2OrAtItsCap) {
  const std::string dir = temp_dir("until_clean");
  const std::string diffuse = edited_cornell(dir + "/diffuse", [](nlohmann::json& doc) {
    auto& roots = doc["scenes"][0]["nodes"];
    nlohmann::json kept = nlohmann::json::array();
    for (const auto& n : roots) {
      const std::string name = doc["nodes"][n.get<int>()].value("name", "");
      if (name != "mirror_sphere" && name != "glass_sphere") kept.push_back(n);
    }
    roots = kept;
  });
  if (diffuse.empty()) GTEST_SKIP() << "assets/cornell not generated";
  const Result clean = run("render --scene " + diffuse + " --size 16x16 --threshold 0.1 --until-clean --quiet --out " +
                           dir + "/clean");
  ASSERT_EQ(clean.code, 0) << clean.err;
  const auto stats = nlohmann::json::parse(slurp(dir + "/clean/stats.json"));
  EXPECT_TRUE(stats["clean"].get<bool>());
  EXPECT_EQ(stats["blend_case_pixels"]["case2"].get<int>(), 16 * 16);
  const auto& until = stats["until_clean"];
  EXPECT_TRUE(until["requested"].get<bool>());
  ASSERT_TRUE(until["time_to_clean_ms"].is_number());
  const auto& series = until["case2_share_over_time"];
  ASSERT_GE(series.size(), 2u);
  EXPECT_EQ(series.back()[2].get<double>(), 1.0);
  EXPECT_LT(series.front()[2].get<double>(), 1.0) << "clean at the first check: the test shows no stop";
  EXPECT_EQ(series.back()[1].get<int>(), stats["settings"]["spp"].get<int>()) << "did not stop at the clean check";

  // Adaptive, and resumed from a state of 30 frames: the checks come at the same frames (16, then
  // each a quarter more), so the resumed render stops where the uninterrupted one did, same image.
  // At t = 0.05, so that the render is clean after the resume (58 frames; at 0.1 it is at 25).
  const std::string adaptive = "render --scene " + diffuse + " --size 16x16 --threshold 0.05 --until-clean --quiet "
                               "--adaptive on --out ";
  ASSERT_EQ(run(adaptive + dir + "/adaptive").code, 0);
  ASSERT_EQ(run(adaptive + dir + "/resumed --spp 30 --checkpoint 100").code, 0);
  const Result resumed = run(adaptive + dir + "/resumed --resume " + dir + "/resumed/state.pxfs");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  const auto whole = nlohmann::json::parse(slurp(dir + "/adaptive/stats.json"));
  const auto continued = nlohmann::json::parse(slurp(dir + "/resumed/stats.json"));
  EXPECT_TRUE(whole["clean"].get<bool>());
  EXPECT_GT(whole["settings"]["spp"].get<int>(), 30) << "clean before the resume: nothing resumed";
  EXPECT_EQ(continued["settings"]["spp"], whole["settings"]["spp"]);
  EXPECT_EQ(continued["clean"], whole["clean"]);
  EXPECT_EQ(slurp(dir + "/resumed/final.exr"), slurp(dir + "/adaptive/final.exr"));

  const Result capped = run("render --size 16x16 --threshold 0.000001 --spp 40 --until-clean --quiet --out " + dir +
                            "/capped");
  ASSERT_EQ(capped.code, 0) << capped.err;
  const auto capped_stats = nlohmann::json::parse(slurp(dir + "/capped/stats.json"));
  EXPECT_FALSE(capped_stats["clean"].get<bool>());
  EXPECT_EQ(capped_stats["settings"]["spp"].get<int>(), 40);
  EXPECT_TRUE(capped_stats["until_clean"]["time_to_clean_ms"].is_null());

  const Result unfiltered = run("render --size 16x16 --filter none --until-clean --out " + dir + "/none");
  EXPECT_EQ(unfiltered.code, 2);
  EXPECT_EQ(lines(unfiltered.err), 1u) << unfiltered.err;
}
