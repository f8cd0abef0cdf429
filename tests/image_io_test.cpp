// core/image_io: EXR channels by name, and the image-thread setting `render --threads` relies on.
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <sstream>

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

}  // namespace
}  // namespace dynbench
