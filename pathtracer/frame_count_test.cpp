// Frame counts of states: a state's frames are summed in 64 bits and refused
// beyond kMaxStateFrames on reading and before a merge, so no count wraps into the int sample
// count of the preview (a crafted state of 2^31 frames merged to "spp": -2147483648).
#include <gtest/gtest.h>

#include "pathtracer/accumulation_state.h"

using namespace pxf;

namespace {

// A 2x1 state of the frames `ranges`, every pixel with one sample per frame.
AccumulationState state_of_frames(std::vector<FrameRange> ranges) {
  AccumulationState s;
  s.settings.width = 2;
  s.settings.height = 1;
  s.settings.max_vertices = 6;
  s.settings.rr_start_vertex = 3;
  s.frames = std::move(ranges);
  s.acc.width = 2;
  s.acc.height = 1;
  s.acc.lv_mean.assign(2, glm::vec3(0.5f));
  s.acc.hv_mean.assign(2, glm::vec3(0.25f));
  s.acc.albedo_mean.assign(2, glm::vec3(0.8f));
  s.acc.hv_lum_mean.assign(2, 0.25);
  s.acc.hv_lum_m2.assign(2, 0.0);
  s.acc.lv_lum_mean.assign(2, 0.5);
  s.acc.lv_lum_m2.assign(2, 0.0);
  s.acc.samples.assign(2, std::min<uint64_t>(s.frame_count(), UINT32_MAX));
  s.traced = s.acc.samples;
  return s;
}

std::string decode_error(const AccumulationState& state) {
  const std::vector<uint8_t> bytes = encode_state(state);
  try {
    decode_state(bytes.data(), bytes.size());
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(StateFrameCount, TheMostAStateHoldsDecodes) {
  EXPECT_EQ(decode_error(state_of_frames({{0, kMaxStateFrames}})), "");
  EXPECT_EQ(decode_error(state_of_frames({{100, 200}, {1000, 1000 + kMaxStateFrames - 100}})), "");
}

TEST(StateFrameCount, TwoToThe31FramesAreRefusedWithOneLine) {
  const std::string error = decode_error(state_of_frames({{0, 1u << 31}}));
  EXPECT_NE(error.find("2147483648 frames"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
  // Ranges whose sum passes 2^32 (wrapping a 32-bit total to a small number) are refused too.
  EXPECT_NE(decode_error(state_of_frames({{0, 0xC0000000u}, {0xC0000001u, 0xFFFFFFFFu}})), "");
}

TEST(StateFrameCount, AMergeBeyondTheLimitIsRefusedBeforeCombining) {
  const uint32_t half = 1u << 30;
  const std::vector<AccumulationState> states = {state_of_frames({{0, half}}), state_of_frames({{half, 2 * half}})};
  try {
    merge_states(states);
    FAIL() << "merged 2^31 frames";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("2147483648 frames"), std::string::npos) << e.what();
  }
  // One frame fewer fits: the merged count is exactly the limit.
  const AccumulationState merged =
      merge_states({state_of_frames({{0, half}}), state_of_frames({{half, 2 * half - 1}})});
  EXPECT_EQ(merged.frame_count(), kMaxStateFrames);
}

}  // namespace
