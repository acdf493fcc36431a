#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "image/image.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {
std::string temp_path(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("pxf_image_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

Image ramp(int w, int h, std::vector<std::string> channels) {
  Image img(w, h, std::move(channels));
  for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = 0.001f * static_cast<float>(i) - 0.3f;
  return img;
}
}  // namespace

TEST(Image, ConstructionAndChannelAccess) {
  Image img = Image::rgba(3, 2, 0.5f);
  EXPECT_EQ(img.pixels.size(), 3u * 2u * 4u);
  EXPECT_EQ(img.channel_index("B"), 2);
  EXPECT_EQ(img.channel_index("Z"), -1);
  img.at(2, 1, 3) = 7.0f;
  EXPECT_EQ(img.pixels.back(), 7.0f);
  Image ba = img.select({"B", "A"});
  EXPECT_EQ(ba.num_channels(), 2);
  EXPECT_EQ(ba.at(2, 1, 1), 7.0f);
  EXPECT_THROW(img.select({"Z"}), Error);
}

TEST(ImageExr, SingleLayerRoundTripIsExact) {
  const std::string path = temp_path("single.exr");
  Image img = ramp(17, 5, {"R", "G", "B", "A"});
  write_exr(path, img);
  Image back = read_exr(path);
  EXPECT_EQ(back.channels, img.channels);
  ASSERT_EQ(back.width, 17);
  ASSERT_EQ(back.height, 5);
  EXPECT_EQ(back.pixels, img.pixels);
}

TEST(ImageExr, MultiLayerRoundTripKeepsNamesAndOrder) {
  const std::string path = temp_path("layers.exr");
  std::vector<Layer> layers = {{"final", ramp(8, 4, {"R", "G", "B"})},
                               {"var_u", ramp(8, 4, {"Y"})},
                               {"depth", ramp(8, 4, {"Z"})}};
  write_exr(path, layers);
  std::vector<Layer> back = read_exr_layers(path);
  ASSERT_EQ(back.size(), 3u);
  for (const Layer& l : layers) {
    Image got = read_exr(path, l.name);
    EXPECT_EQ(got.channels, l.image.channels) << l.name;
    EXPECT_EQ(got.pixels, l.image.pixels) << l.name;
  }
  EXPECT_THROW(read_exr(path, "missing"), Error);
}

// Half floats: 10 mantissa bits, round to nearest even, largest finite 65504; read back as floats.
TEST(ImageExr, HalfFloatOptionRoundsToTheNearestHalfAndHalvesTheSamples) {
  const std::string path = temp_path("half.exr");
  const std::vector<float> values = {1.0f, 0.1f, 1.0f / 3.0f, -2.5f, 65504.0f, 70000.0f, 1e-8f, 2049.0f};
  const std::vector<float> halves = {1.0f, 0.0999755859375f, 0.333251953125f, -2.5f, 65504.0f, INFINITY, 0.0f, 2048.0f};
  Image img = Image::gray(4, 2);
  img.pixels = values;
  write_exr(path, img, /*half=*/true);
  Image back = read_exr(path);
  EXPECT_EQ(back.channels, img.channels);
  EXPECT_EQ(back.pixels, halves);

  // Pixel data takes 2 bytes a sample instead of 4 (an incompressible pattern, so ZIP keeps that ratio).
  Image noise = Image::rgb(64, 64);
  uint32_t state = 12345;
  for (float& v : noise.pixels) v = static_cast<float>((state = state * 1664525u + 1013904223u) >> 8) / 16777216.0f;
  const std::string full_path = temp_path("noise_full.exr"), half_path = temp_path("noise_half.exr");
  write_exr(full_path, noise);
  write_exr(half_path, noise, true);
  const double ratio = static_cast<double>(fs::file_size(half_path)) / static_cast<double>(fs::file_size(full_path));
  EXPECT_GT(ratio, 0.4);
  EXPECT_LT(ratio, 0.6);
  const Image noise_back = read_exr(half_path);
  for (size_t i = 0; i < noise.pixels.size(); ++i) ASSERT_NEAR(noise_back.pixels[i], noise.pixels[i], 0.5f / 1024.0f) << i;

  // Layers too.
  write_exr(path, std::vector<Layer>{{"sky", img}}, true);
  EXPECT_EQ(read_exr(path, "sky").pixels, halves);
}

TEST(ImageExr, NonFiniteValuesSurviveRoundTripAndAreCounted) {
  const std::string path = temp_path("nan.exr");
  Image img = Image::rgb(2, 2, 1.0f);
  img.at(0, 0, 0) = NAN;
  img.at(1, 1, 2) = INFINITY;
  write_exr(path, img);
  Image back = read_exr(path);
  EXPECT_TRUE(std::isnan(back.at(0, 0, 0)));
  EXPECT_TRUE(std::isinf(back.at(1, 1, 2)));
  EXPECT_EQ(count_nonfinite(back), 2u);
}

TEST(ImageExr, MissingAndCorruptFilesGiveOneLineErrorsNamingTheFile) {
  const std::string missing = temp_path("does_not_exist.exr");
  try {
    read_exr(missing);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find(missing), std::string::npos);
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
  const std::string corrupt = temp_path("corrupt.exr");
  std::ofstream(corrupt) << "not an exr";
  EXPECT_THROW(read_exr(corrupt), Error);
}

namespace {
std::vector<unsigned char> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<unsigned char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
}  // namespace

// The file readers read the bytes and decode them from memory: both entry points agree, and every
// truncation of a valid file is a pxf::Error naming the input, never a crash or a partial image.
TEST(ImageExr, FromMemoryMatchesTheFileAndRefusesEveryTruncation) {
  const std::string path = temp_path("memory.exr");
  const Image img = ramp(5, 3, {"R", "G", "B"});
  write_exr(path, std::vector<Layer>{{"", img}, {"var", ramp(5, 3, {"Y"})}});
  const std::vector<unsigned char> bytes = file_bytes(path);
  const std::vector<Layer> from_memory = read_exr_layers_from_memory(bytes.data(), bytes.size(), "memory.exr");
  const std::vector<Layer> from_file = read_exr_layers(path);
  ASSERT_EQ(from_memory.size(), from_file.size());
  for (size_t i = 0; i < from_file.size(); ++i) {
    EXPECT_EQ(from_memory[i].name, from_file[i].name);
    EXPECT_EQ(from_memory[i].image.channels, from_file[i].image.channels);
    EXPECT_EQ(from_memory[i].image.pixels, from_file[i].image.pixels);
  }
  EXPECT_EQ(from_file[0].image.pixels, img.pixels);
  for (size_t size = 0; size < bytes.size(); size += 7) {
    try {
      read_exr_layers_from_memory(bytes.data(), size, "cut.exr");
      ADD_FAILURE() << "a file cut to " << size << " of " << bytes.size() << " bytes was read";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("cut.exr: ", 0), 0u) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
}

// A header that asks for more samples than the reader allows is refused before anything is
// allocated, with the size in the message.
TEST(ImageIo, ImagesLargerThanTheSampleLimitAreRefused) {
  const std::string exr_path = temp_path("limit.exr");
  write_exr(exr_path, Image::rgb(8, 4, 0.5f));
  const std::vector<unsigned char> exr = file_bytes(exr_path);
  EXPECT_EQ(read_exr_layers_from_memory(exr.data(), exr.size(), "limit.exr", 8 * 4 * 3).size(), 1u);
  try {
    read_exr_layers_from_memory(exr.data(), exr.size(), "limit.exr", 8 * 4 * 3 - 1);
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("8x4 pixels with 3 channels"), std::string::npos) << e.what();
  }
  const std::string png_path = temp_path("limit.png");
  write_png(png_path, Image::rgb(8, 4, 0.5f));
  const std::vector<unsigned char> png = file_bytes(png_path);
  EXPECT_EQ(read_ldr_or_hdr_from_memory(png.data(), png.size(), "limit.png", 8 * 4 * 3).width, 8);
  EXPECT_THROW(read_ldr_or_hdr_from_memory(png.data(), png.size(), "limit.png", 8 * 4 * 3 - 1), Error);
  // A Radiance header declaring 2^20 x 2^20 pixels and no data (stb would allocate 12 TiB of floats).
  const std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1048576 +X 1048576\n";
  try {
    read_ldr_or_hdr_from_memory(hdr.data(), hdr.size(), "huge.hdr");
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("huge.hdr: ", 0), 0u) << e.what();
  }
  EXPECT_THROW(read_ldr_or_hdr_from_memory(hdr.data(), 0, "empty.hdr"), Error);
}

