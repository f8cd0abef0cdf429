#pragma once
// A Cube 2 capture's options as one JSON document (docs/cli.md, "Job files"): what
// `dynbench capture cube2 --job FILE` reads and what a Slurm capture array's tasks run
// (pipeline/cluster_jobs.cpp writes DIR/slurm/capture-job.json), so the options are spelled once.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "capture/cube2.h"
#include "core/error.h"

namespace dynbench::capture {

inline constexpr int kCube2JobVersion = 1;  // the document's "dynbench_cube2_capture"

nlohmann::json cube2JobJson(const Cube2Options& options);

// The options a document describes. Keys left out take Cube2Options' defaults; an unknown key or a
// wrong type is an error naming `source` and the JSON pointer (the values are checked by the
// capture itself, as the command line's are).
Expected<Cube2Options> parseCube2Job(const nlohmann::json& document, const std::filesystem::path& source);
Expected<Cube2Options> readCube2Job(const std::filesystem::path& path);
Expected<void> writeCube2Job(const Cube2Options& options, const std::filesystem::path& path);

}  // namespace dynbench::capture
