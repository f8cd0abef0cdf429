// core/image_io: EXR channels by name, the image-thread setting `render --threads` relies on, and
// PNGs with ICC profiles read from many threads at once (textures load in parallel).
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <zlib.h>

#include <gtest/gtest.h>

#include "core/image_io.h"
#include "gltf_builder.h"

namespace dynbench {
namespace {

// Feature buffers are EXR files with named channels (P.X, N.Z, direct.R, ...); they must survive.
TEST(ImageIo, ExrKeepsNamedFloatChannels) {
  FloatImage image{3, 2, 4, {}, {"P.X", "P.Y", "P.Z", "hit"}};
  for (int i = 0; i < 24; ++i) image.pixels.push_back(i * 1.5f - 7.0f + 1e-3f * i);
  const auto file = test::freshDir("exr_names") / "frame_00000.exr";
  ASSERT_TRUE(writeImage(file, image));
  auto back = readImage(file);
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->channels, 4);
  EXPECT_EQ(back->channelNames.size(), 4u);
  // OpenEXR stores channels sorted by name; find each by name and compare exactly (32-bit float).
  for (int c = 0; c < 4; ++c) {
    const auto it = std::find(back->channelNames.begin(), back->channelNames.end(), image.channelNames[static_cast<std::size_t>(c)]);
    ASSERT_NE(it, back->channelNames.end()) << image.channelNames[static_cast<std::size_t>(c)];
    const int b = static_cast<int>(it - back->channelNames.begin());
    for (int p = 0; p < 6; ++p) EXPECT_EQ(back->pixels[static_cast<std::size_t>(p * 4 + b)], image.pixels[static_cast<std::size_t>(p * 4 + c)]);
  }
  FloatImage wrong{1, 1, 2, {0, 0}, {"only one"}};
  EXPECT_FALSE(writeImage(file, wrong));
}

// `render --threads 1` holds for the frames' writing too: with one image thread, a ZIP EXR is
// compressed on the calling thread; with two, mostly on OpenEXR's pool. Measured as the CPU time
// (/proc/self/task/*/stat, clock ticks) of this process's other threads during a write.
TEST(ImageIo, OneImageThreadCompressesOnTheCallingThread) {
  namespace fs = std::filesystem;
  auto otherThreadsTicks = [] {
    long ticks = 0;
    const std::string self = std::to_string(::gettid());
    for (const auto& task : fs::directory_iterator("/proc/self/task")) {
      if (task.path().filename() == self) continue;
      std::ifstream in(task.path() / "stat");
      std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      std::istringstream fields(stat.substr(stat.rfind(')') + 2));  // after "pid (comm) "
      std::string field;
      for (int i = 3; i <= 15 && fields >> field; ++i)
        if (i >= 14) ticks += std::stol(field);  // utime, stime
    }
    return ticks;
  };
  FloatImage image{1024, 1024, 8, {}, {"a.R", "a.G", "a.B", "b.R", "b.G", "b.B", "c.X", "c.Y"}};
  std::uint32_t state = 1;
  for (std::size_t i = 0; i < 1024u * 1024u * 8u; ++i) {
    state = state * 1664525u + 1013904223u;  // noise-like values, so that ZIP has work to do
    image.pixels.push_back(static_cast<float>(state >> 8) * 1e-4f);
  }
  const auto dir = test::freshDir("exr_threads");
  setImageThreads(1);
  ASSERT_TRUE(writeImage(dir / "warm.exr", image));  // OpenImageIO applies the setting at a write
  long before = otherThreadsTicks();
  ASSERT_TRUE(writeImage(dir / "one.exr", image));
  const long alone = otherThreadsTicks() - before;
  setImageThreads(2);
  ASSERT_TRUE(writeImage(dir / "warm2.exr", image));
  before = otherThreadsTicks();
  ASSERT_TRUE(writeImage(dir / "two.exr", image));
  const long pooled = otherThreadsTicks() - before;
  setImageThreads(0);
  EXPECT_LE(alone, 1) << "clock ticks of other threads while one image thread wrote";
  EXPECT_GE(pooled, 5) << "clock ticks of OpenEXR's pool while two image threads wrote";
  auto one = readImage(dir / "one.exr");
  ASSERT_TRUE(one);
  EXPECT_EQ(one->pixels.size(), image.pixels.size());
}

// A PNG file's bytes with an iCCP chunk inserted after IHDR: an ICC v2 display profile (RGB, XYZ
// connection space, D50 illuminant, as libpng requires) with `tags` text tags, each with a
// signature unique to `salt`. OpenImageIO 2.4 decodes the profile in ImageInput::open and names
// every tag through a static std::unordered_map's operator[], which inserts unknown signatures: from
// two threads at once that corrupts the map (OpenImageIO issue #3756). Cube 2's textures carry such
// profiles; `fidelity` crashed in 1 run of about 15 loading them in parallel.
std::string pngWithIccProfile(const std::string& png, int salt, int tags) {
  std::string icc(128, '\0');
  const auto put32 = [](std::string& s, std::size_t at, std::uint32_t v) {
    for (int b = 0; b < 4; ++b) s[at + static_cast<std::size_t>(b)] = static_cast<char>((v >> (24 - 8 * b)) & 0xff);
  };
  icc.replace(8, 4, std::string("\x02\x10\x00\x00", 4));
  icc.replace(12, 12, "mntrRGB XYZ ");
  icc.replace(36, 4, "acsp");
  put32(icc, 68, 0x0000F6D6);  // D50: X 0.9642, Y 1, Z 0.8249 (s15Fixed16)
  put32(icc, 72, 0x00010000);
  put32(icc, 76, 0x0000D32D);
  icc.resize(132 + 12 * static_cast<std::size_t>(tags));
  put32(icc, 128, static_cast<std::uint32_t>(tags));
  for (int t = 0; t < tags; ++t) {
    const std::size_t entry = 132 + 12 * static_cast<std::size_t>(t), data = icc.size();
    const std::uint32_t signature = 0x41000000u + static_cast<std::uint32_t>(salt) * 4096u + static_cast<std::uint32_t>(t);
    put32(icc, entry, signature);
    put32(icc, entry + 4, static_cast<std::uint32_t>(data));
    put32(icc, entry + 8, 12);
    icc += std::string("text\0\0\0\0ab\0\0", 12);
  }
  put32(icc, 0, static_cast<std::uint32_t>(icc.size()));
  uLongf packedSize = compressBound(static_cast<uLong>(icc.size()));
  std::string packed(packedSize, '\0');
  compress(reinterpret_cast<Bytef*>(packed.data()), &packedSize, reinterpret_cast<const Bytef*>(icc.data()), static_cast<uLong>(icc.size()));
  packed.resize(packedSize);
  const std::string body = std::string("iCCP") + std::string("test\0\0", 6) + packed;
  std::string chunk(4, '\0');
  put32(chunk, 0, static_cast<std::uint32_t>(body.size() - 4));
  chunk += body + std::string(4, '\0');
  put32(chunk, chunk.size() - 4, static_cast<std::uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size()))));
  const std::size_t afterHeader = 8 + 4 + 4 + 13 + 4;  // signature, IHDR's length, type, data and CRC
  return png.substr(0, afterHeader) + chunk + png.substr(afterHeader);
}

