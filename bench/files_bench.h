// `pxf bench files`: the equal-time table over a list of scene files, each with its own light: for
// every file and every --times budget, plain path tracing against the preview at equal wall time of
// the whole job, in alternating rounds, judged against a reference of another seed. Writes one CSV
// and one contact sheet of the images.
#pragma once
#include <string>
#include <vector>

namespace pxf {

// One line of the list: NAME SCENE [ENV]. SCENE is a built-in name or a glTF file, ENV an
// equirectangular .exr or .hdr (or "-" for the scene's own light); a relative path is taken from
// the list file's folder. '#' starts a comment; blank lines are skipped.
struct BenchFileEntry {
  std::string name, scene, env;
};

// Parses a list's text; `folder` resolves relative paths. Throws pxf::Error, one line naming
// `source` and the line (a missing scene, a name that is not [A-Za-z0-9._-]+, a repeated name).
std::vector<BenchFileEntry> parse_bench_file_list(const std::string& text, const std::string& source,
                                                  const std::string& folder);

// The mode's entry point (bench/bench_command.cpp lists it).
int files_bench_mode(const std::vector<std::string>& args, const std::string& summary);

}  // namespace pxf
