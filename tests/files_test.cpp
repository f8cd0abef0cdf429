#include <gtest/gtest.h>

#include <string>

#include "core/files.h"

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

}  // namespace
}  // namespace dynbench
