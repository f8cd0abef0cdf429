// core/progress: the terminal progress line (done, rate, time left).
#include <gtest/gtest.h>

#include "core/progress.h"

namespace dynbench {
namespace {

TEST(Progress, LineShowsDoneRateAndTimeLeft) {
  // 3 of 12 files in 2 s: 1.5 files/s, 9 left -> 6 s.
  EXPECT_EQ(Progress::format("stats", 3, 12, "files", 2.0, "a.gltf"), "stats: 3/12 files, 1.5 files/s, 6 s left: a.gltf");
  EXPECT_EQ(Progress::format("stats", 0, 12, "files", 0.0, ""), "stats: 0/12 files");
  // Unknown total: a count and a rate, no time left.
  EXPECT_EQ(Progress::format("convert", 500, 0, "frames", 2.0, ""), "convert: 500 frames, 250 frames/s");
}

}  // namespace
}  // namespace dynbench
