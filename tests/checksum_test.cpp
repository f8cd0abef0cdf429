// SHA-256 of files (core/checksum.h): the FIPS 180-2 known answers, and a missing file's error;
// the digest of a set of files against coreutils' sha256sum (the suite's pins, docs/suite.md).
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/checksum.h"
#include "gltf_builder.h"

namespace dynbench {
namespace {

TEST(Checksum, Sha256OfFilesMatchesThePublishedVectors) {
  const auto dir = test::freshDir("checksum");
  std::ofstream(dir / "abc") << "abc";
  std::ofstream(dir / "empty");
  // FIPS 180-2, Appendix B.1, and the digest of the empty message.
  EXPECT_EQ(*sha256File(dir / "abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(*sha256File(dir / "empty"), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  // A million 'a's (Appendix B.3): longer than the read buffer.
  std::ofstream(dir / "million") << std::string(1000000, 'a');
  EXPECT_EQ(*sha256File(dir / "million"), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  const auto missing = sha256File(dir / "nope");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kIo);
  EXPECT_NE(missing.error().message.find("nope"), std::string::npos);
}

// A digest fed in parts is the digest of the whole; the stream ends with its digest.
TEST(Checksum, Sha256StreamFedInPartsMatchesThePublishedVector) {
  Sha256Stream sha;
  sha.update("a", 1);
  sha.update("bc", 2);
  EXPECT_EQ(sha.hex(), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha.hex(), "");
  EXPECT_EQ(sha256Text("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Checksum, ListingDigestIsSha256sumsListingDigested) {
  EXPECT_EQ(sha256Text("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  const auto dir = test::freshDir("checksum_listing");
  std::filesystem::create_directories(dir / "models");
  std::ofstream(dir / "Capture.txt") << "f 0\n";
  std::ofstream(dir / "models" / "00001.txt") << "mesh\n";
  std::ofstream(dir / "LICENSES.txt") << "zlib\n";
  // Given in another order: the digest sorts the paths bytewise ('C' < 'L' < 'm').
  const auto ours = sha256Listing(dir, {"models/00001.txt", "LICENSES.txt", "Capture.txt"});
  ASSERT_TRUE(ours) << ours.error().message;
  // The oracle: coreutils, as docs/suite.md tells a user to check a pin by hand.
  const std::string command = "cd '" + dir.string() + "' && printf 'models/00001.txt\\nLICENSES.txt\\nCapture.txt\\n' | LC_ALL=C sort | xargs -d '\\n' sha256sum | sha256sum";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char line[128] = {};
  ASSERT_NE(std::fgets(line, sizeof line, pipe), nullptr);
  ::pclose(pipe);
  EXPECT_EQ(*ours, std::string(line).substr(0, 64));
  // One byte changed in one file changes the digest; a missing file is an error naming it.
  std::ofstream(dir / "models" / "00001.txt") << "mesh!\n";
  EXPECT_NE(*sha256Listing(dir, {"models/00001.txt", "LICENSES.txt", "Capture.txt"}), *ours);
  const auto missing = sha256Listing(dir, {"Capture.txt", "models/00002.txt"});
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("00002.txt"), std::string::npos);
}

}  // namespace
}  // namespace dynbench
