#include "bench/files_bench.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace pxf {
namespace {

TEST(FilesBench, ListLinesGiveNameSceneAndLight) {
  const auto entries = parse_bench_file_list(
      "# a comment\n\nchair chair/WickerChair.gltf skies/quarry.hdr  # trailing\nbox cornell\n"
      "abs /data/lamp.glb -\n",
      "list.txt", "/sets");
  ASSERT_EQ(entries.size(), 3u);
  EXPECT_EQ(entries[0].name, "chair");
  EXPECT_EQ(entries[0].scene, "/sets/chair/WickerChair.gltf");
  EXPECT_EQ(entries[0].env, "/sets/skies/quarry.hdr");
  EXPECT_EQ(entries[1].scene, "cornell");  // a built-in name stays a name
  EXPECT_EQ(entries[1].env, "");
  EXPECT_EQ(entries[2].scene, "/data/lamp.glb");
  EXPECT_EQ(entries[2].env, "");  // "-": the scene's own light
}

TEST(FilesBench, BadListsAreRefusedNamingTheLine) {
  const auto refused = [](const std::string& text, const std::string& expected) {
    try {
      parse_bench_file_list(text, "l.txt", "");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("only-a-name\n", "l.txt:1: expected NAME SCENE [ENV]");
  refused("a b c d\n", "l.txt:1: expected");
  refused("ok cornell\nbad/name cornell\n", "l.txt:2: the name 'bad/name'");
  refused("a cornell\na atrium\n", "l.txt:2: the name 'a' is used twice");
  refused("# nothing\n\n", "l.txt: no file listed");
}

}  // namespace
}  // namespace pxf