// Headers that would make OpenEXR allocate what the file cannot hold (inputs from fuzz/make_seeds.py;
// the fuzzer ran at 30 inputs per second on them before): refused up front, with the attribute named.
TEST(ImageExr, HeaderLengthsBeyondTheFileAreRefusedBeforeOpenExrAllocates) {
  const std::string dir = std::string(PXF_SOURCE_DIR) + "/fuzz/corpus/exr_reader/";
  const std::pair<const char*, const char*> cases[] = {
      {"attribute_past_end.exr", "attribute 'junk' of 2147483647 bytes runs past the end"},
      {"box2i_wrong_length.exr", "attribute 'box' of type 'box2i' has an invalid length 256"},
      {"huge_preview.exr", "attribute 'preview' of type 'preview' has an invalid length 8"},
      {"tiles_huge.exr", "tiles of 1048576x1048576 pixels"},
      {"huge_window.exr", "pixels with 1 channels exceed"}};
  for (const auto& [file, expected] : cases) {
    try {
      read_exr_layers(dir + file);
      ADD_FAILURE() << file << " was read";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(expected), std::string::npos) << msg;
      EXPECT_EQ(msg.rfind(dir + file + ": ", 0), 0u) << msg;
    }
  }
}

// A Radiance file cut inside its run-length pixel data made stb loop forever (found by the fuzzer;
// fuzz/crashers/hdr_reader/ holds a variant with a NUL header line): now a one-line error.
TEST(ImageHdr, TruncatedRunLengthDataIsAnErrorNotAHang) {
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n";
  std::string line = {2, 2, 0, 8};
  for (int c = 0; c < 4; ++c) line += std::string{char(128 + 8), char(100 + c)};
  const std::string whole = header + line + line + line + line;
  const Image image = read_ldr_or_hdr_from_memory(whole.data(), whole.size(), "whole.hdr");
  ASSERT_EQ(image.width, 8);
  EXPECT_GT(image.at(7, 3, 0), 0.0f);
  for (size_t cut = header.size() + 4; cut < whole.size(); ++cut) {
    try {
      read_ldr_or_hdr_from_memory(whole.data(), cut, "cut.hdr");
      ADD_FAILURE() << "cut at " << cut << " was read";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("cut.hdr: ", 0), 0u) << e.what();
    }
  }
}

