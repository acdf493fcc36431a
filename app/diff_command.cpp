// pxf diff: image metrics between two images (SPEC section 4), the same code the tests use.
#include <cstdio>

#include "app/cli.h"
#include "app/commands.h"
#include "image/image.h"

namespace pxf {

int run_diff(const Args& args) {
  std::string test_path, reference_path, layer, reference_layer;
  double max_nrmse = -1;
  CommandLine cli("diff", "TEST.exr REFERENCE.exr [options]",
                  "Prints NRMSE (% of the reference mean), RMSE, relative MSE, max |difference| and the\n"
                  "NaN/Inf count of TEST against REFERENCE over their shared color channels.");
  cli.positional("TEST.exr", &test_path, "image to judge (EXR)");
  cli.positional("REFERENCE.exr", &reference_path, "reference image (EXR)");
  cli.option("--layer", &layer, "NAME", "layer of TEST to compare (default: the unnamed layer, else the first)");
  cli.option("--reference-layer", &reference_layer, "NAME", "layer of REFERENCE (default: same as --layer)");
  cli.option("--max-nrmse", &max_nrmse, "exit with code 1 when NRMSE (%) is above this", 0.0, 1e9);
  if (!cli.parse(args)) return 0;
  if (!cli.given("--reference-layer")) reference_layer = layer;

  const Image test = read_exr(test_path, layer);
  const Image reference = read_exr(reference_path, reference_layer);
  const ImageMetrics m = compare_images(test, reference);
  std::printf("%s\n", format_metrics(m).c_str());
  if (m.nan_count + m.inf_count > 0) {
    std::fprintf(stderr, "pxf diff: %s has %zu non-finite samples\n", test_path.c_str(), m.nan_count + m.inf_count);
    return 1;
  }
  if (max_nrmse >= 0 && m.nrmse_percent > max_nrmse) {
    std::fprintf(stderr, "pxf diff: NRMSE %.4f %% is above --max-nrmse %.4f %%\n", m.nrmse_percent, max_nrmse);
    return 1;
  }
  return 0;
}

}  // namespace pxf
