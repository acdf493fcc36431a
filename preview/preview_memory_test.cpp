// The render's memory check (`--size 16384x16384` must not be accepted and then fail
// with bad_alloc or "framebuffer incomplete" after allocating most of the machine).
#include <gtest/gtest.h>

#include <string>
#include "image/image.h"
#include "preview/preview.h"

namespace pxf {
namespace {

constexpr uint64_t kGiB = 1024ull * 1024 * 1024;

TEST(PreviewMemory, EstimateIsPerPixel) {
  EXPECT_EQ(preview_bytes(512, 512), 512ull * 512 * kPreviewBytesPerPixel);
  EXPECT_EQ(preview_bytes(16384, 16384), 16384ull * 16384 * kPreviewBytesPerPixel);  // no int overflow
  EXPECT_EQ(preview_bytes(-3, 5), 0u);
}

TEST(PreviewMemory, HugeSizeIsRefusedWithOneLineNamingTheSizeAndBothFigures) {
  try {
    check_preview_memory(16384, 16384, 24 * kGiB);
    FAIL() << "16384x16384 accepted with 24 GiB available";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("--size 16384x16384"), std::string::npos) << message;
    EXPECT_NE(message.find("192.5 GiB"), std::string::npos) << message;  // 16384^2 x 770 B
    EXPECT_NE(message.find("24.0 GiB available"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(PreviewMemory, UsualSizesPassAndAnUnknownFigureDoesNotRefuse) {
  EXPECT_NO_THROW(check_preview_memory(1920, 1080, 24 * kGiB));
  EXPECT_NO_THROW(check_preview_memory(16384, 16384, 0));  // the system reported nothing
  // The boundary: exactly the estimate fits, one byte less does not.
  EXPECT_NO_THROW(check_preview_memory(1000, 1000, preview_bytes(1000, 1000)));
  EXPECT_THROW(check_preview_memory(1000, 1000, preview_bytes(1000, 1000) - 1), Error);
}

}  // namespace
}  // namespace pxf
