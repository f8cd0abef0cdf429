#pragma once
// Golden output: a command's text compared byte for byte with tests/golden/NAME. After a deliberate
// change to the output, regenerate every golden file with
//   DYNBENCH_UPDATE_GOLDEN=1 ctest --preset release -R Golden
// and review the diff (git diff tests/golden) before committing it.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/files.h"

namespace dynbench::test {

inline void expectGolden(const std::string& actual, const std::string& name) {
  const std::filesystem::path file = std::filesystem::path(DYNBENCH_SOURCE_DIR) / "tests" / "golden" / name;
  if (const char* update = std::getenv("DYNBENCH_UPDATE_GOLDEN"); update && std::string(update) == "1") {
    ASSERT_TRUE(writeFileAtomic(file, actual)) << file;
    return;
  }
  auto expected = readWholeFile(file);
  ASSERT_TRUE(expected) << file << " is missing: run with DYNBENCH_UPDATE_GOLDEN=1 to write it";
  EXPECT_EQ(actual, *expected) << "differs from " << file << " (DYNBENCH_UPDATE_GOLDEN=1 regenerates it)";
}

}  // namespace dynbench::test
