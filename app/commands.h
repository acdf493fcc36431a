// The pxf subcommands. Each takes its arguments (after the subcommand name) and returns the exit
// code: 0 success, 1 failure (a pxf::Error, printed as one line), 2 usage error. `pxf bench` is
// bench/bench_command.h's.
#pragma once
#include <string>
#include <vector>

namespace pxf {

using Args = std::vector<std::string>;

int run_render(const Args& args);
int run_explore(const Args& args);
int run_diff(const Args& args);
int run_merge(const Args& args);

}  // namespace pxf
