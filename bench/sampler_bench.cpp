#include "bench/bench_harness.h"
#include "bench/sampler_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/timing.h"
#include "image/metrics.h"

namespace pxf {
namespace {

const char* sampler_name(SamplerType type) { return sampler_type_names()[static_cast<int>(type)].c_str(); }
constexpr SamplerType kSamplers[2] = {SamplerType::Independent, SamplerType::Sobol};

TraceParams with_sampler(TraceParams params, SamplerType type, uint64_t seed) {
  params.sampler = type;
  params.seed = seed;
  return params;
}

// Squared errors summed over seeds: the unfiltered image's, LV's (and on the pixels that see an
// emitter), HV's (and on each image's worst 1 % of pixels, where fireflies sit).
struct ErrorSums {
  double all = 0, lv = 0, lv_emitters = 0, hv = 0, hv_worst = 0;
  // The images (unfiltered, LV, HV) and their references, in that order.
  void add(const Image (&test)[3], const Image (&reference)[3], const Image& emitters) {
    all += total_squared_error(pixel_squared_errors(test[0], reference[0]));
    const std::vector<double> lv_errors = pixel_squared_errors(test[1], reference[1]);
    lv += total_squared_error(lv_errors);
    lv_emitters += masked_squared_error(lv_errors, emitters);
    const std::vector<double> hv_errors = pixel_squared_errors(test[2], reference[2]);
    const double hv_total = total_squared_error(hv_errors);
    hv += hv_total;
    hv_worst += hv_total * worst_pixels_share(hv_errors, 0.01);
  }
};

// paths/s of a renderer over `frames` frames (after the caller's warm-up).
double paths_per_second(ProgressiveRenderer& renderer, int frames) {
  const uint64_t before = renderer.stats().paths;
  const auto start = BenchClock::now();
  for (int i = 0; i < frames; ++i) renderer.add_frame();
  return static_cast<double>(renderer.stats().paths - before) / (elapsed_ms(start) / 1000.0);
}

}  // namespace

void run_sampler_error_bench(const SamplerBenchSetup& b, int reference_spp, const std::vector<int>& spps, int rounds,
                             int seeds) {
  // The reference: Sobol from a seed no run below uses.
  ProgressiveRenderer reference(b.scene, with_sampler(b.trace, SamplerType::Sobol, b.trace.seed + 7919), b.width, b.height);
  const auto start = BenchClock::now();
  for (int i = 0; i < reference_spp; ++i) reference.add_frame();
  std::printf("%s %dx%d: reference %d spp in %.1f s\n", b.scene_name.c_str(), b.width, b.height, reference_spp,
              elapsed_ms(start) / 1000);
  // Unfiltered, LV, HV.
  const Image references[3] = {reference.unfiltered_image(), reference.lv_image(), reference.hv_image()};
  const Image emitters = reference.emitter_coverage_image();
  const int max_spp = *std::max_element(spps.begin(), spps.end());

  // One seed's NRMSE is dominated by the few fireflies it happens to catch: the figures are the
  // root mean square over `seeds` seeds (the NRMSE of the expected squared error).
  std::ostringstream csv;
  csv << "scene,sampler,spp,seeds,nrmse_percent,lv_nrmse_percent,hv_nrmse_percent,lv_share,lv_emitter_share,hv_share,"
         "hv_worst1_share\n";
  std::printf("RMS over %d seeds; LV and HV each against the reference's own LV and HV mean\n", seeds);
  std::printf("%-12s %6s %14s %14s %14s\n", "sampler", "spp", "NRMSE %", "LV NRMSE %", "HV NRMSE %");
  constexpr size_t kMaxSpps = 16;
  double square[2][3][kMaxSpps] = {};  // [sampler][all, LV, HV][spp]: sum over seeds of NRMSE^2
  ErrorSums sums[2][kMaxSpps] = {};
  for (int s = 0; s < 2; ++s) {
    for (int seed = 0; seed < seeds; ++seed) {
      ProgressiveRenderer renderer(b.scene, with_sampler(b.trace, kSamplers[s], b.trace.seed + 100 * seed), b.width,
                                   b.height);
      for (int frame = 1; frame <= max_spp; ++frame) {
        renderer.add_frame();
        const auto it = std::find(spps.begin(), spps.end(), frame);
        if (it == spps.end() || it - spps.begin() >= static_cast<long>(kMaxSpps)) continue;
        const size_t k = static_cast<size_t>(it - spps.begin());
        const Image images[3] = {renderer.unfiltered_image(), renderer.lv_image(), renderer.hv_image()};
        for (int c = 0; c < 3; ++c) {
          const double e = compare_images(images[c], references[c]).nrmse_percent;
          square[s][c][k] += e * e;
        }
        sums[s][k].add(images, references, emitters);
      }
    }
  }
  double nrmse[2][3][kMaxSpps] = {};
  for (int s = 0; s < 2; ++s)
    for (size_t k = 0; k < spps.size() && k < kMaxSpps; ++k) {
      for (int c = 0; c < 3; ++c) nrmse[s][c][k] = std::sqrt(square[s][c][k] / seeds);
      std::printf("%-12s %6d %14.2f %14.2f %14.2f\n", sampler_name(kSamplers[s]), spps[k], nrmse[s][0][k],
                  nrmse[s][1][k], nrmse[s][2][k]);
      const ErrorSums& e = sums[s][k];
      csv << b.scene_name << "," << sampler_name(kSamplers[s]) << "," << spps[k] << "," << seeds << ","
          << nrmse[s][0][k] << "," << nrmse[s][1][k] << "," << nrmse[s][2][k] << "," << e.lv / e.all << ","
          << e.lv_emitters / e.all << "," << e.hv / e.all << "," << e.hv_worst / e.all << "\n";
    }
  for (size_t k = 0; k < spps.size() && k < kMaxSpps; ++k)
    std::printf("%d spp: sobol / independent NRMSE %.3f, LV %.3f, HV %.3f\n", spps[k], nrmse[1][0][k] / nrmse[0][0][k],
                nrmse[1][1][k] / nrmse[0][1][k], nrmse[1][2][k] / nrmse[0][2][k]);
  const std::string csv_path = b.out + "/sampler_error_" + b.scene_name + ".csv";
  write_bench_text(csv_path, csv.str());
  std::printf("wrote %s\n", csv_path.c_str());
  std::printf("where the squared error sits, summed over the seeds (%% of the unfiltered image's): LV's and HV's\n"
              "own; of LV's, the pixels that see an emitter (its edges); of HV's, each image's worst 1 %% of pixels\n");
  std::printf("%-12s %6s %10s %16s %10s %16s\n", "sampler", "spp", "LV", "emitter pixels", "HV", "worst 1 %");
  for (int s = 0; s < 2; ++s)
    for (size_t k = 0; k < spps.size() && k < kMaxSpps; ++k) {
      const ErrorSums& e = sums[s][k];
      std::printf("%-12s %6d %9.1f%% %15.1f%% %9.1f%% %15.1f%%\n", sampler_name(kSamplers[s]), spps[k],
                  100 * e.lv / e.all, 100 * e.lv_emitters / e.all, 100 * e.hv / e.all, 100 * e.hv_worst / e.all);
    }

  // Throughput: both samplers in one process, alternating rounds; the median of each.
  std::vector<double> rate[2];
  ProgressiveRenderer independent(b.scene, with_sampler(b.trace, SamplerType::Independent, b.trace.seed), b.width, b.height);
  ProgressiveRenderer sobol(b.scene, with_sampler(b.trace, SamplerType::Sobol, b.trace.seed), b.width, b.height);
  paths_per_second(independent, 3);
  paths_per_second(sobol, 3);
  const int frames_per_round = 8;
  for (int r = 0; r < rounds; ++r) {
    rate[0].push_back(paths_per_second(independent, frames_per_round));
    rate[1].push_back(paths_per_second(sobol, frames_per_round));
  }
  const double independent_rate = median_of(rate[0]), sobol_rate = median_of(rate[1]);
  std::printf("paths/s (median of %d rounds of %d frames): independent %.0f, sobol %.0f, sobol / independent %.3f\n",
              rounds, frames_per_round, independent_rate, sobol_rate, sobol_rate / independent_rate);
}

void run_variance_ratio_bench(const SamplerBenchSetup& b, const std::vector<int>& spps, int seeds) {
  const size_t pixels = static_cast<size_t>(b.width) * static_cast<size_t>(b.height);
  const int max_spp = *std::max_element(spps.begin(), spps.end());
  std::ostringstream csv;
  csv << "scene,sampler,spp,median_ratio,fraction_of_mean_below_0.25,fraction_of_estimates_below_0.25,pixels\n";
  std::printf("%s %dx%d, %d seeds: ratio of estimated to empirical Var[L_u] of the pixel mean (HV luminance)\n",
              b.scene_name.c_str(), b.width, b.height, seeds);
  std::printf("%-12s %6s %14s %22s %22s %8s\n", "sampler", "spp", "median ratio", "mean est. < 0.25 emp.",
              "single est. < 0.25 emp.", "pixels");
  for (SamplerType type : kSamplers) {
    // [spp][seed][pixel]: the pixel mean and the estimated variance of the mean.
    std::vector<std::vector<std::vector<float>>> mean(spps.size()), estimate(spps.size());
    for (int seed = 0; seed < seeds; ++seed) {
      ProgressiveRenderer renderer(b.scene, with_sampler(b.trace, type, b.trace.seed + 1000 + seed), b.width, b.height);
      for (int frame = 1; frame <= max_spp; ++frame) {
        renderer.add_frame();
        const auto it = std::find(spps.begin(), spps.end(), frame);
        if (it == spps.end()) continue;
        const size_t k = static_cast<size_t>(it - spps.begin());
        const Accumulation& acc = renderer.accumulation();
        mean[k].emplace_back(acc.hv_lum_mean.begin(), acc.hv_lum_mean.end());
        estimate[k].push_back(renderer.variance_of_mean());
      }
    }
    for (size_t k = 0; k < spps.size(); ++k) {
      std::vector<double> ratios;
      size_t single_below = 0, singles = 0, mean_below = 0;
      for (size_t p = 0; p < pixels; ++p) {
        double sum = 0, sum2 = 0, est = 0;
        bool known = true;
        for (int s = 0; s < seeds; ++s) {
          sum += mean[k][s][p];
          est += estimate[k][s][p];
          known = known && estimate[k][s][p] >= 0.0f;
        }
        const double m = sum / seeds;
        for (int s = 0; s < seeds; ++s) sum2 += (mean[k][s][p] - m) * (mean[k][s][p] - m);
        const double empirical = sum2 / (seeds - 1);
        if (!known || !(empirical > 1e-12 * (m * m + 1e-12))) continue;  // a noiseless pixel: no ratio
        const double ratio = est / seeds / empirical;
        ratios.push_back(ratio);
        mean_below += ratio < 0.25;
        for (int s = 0; s < seeds; ++s, ++singles) single_below += estimate[k][s][p] < 0.25 * empirical;
      }
      const double median = median_of(ratios);
      const double mean_fraction = ratios.empty() ? 0 : static_cast<double>(mean_below) / ratios.size();
      const double single_fraction = singles ? static_cast<double>(single_below) / singles : 0;
      std::printf("%-12s %6d %14.3f %21.1f%% %21.1f%% %8zu\n", sampler_name(type), spps[k], median, 100 * mean_fraction,
                  100 * single_fraction, ratios.size());
      csv << b.scene_name << "," << sampler_name(type) << "," << spps[k] << "," << median << "," << mean_fraction << ","
          << single_fraction << "," << ratios.size() << "\n";
    }
  }
  const std::string csv_path = b.out + "/variance_ratio_" + b.scene_name + ".csv";
  write_bench_text(csv_path, csv.str());
  std::printf("wrote %s\n", csv_path.c_str());
}

}  // namespace pxf
