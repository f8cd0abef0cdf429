#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>

#include "core/files.h"
#include "gltf_builder.h"

namespace dynbench {
namespace {

TEST(Files, AsciiLowercaseMapsOnlyAToZ) {
  EXPECT_EQ(asciiLowercase("Textures/Base_Wall/METAL2_2.TGA"), "textures/base_wall/metal2_2.tga");
  // Bytes outside A-Z stay as they are: digits, punctuation, and UTF-8's (here "Ä", 0xC3 0x84),
  // whatever the process's locale.
  const std::string utf8 = "\xC3\x84-Z[@`{";
  EXPECT_EQ(asciiLowercase(utf8), "\xC3\x84-z[@`{");
  EXPECT_EQ(asciiLowercase(""), "");
}

TEST(Files, LowercaseExtensionKeepsTheDotAndOnlyTheLastOne) {
  EXPECT_EQ(lowercaseExtension("maps/Q3DM6.BSP"), ".bsp");
  EXPECT_EQ(lowercaseExtension("frames/frame_00001.Exr"), ".exr");
  EXPECT_EQ(lowercaseExtension("archive.tar.GZ"), ".gz");
  EXPECT_EQ(lowercaseExtension("README"), "");
  EXPECT_EQ(lowercaseExtension("folder.d/file"), "");
}

// One holder at a time: a second lock is refused (tryTake) or waits (wait) until the first goes, and
// the holder's note is what another process reads.
TEST(Files, AFileLockHasOneHolderAndAWaiterGetsItWhenItGoes) {
  const auto dir = test::freshDir("file_lock");
  const auto file = dir / "map.txt.lock";
  std::optional<FileLock> first;
  {
    auto taken = FileLock::wait(file);
    ASSERT_TRUE(taken) << taken.error().message;
    first.emplace(std::move(*taken));
  }
  first->note("4242");
  EXPECT_EQ(*readWholeFile(file), "4242");
  auto refused = FileLock::tryTake(file);
  ASSERT_TRUE(refused) << refused.error().message;
  EXPECT_FALSE(refused->has_value()) << "a second holder while the first holds it";

  std::atomic<bool> got{false};
  std::thread waiter([&] {
    auto second = FileLock::wait(file);
    EXPECT_TRUE(second) << second.error().message;
    got = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_FALSE(got) << "the waiter did not wait for the holder";
  first.reset();
  waiter.join();
  EXPECT_TRUE(got);
  // the waiter's lock went with its thread's scope: free again
  auto again = FileLock::tryTake(file);
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_TRUE(again->has_value());
}

TEST(Files, AFileLockInAMissingFolderIsAnErrorNamingTheFile) {
  const auto dir = test::freshDir("file_lock_missing");
  const auto file = dir / "no such folder" / "x.lock";
  const auto waited = FileLock::wait(file);
  ASSERT_FALSE(waited);
  EXPECT_EQ(waited.error().code, ErrorCode::kIo);
  EXPECT_NE(waited.error().message.find(file.string()), std::string::npos) << waited.error().message;
  const auto tried = FileLock::tryTake(file);
  ASSERT_FALSE(tried);
  EXPECT_NE(tried.error().message.find(file.string()), std::string::npos) << tried.error().message;
}

}  // namespace
}  // namespace dynbench
