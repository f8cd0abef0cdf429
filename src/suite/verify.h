#pragma once
// `dynbench suite verify DIR`: a finished suite's numbers re-derived from the files it recorded.
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "pipeline/dataset_run.h"

namespace dynbench::suite {

struct VerifyOutcome {
  std::size_t files = 0, numbers = 0;    // checked
  std::vector<std::string> differences;  // one line each: what differs, recorded and found
};
// Recomputes every number of DIR/suite.json from the files it lists (their SHA-256, discard and
// evaluate on the recorded frames, the camera measures from the datasets, the validity table).
Expected<VerifyOutcome> verifySuite(const std::filesystem::path& dir, const pipeline::RunLog& log);

}  // namespace dynbench::suite
