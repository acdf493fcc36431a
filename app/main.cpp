// pxf: pixel filtering for progressive path tracing. One core, four front ends.
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>

#include "app/cli.h"
#include "app/commands.h"
#include "bench/bench_command.h"
#include "image/image.h"

namespace {

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const pxf::Args&);
};

const Command kCommands[] = {
    {"render", "headless progressive render with pixel filtering: images, all buffers, stats", pxf::run_render},
    {"explore", "interactive explorer (Dear ImGui): live view of every buffer, live parameters", pxf::run_explore},
    {"bench", "run time against error: per-stage timings, NRMSE at equal time, CSV and plots", pxf::run_bench},
    {"merge", "combine the saved states of render shards (--frames, --shard) and write the usual outputs",
     pxf::run_merge},
    {"diff", "image metrics (NRMSE, RMSE, relMSE, NaN/Inf) between two EXR images", pxf::run_diff},
};

void print_usage(FILE* out) {
  std::fprintf(out, "usage: pxf <command> [options]   (pxf <command> --help for details)\n\ncommands:\n");
  for (const auto& c : kCommands) std::fprintf(out, "  %-8s %s\n", c.name, c.summary);
}

}  // namespace

int main(int argc, char** argv) {
  // Progress and reports on stdout and stderr are best effort: a reader that went away (`pxf render
  // 2>&1 | head -1`) must not kill a render, whose results go to files.
  std::signal(SIGPIPE, SIG_IGN);
  if (argc < 2) {
    print_usage(stderr);
    return 2;
  }
  if (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "help")) {
    print_usage(stdout);
    return 0;
  }
  for (const auto& c : kCommands) {
    if (std::strcmp(argv[1], c.name) != 0) continue;
    try {
      return c.run(pxf::Args(argv + 2, argv + argc));
    } catch (const pxf::UsageError& e) {
      std::fprintf(stderr, "pxf %s: %s\n", c.name, e.what());
      return 2;
    } catch (const pxf::Error& e) {
      std::fprintf(stderr, "pxf %s: %s\n", c.name, e.what());
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "pxf %s: internal error: %s\n", c.name, e.what());
      return 1;
    }
  }
  std::fprintf(stderr, "pxf: unknown command '%s'\n", argv[1]);
  print_usage(stderr);
  return 2;
}