// A 175-byte PNG (found by the fuzzer) whose chunk declares 2 GiB made stb allocate 2 GiB before it
// noticed the data was not there; every cut of a valid PNG is refused the same way.
TEST(ImagePng, ChunksLongerThanTheFileAreRefusedBeforeStbAllocates) {
  const std::string crasher = std::string(PXF_SOURCE_DIR) + "/fuzz/crashers/png_reader/oom-idat-chunk-length-2gib.png";
  try {
    read_ldr_or_hdr(crasher);
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("runs past the end of the file"), std::string::npos) << e.what();
  }
  const std::string path = temp_path("chunks.png");
  write_png(path, Image::rgb(5, 4, 0.5f));
  const std::vector<unsigned char> png = file_bytes(path);
  EXPECT_EQ(read_ldr_or_hdr_from_memory(png.data(), png.size(), "chunks.png").height, 4);
  for (size_t cut = 9; cut < png.size(); ++cut)
    EXPECT_THROW(read_ldr_or_hdr_from_memory(png.data(), cut, "cut.png"), Error) << cut;
}

TEST(ImageIo, WritesAreAtomicAndLeaveNoTemporaryFile) {
  const std::string path = temp_path("atomic.exr");
  write_exr(path, Image::rgb(4, 4, 0.25f));
  for (auto& entry : fs::directory_iterator(fs::path(path).parent_path()))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
  // A write that fails leaves neither the target nor a temporary behind.
  const std::string failing = temp_path("failing.bin");
  EXPECT_THROW(write_file_atomically(failing, [](const std::string& tmp) {
                 std::ofstream(tmp) << "partial";
                 throw Error("interrupted");
               }),
               Error);
  EXPECT_FALSE(fs::exists(failing));
  EXPECT_FALSE(fs::exists(failing + ".tmp-" + std::to_string(::getpid())));
}

// An output named like a device or a FIFO is refused, and what the name holds is left as it was
// (an atomic write renames over it: /dev/null written as root became a regular file).
TEST(ImageIo, AWriteOverAFifoOrADirectoryIsRefusedAndLeavesIt) {
  const std::string fifo = temp_path("out_fifo.png");
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    write_png(fifo, Image::rgb(2, 2, 0.5f));
    FAIL() << "a FIFO was written over";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), fifo + ": not a regular file (a FIFO), which pxf does not replace");
  }
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_FALSE(fs::exists(fifo + ".tmp-" + std::to_string(::getpid())));
  const std::string folder = temp_path("out_folder.exr");
  fs::create_directories(folder);
  EXPECT_THROW(write_exr(folder, Image::rgb(2, 2, 0.5f)), Error);
  EXPECT_TRUE(fs::is_directory(folder));
  // A regular file is replaced, as before.
  const std::string file = temp_path("out_file.png");
  write_png(file, Image::rgb(2, 2, 0.0f));
  write_png(file, Image::rgb(3, 2, 0.0f));
  EXPECT_EQ(read_ldr_or_hdr(file).width, 3);
}