// Textures are read by a parallel loop (render::TextureSet::load); reading PNGs with ICC profiles
// from several threads at once must neither crash nor lose pixels.
TEST(ImageIo, PngsWithIccProfilesReadFromManyThreads) {
  const auto dir = test::freshDir("png_icc");
  FloatImage image{4, 2, 3, {}, {}};
  for (int i = 0; i < 24; ++i) image.pixels.push_back(static_cast<float>(i * 10) / 255.0f);
  ASSERT_TRUE(writeImage(dir / "plain.png", image));
  std::ifstream in(dir / "plain.png", std::ios::binary);
  const std::string png((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(png.substr(12, 4), "IHDR");
  const auto plain = readImage(dir / "plain.png");
  ASSERT_TRUE(plain);
  constexpr int kThreads = 4, kFilesPerThread = 24;
  for (int f = 0; f < kThreads * kFilesPerThread; ++f)
    std::ofstream(dir / ("icc_" + std::to_string(f) + ".png"), std::ios::binary) << pngWithIccProfile(png, f, 256);
  std::vector<int> good(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int f = t; f < kThreads * kFilesPerThread; f += kThreads) {
        auto back = readImage(dir / ("icc_" + std::to_string(f) + ".png"));
        good[static_cast<std::size_t>(t)] += back && back->pixels == plain->pixels;
      }
    });
  for (auto& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(good[static_cast<std::size_t>(t)], kFilesPerThread) << "thread " << t;
}

}  // namespace
}  // namespace dynbench
