// Helpers of the integration tests: a headless GL context per test binary and small renders
// through the same Preview core as `pxf render`.
#pragma once
#include <memory>
#include <string>

#include "gl/context.h"
#include "preview/preview.h"

namespace pxf::test_support {

// One OSMesa context for the whole test binary (created on first use, made current).
GlContext& headless_context();

// Renders `spp` frames of a built-in scene (or file) with `settings` and finishes the capture. The
// scene is loaded once per test binary and stays loaded (the Preview references it).
std::unique_ptr<Preview> render_preview(const std::string& scene, int width, int height, int spp,
                                        const PreviewSettings& settings);

// An empty-to-be folder path for one test, under a per-process folder named for the suite
// (removed first if a previous run left it; its parent exists).
std::string temp_dir(const std::string& suite, const std::string& name);
// The whole file as text ("" if it cannot be read).
std::string slurp(const std::string& path);

// `pxf ARGS` run to its end: the exit code (-1 if it did not exit) and what it printed, kept in a
// folder of `suite`'s.
struct PxfResult {
  int code = -1;
  std::string out, err;
};
PxfResult run_pxf(const std::string& args, const std::string& suite);

// A merge of accumulation states against one render of the same samples: shard means are combined
// as n-weighted means in double and rounded to float once, where the single render rounds its
// running float mean at every sample, so values may differ by a few float ulps of the radiance
// (2e-5 relative + 1e-6; docs/state-format.md).
void expect_merge_close(const Image& merged, const Image& single, const std::string& what);

// DIR/NAME: a glTF of one triangle facing +Z (a data-URI buffer), no lights, no camera; creates DIR.
std::string write_bare_triangle(const std::string& dir, const std::string& name = "bare.gltf");

// Folder for files a failing test leaves behind for a person to look at.
std::string failure_dir(const std::string& test_name);

}  // namespace pxf::test_support