TEST(ImagePng, WriteThenReadGivesQuantizedValues) {
  const std::string path = temp_path("out.png");
  Image img = Image::rgb(3, 1);
  img.at(0, 0, 0) = 1.0f;   // 255
  img.at(1, 0, 1) = 0.5f;   // 128
  img.at(2, 0, 2) = NAN;    // 0
  img.at(2, 0, 0) = 7.0f;   // clamped to 255
  write_png(path, img);
  Image back = read_ldr_or_hdr(path);
  ASSERT_EQ(back.channels, (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_FLOAT_EQ(back.at(0, 0, 0), 1.0f);
  EXPECT_FLOAT_EQ(back.at(1, 0, 1), 128.0f / 255.0f);
  EXPECT_FLOAT_EQ(back.at(2, 0, 2), 0.0f);
  EXPECT_FLOAT_EQ(back.at(2, 0, 0), 1.0f);
}

TEST(ImageColor, SrgbCurveRoundTripsAndHandlesEdges) {
  for (float v : {0.0f, 0.001f, 0.0031308f, 0.18f, 0.5f, 1.0f})
    EXPECT_NEAR(linear_from_srgb(srgb_from_linear(v)), v, 1e-6f);
  EXPECT_NEAR(srgb_from_linear(0.18f), 0.4614f, 1e-4f);
  EXPECT_EQ(srgb_from_linear(NAN), 0.0f);
  EXPECT_EQ(srgb_from_linear(-1.0f), 0.0f);
  EXPECT_NEAR(luminance(1, 1, 1), 1.0f, 1e-6f);
}

TEST(ImageMetrics, MatchHandComputedValues) {
  // reference RGB pixels: (1,2,3), (3,2,1); test: (1,2,3), (4,2,0) -> diffs 0,0,0,1,0,-1
  Image ref = Image::rgb(2, 1), test = Image::rgb(2, 1);
  const float r[] = {1, 2, 3, 3, 2, 1}, t[] = {1, 2, 3, 4, 2, 0};
  std::copy(r, r + 6, ref.pixels.begin());
  std::copy(t, t + 6, test.pixels.begin());
  ImageMetrics m = compare_images(test, ref);
  EXPECT_EQ(m.samples, 6u);
  EXPECT_NEAR(m.rmse, std::sqrt(2.0 / 6.0), 1e-12);
  EXPECT_NEAR(m.reference_mean, 2.0, 1e-12);
  EXPECT_NEAR(m.test_mean, 2.0, 1e-12);
  EXPECT_NEAR(m.nrmse_percent, 100.0 * std::sqrt(2.0 / 6.0) / 2.0, 1e-9);
  EXPECT_NEAR(m.rel_mse, (1.0 / (9 + 1e-2) + 1.0 / (1 + 1e-2)) / 6.0, 1e-12);
  EXPECT_NEAR(m.max_abs_diff, 1.0, 1e-12);
  EXPECT_EQ(m.nan_count, 0u);
}

TEST(ImageMetrics, CountsNonFiniteTestSamplesAndSkipsThem) {
  Image ref = Image::rgb(2, 1, 1.0f), test = Image::rgb(2, 1, 1.0f);
  test.at(0, 0, 0) = NAN;
  test.at(1, 0, 1) = -INFINITY;
  ImageMetrics m = compare_images(test, ref);
  EXPECT_EQ(m.nan_count, 1u);
  EXPECT_EQ(m.inf_count, 1u);
  EXPECT_EQ(m.samples, 4u);
  EXPECT_EQ(m.rmse, 0.0);
}

TEST(ImageMetrics, IgnoresAlphaAndRejectsMismatches) {
  Image ref = Image::rgba(1, 1, 1.0f), test = Image::rgba(1, 1, 1.0f);
  test.at(0, 0, 3) = 0.0f;
  EXPECT_EQ(compare_images(test, ref).rmse, 0.0);
  EXPECT_THROW(compare_images(Image::rgb(2, 1), Image::rgb(1, 1)), Error);
  EXPECT_THROW(compare_images(Image::gray(1, 1, "Z"), Image::rgb(1, 1)), Error);
}

TEST(Image, SumOfAddsSampleBySampleAndChecksTheShape) {
  Image a = Image::rgb(2, 1, 1.0f), b = Image::rgb(2, 1, 0.5f);
  b.at(1, 0, 2) = 3.0f;
  const Image s = sum_of(a, b);
  EXPECT_EQ(s.channels, a.channels);
  EXPECT_EQ(s.at(0, 0, 0), 1.5f);
  EXPECT_EQ(s.at(1, 0, 2), 4.0f);
  EXPECT_THROW(sum_of(a, Image::rgb(1, 2)), Error);
  EXPECT_THROW(sum_of(a, Image::gray(2, 1)), Error);
}
