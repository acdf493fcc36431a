#include "bench/fidelity_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "app/render_output.h"
#include "core/timing.h"
#include "gl/pass_params.h"

namespace pxf {
namespace {

float luminance_at(const Image& rgb, size_t p) {
  return 0.2126f * rgb.pixels[3 * p] + 0.7152f * rgb.pixels[3 * p + 1] + 0.0722f * rgb.pixels[3 * p + 2];
}

// One (spp, t): per seed and pixel Y(L - L_lv), Y(L) and the blend case.
struct Samples {
  std::vector<std::vector<float>> hv, total;
  std::vector<std::vector<uint8_t>> blend_case;
};

struct Summary {
  size_t pixels = 0, at_most_t = 0;
  double median_ratio = 0, median_ratio_sd = 0;
};

// Ratios empirical / t of the pixels whose most frequent case is `want` (seed subset `pick`).
std::vector<double> ratios(const Samples& s, const std::vector<int>& pick, float t, int want,
                           const std::vector<int>& majority) {
  std::vector<double> out;
  const size_t pixels = s.hv[0].size();
  const double n = static_cast<double>(pick.size());
  for (size_t p = 0; p < pixels; ++p) {
    if (majority[p] != want) continue;
    double sum = 0, sum_total = 0;
    for (int k : pick) sum += s.hv[k][p], sum_total += s.total[k][p];
    const double mean = sum / n, lb = sum_total / n;
    double ss = 0;
    for (int k : pick) ss += (s.hv[k][p] - mean) * (s.hv[k][p] - mean);
    if (!(lb > 0)) continue;
    out.push_back(ss / (n - 1) / (lb * lb) / t);
  }
  return out;
}

Summary summarize(const Samples& s, float t, int want, const std::vector<int>& majority) {
  const int seeds = static_cast<int>(s.hv.size());
  std::vector<int> all(seeds);
  for (int k = 0; k < seeds; ++k) all[k] = k;
  const std::vector<double> r = ratios(s, all, t, want, majority);
  Summary out;
  out.pixels = r.size();
  for (double v : r) out.at_most_t += v <= 1.0;
  out.median_ratio = median_of(r);
  // The finite-seed uncertainty of the median: its spread over 20 bootstrap resamplings of seeds.
  std::mt19937 rng(17);
  std::uniform_int_distribution<int> pick_seed(0, seeds - 1);
  std::vector<double> medians;
  for (int b = 0; b < 20 && !r.empty(); ++b) {
    std::vector<int> pick(seeds);
    for (int& k : pick) k = pick_seed(rng);
    medians.push_back(median_of(ratios(s, pick, t, want, majority)));
  }
  double m = 0, ss = 0;
  for (double v : medians) m += v / medians.size();
  for (double v : medians) ss += (v - m) * (v - m);
  out.median_ratio_sd = medians.size() > 1 ? std::sqrt(ss / (medians.size() - 1)) : 0;
  return out;
}

}  // namespace

namespace {

// One seed's final image at one sample count, blended at each threshold `ts` (the same samples).
void record(Preview& preview, const std::vector<float>& ts, std::vector<Samples>& out_per_t,
            size_t first_t = 0) {
  const size_t pixels = static_cast<size_t>(preview.width()) * static_cast<size_t>(preview.height());
  for (size_t ti = 0; ti < ts.size(); ++ti) {
    PreviewSettings s = preview.settings();
    if (s.threshold != ts[ti]) {
      s.threshold = ts[ti];
      preview.set_settings(s);  // the same samples, filtered and blended for this t
    }
    preview.redisplay();
    const std::vector<Layer> buffers = preview.buffers();
    const Image& final_rgb = layer_image(buffers, "final");
    const Image& lv = layer_image(buffers, "lv");
    const Image& blend_case = layer_image(buffers, "case");
    Samples& out = out_per_t[first_t + ti];
    out.hv.emplace_back(pixels);
    out.total.emplace_back(pixels);
    out.blend_case.emplace_back(pixels);
    for (size_t p = 0; p < pixels; ++p) {
      const float y = luminance_at(final_rgb, p);
      out.total.back()[p] = y;
      out.hv.back()[p] = y - luminance_at(lv, p);
      out.blend_case.back()[p] = static_cast<uint8_t>(blend_case.pixels[p]);
    }
  }
}

PreviewSettings seed_settings(const FidelityBenchSetup& b, int seed) {
  PreviewSettings settings = b.settings;
  settings.trace.seed = b.settings.trace.seed + 1000 + static_cast<uint64_t>(seed);
  settings.schedule = FilterSchedule::PowersOfTwo;
  settings.adaptive = false;
  return settings;
}

// Uniform frames up to the largest spp, recording at each; returns each spp's time (the recording
// left out).
std::vector<double> run_uniform_seed(const FidelityBenchSetup& b, int seed, const std::vector<int>& spps,
                                     const std::vector<float>& ts, std::vector<std::vector<Samples>>& samples) {
  Preview preview(b.scene, seed_settings(b, seed), b.width, b.height);
  std::vector<double> ms(spps.size());
  double elapsed = 0;
  for (int frame = 1; frame <= *std::max_element(spps.begin(), spps.end()); ++frame) {
    const auto it = std::find(spps.begin(), spps.end(), frame);
    const auto start = BenchClock::now();
    preview.add_frame(it != spps.end(), false);
    elapsed += elapsed_ms(start);
    if (it == spps.end()) continue;
    const size_t k = static_cast<size_t>(it - spps.begin());
    ms[k] = elapsed;
    record(preview, ts, samples[k]);
  }
  return ms;
}

// Adaptive frames for threshold ts[ti] (the allocation follows it), recorded when the job has taken
// the uniform run's time at each spp: spp-equivalents at equal time.
void run_adaptive_seed(const FidelityBenchSetup& b, int seed, const std::vector<double>& uniform_ms,
                       const std::vector<float>& ts, size_t ti, std::vector<std::vector<Samples>>& samples) {
  PreviewSettings settings = seed_settings(b, seed);
  settings.adaptive = true;
  settings.threshold = ts[ti];
  Preview preview(b.scene, settings, b.width, b.height);
  double elapsed = 0;
  for (size_t k = 0; k < uniform_ms.size(); ++k) {
    while (elapsed < uniform_ms[k]) {
      const auto start = BenchClock::now();
      preview.add_frame(false, false);
      elapsed += elapsed_ms(start);
    }
    const auto start = BenchClock::now();
    preview.finish();  // the fresh filter run the uniform job's checkpoint frame had
    elapsed += elapsed_ms(start);
    record(preview, {ts[ti]}, samples[k], ti);
  }
}

}  // namespace

void run_threshold_fidelity_bench(const FidelityBenchSetup& b, const std::vector<int>& spps,
                                  const std::vector<float>& thresholds, int seeds) {
  const size_t pixels = static_cast<size_t>(b.width) * static_cast<size_t>(b.height);
  // samples[mode][spp][t], mode 0 uniform, 1 adaptive at equal time (b.with_adaptive only)
  const int modes = b.with_adaptive ? 2 : 1;
  std::vector<std::vector<std::vector<Samples>>> samples(
      modes, std::vector<std::vector<Samples>>(spps.size(), std::vector<Samples>(thresholds.size())));
  const auto start = BenchClock::now();
  for (int seed = 0; seed < seeds; ++seed) {
    const std::vector<double> uniform_ms = run_uniform_seed(b, seed, spps, thresholds, samples[0]);
    for (size_t ti = 0; b.with_adaptive && ti < thresholds.size(); ++ti)
      run_adaptive_seed(b, seed, uniform_ms, thresholds, ti, samples[1]);
    std::fprintf(stderr, "\rseed %d/%d (%.0f s)", seed + 1, seeds, elapsed_ms(start) / 1000);
  }
  std::fprintf(stderr, "\n");

  std::ostringstream csv;
  csv << "scene,filter,mode,spp,t,case,pixels,fraction_at_most_t,median_ratio,median_ratio_sd\n";
  std::printf("%s %dx%d, filter %s, %d seeds: empirical perceived variance Var[Y(L - L_lv)] / L_b^2 of the final "
              "image against t, by the pixel's most frequent blend case%s\n",
              b.scene_name.c_str(), b.width, b.height, filter_kind_name(b.settings.filter.kind), seeds,
              !b.with_adaptive ? ""
              : b.settings.adaptive_params.goal == AdaptiveGoal::Clean ? "; adaptive (goal clean)"
                                                                        : "; adaptive (goal error)");
  if (b.with_adaptive) std::printf("  adaptive: at the uniform job's wall time at each spp, the allocation for that t\n");
  std::printf("%9s %6s %7s %6s %8s %12s %22s\n", "mode", "spp", "t", "case", "pixels", "<= t", "median empirical / t");
  for (int mode = 0; mode < modes; ++mode)
    for (size_t k = 0; k < spps.size(); ++k)
      for (size_t ti = 0; ti < thresholds.size(); ++ti) {
        const Samples& s = samples[mode][k][ti];
        std::vector<int> majority(pixels, -1);
        for (size_t p = 0; p < pixels; ++p) {
          int count[kBlendCaseCount] = {};
          for (const auto& c : s.blend_case) ++count[std::min<int>(c[p], kBlendCaseCount - 1)];
          majority[p] = static_cast<int>(std::max_element(count, count + kBlendCaseCount) - count);
        }
        const char* mode_name = mode ? "adaptive" : "uniform";
        for (int want : {kCaseUnfiltered, kCaseMixed, kCaseBiasGuard}) {
          const Summary r = summarize(s, thresholds[ti], want, majority);
          const double fraction = r.pixels ? static_cast<double>(r.at_most_t) / r.pixels : 0;
          std::printf("%9s %6d %7g %6d %8zu %11.1f%% %13.3f +- %.3f\n", mode_name, spps[k], thresholds[ti], want,
                      r.pixels, 100 * fraction, r.median_ratio, r.median_ratio_sd);
          csv << b.scene_name << "," << filter_kind_name(b.settings.filter.kind) << "," << mode_name << "," << spps[k]
              << "," << thresholds[ti] << "," << want << "," << r.pixels << "," << fraction << "," << r.median_ratio
              << "," << r.median_ratio_sd << "\n";
        }
      }
  const std::string path = b.out + "/threshold_fidelity_" + b.scene_name + ".csv";
  std::ofstream file(path);
  file << csv.str();
  if (!file) throw Error(path + ": cannot write");
  std::printf("wrote %s\n", path.c_str());
}

}  // namespace pxf
