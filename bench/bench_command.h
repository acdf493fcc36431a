// pxf bench: the research and measurement modes (bench_command.cpp lists them), a subcommand like
// those of app/commands.h that only the pxf executable links.
#pragma once
#include "app/commands.h"

namespace pxf {

int run_bench(const Args& args);

}  // namespace pxf
