// Integer counts of the command line: --frames is capped like --spp, and an
// integer option's bound is exact at the top of a 64-bit type (2^64 - 1 is 2^64 in double).
#include <gtest/gtest.h>

#include "app/checkpoint.h"
#include "app/cli.h"

namespace pxf {
namespace {

FrameRange frames_of(const std::string& text, int spp = 64) {
  CheckpointOptions options;
  options.frames = text;
  return render_frame_range(options, spp);
}

TEST(FrameRangeCount, FramesAreCappedLikeSpp) {
  EXPECT_EQ(frames_of("0:16777216").count(), kMaxRenderFrames);
  EXPECT_EQ(frames_of("4294967000:4294967295").count(), 295u);  // a late shard is fine
  EXPECT_THROW(frames_of("0:16777217"), UsageError);
  EXPECT_THROW(frames_of("0:2147483648"), UsageError);
  try {
    frames_of("0:4294967295");
    FAIL() << "no error";
  } catch (const UsageError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("16777216"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
}

TEST(IntegerOptionRange, TheTopOfA64BitTypeIsOutOfRangeNotWrapped) {
  uint64_t value = 0;
  CommandLine cli("test", "", "");
  cli.option("--n", &value, "n", 0, UINT64_MAX);
  EXPECT_THROW(cli.parse({"--n", "18446744073709551616"}), UsageError);  // 2^64
  EXPECT_THROW(cli.parse({"--n", "1e30"}), UsageError);
  EXPECT_TRUE(cli.parse({"--n", "9007199254740992"}));  // 2^53
  EXPECT_EQ(value, 9007199254740992ull);
}

}  // namespace
}  // namespace pxf
