// Checkpoint, resume and frame ranges of `pxf render` (docs/state-format.md): the render's
// accumulation is saved as DIR/state.pxfs at most every N seconds, on Ctrl-C and at the end.
#pragma once
#include <chrono>
#include <string>

#include "app/cli.h"
#include "app/options.h"
#include "pathtracer/accumulation_state.h"
#include "preview/preview.h"

namespace pxf {

struct CheckpointOptions {
  double interval_s = 0;  // --checkpoint: 0 = no periodic state
  std::string resume;     // --resume STATE
  std::string frames;     // --frames A:B
  std::string shard;      // --shard i/n (of the --spp frames)
};

void add_checkpoint_options(CommandLine& cli, CheckpointOptions& options);
// True when the options ask for a state (--checkpoint, --resume, --frames or --shard).
bool uses_state(const CheckpointOptions& options);
std::string state_path(const std::string& out_dir);  // DIR/state.pxfs

// The frames a render traces: --frames A:B, the i-th of n near-equal parts of 0:spp for
// --shard i/n, else 0:spp. Throws UsageError for a malformed or empty range.
FrameRange render_frame_range(const CheckpointOptions& options, int spp);

// The sample settings of a render: the scene's content hash, size and path-tracing parameters.
SampleSettings render_sample_settings(const SceneOptions& scene, const PreviewSettings& settings);
// The inverse for what a state records: size and the settings that change the samples (pxf merge
// takes them from the states, so that the merged image is the render its shards were made of).
void apply_sample_settings(const SampleSettings& s, SceneOptions& scene, PreviewSettings& settings);

class Checkpointer {
 public:
  Checkpointer(const CheckpointOptions& options, const std::string& out_dir, const SampleSettings& settings,
               FrameRange range);
  // Whether this render keeps a state file at all (any of the options given).
  bool enabled() const { return enabled_; }
  // Loads --resume (if given) into the preview after checking that it belongs to this render;
  // otherwise starts the preview at the range's first frame. Throws pxf::Error before anything is
  // written when the state does not fit.
  void start(Preview& preview) const;
  // Writes the state when the interval has passed since the last write. A failed write warns once
  // on stderr and is retried after the next interval; the render goes on (the previous state stays).
  void maybe_write(const Preview& preview);
  // Writes the state now (nothing without samples); throws pxf::Error naming the file on failure.
  void write(const Preview& preview);
  // The final write: its one-line error, or "" (written, or nothing to write). Returned, not
  // thrown, so that the render's outputs are still written; the caller then exits 1.
  std::string write_final(const Preview& preview);
  // Whether the state file holds the current samples (the last write succeeded).
  bool written() const { return written_; }
  double write_ms() const { return write_ms_; }  // total time spent writing states

 private:
  AccumulationState state_of(const Preview& preview) const;

  CheckpointOptions options_;
  std::string path_;
  SampleSettings settings_;
  FrameRange range_;
  bool enabled_;
  std::chrono::steady_clock::time_point last_write_;
  double write_ms_ = 0;
  bool written_ = false;
  bool warned_ = false;  // a periodic write failed and was reported
};

}  // namespace pxf
