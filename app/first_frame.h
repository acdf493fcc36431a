// `pxf render --time`: the first frame traces whatever the budget (it is what measures the costs
// the budget then stops on), so a budget too small for one frame would be overrun silently, by
// many times on a large image. Large images therefore get a probe first: one frame, with its passes and
// the finish, of the same scene and settings at kProbePixels pixels, timed and scaled to the image's
// pixels. When even that one frame would not fit the budget, the render is refused up front.
#pragma once
#include <string>

#include "preview/preview.h"

namespace pxf {

// Pixels of the probe frame, and the images that get one: smaller images trace their first frame
// at once (it costs about what the probe would).
constexpr double kProbePixels = 256.0 * 256.0;

// The probe's size for a width x height image: about kProbePixels, the image's aspect kept.
void probe_size(int width, int height, int& probe_width, int& probe_height);

// The first frame's predicted cost (ms) from a probe of `probe_pixels` that took `probe_ms`: linear
// in the pixels (tracing and every pass are per pixel), so the probe's fixed costs only make it
// err on the long side.
double scaled_first_frame_ms(double probe_ms, double probe_pixels, double pixels);

// "" when the first frame fits (elapsed + predicted <= budget), else the one-line refusal naming
// the figures and what to change.
std::string first_frame_refusal(double predicted_ms, double elapsed_ms, double budget_ms, int width, int height);

// Runs the probe when the image is larger than kProbePixels (needs a current GL context) and throws
// pxf::Error with first_frame_refusal's line when the first frame cannot fit. `elapsed_ms`: the
// job's time so far (the probe's own time counts too).
void check_first_frame_fits(const Scene& scene, const PreviewSettings& settings, int width, int height,
                            double budget_ms, double elapsed_ms);

}  // namespace pxf
