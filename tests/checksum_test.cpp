// SHA-256 of files (core/checksum.h): the FIPS 180-2 known answers, and a missing file's error.
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

}  // namespace
}  // namespace dynbench
