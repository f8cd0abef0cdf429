// The test executable's main: GoogleTest's, plus the removal of this process's scratch folder
// (test::freshDir: $TMPDIR/dynbench_test_PID) once its tests have passed. ctest runs every test in
// a process of its own, and the end-to-end ones leave up to 400 MB each (captures, frames): kept,
// they filled 20 GB of /tmp over a few sessions. A failed test's folder stays, for a look at what
// it made, and its path is printed.
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

#include "gltf_builder.h"

namespace {

class ScratchFolder : public ::testing::Environment {
 public:
  void TearDown() override {
    const std::filesystem::path folder = dynbench::test::scratchRoot();
    std::error_code ec;
    if (!std::filesystem::exists(folder, ec)) return;
    if (::testing::UnitTest::GetInstance()->Passed()) {
      std::filesystem::remove_all(folder, ec);
    } else {
      std::cerr << "the failed test's files are kept in " << folder.string() << "\n";
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ::testing::AddGlobalTestEnvironment(new ScratchFolder);  // GoogleTest owns and deletes it
  return RUN_ALL_TESTS();
}
