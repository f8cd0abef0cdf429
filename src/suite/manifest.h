#pragma once
// A suite's manifest (docs/suite.md): its datasets (engine, preset, map, seed, seconds, camera, and
// the SHA-256 pins of each capture and dataset) and one render window and method list for all.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "pipeline/dataset_run.h"

namespace dynbench::suite {

inline constexpr int kManifestVersion = 1;  // "dynbench_suite" in a manifest
// Frames of each dataset's window rendered again with another seed for the reference's noise floor
// (/render/floor_frames; DatasetRunSettings::floorFrames).
using pipeline::kDefaultFloorFrames;

struct DatasetSpec {
  std::string name;             // unique in the suite: the RUN folder's name
  std::string engine = "cube2";  // or "openarena" (no presets; map oa_dm1 and 4 bots unless given)
  std::string preset;           // a capture preset (calm, fps, hard) or empty
  std::string map;              // empty: the preset's (or colos)
  int bots = 0;                 // 0: the preset's (or 6)
  unsigned seed = 1;
  double seconds = 10.0;        // game time captured
  capture::GameCpu gameCpu = capture::GameCpu::kEmulated;  // openarena: the CPU the game runs on (capture/openarena.h)
  // "bot" (the first-person bot), "slowed" (its turns slowed: camera/slowed.h), "flythrough" or
  // "vr" (a head trace on the fly-through's path: camera/vr_head.h)
  std::string camera = "bot";
  // camera "vr": the head trace as the manifest names it (/datasets/N/trace, relative to the
  // manifest's folder), and that path resolved
  std::string trace;
  std::filesystem::path tracePath;
  // The camera as tables and records name it: the policy, and for "vr" the trace's file name
  // ("vr-eyenavgs_nthu_london_user7_quickturns"), so that one match's VR datasets stay apart.
  std::string cameraLabel() const;
  // Pins (/datasets/N/sha256/capture and /dataset): the SHA-256 the capture folder and the dataset
  // must have (captureDigest, scene::datasetDigest); empty: not checked.
  std::string captureSha256, datasetSha256;
};

struct Manifest {
  int version = kManifestVersion;
  std::string name, description;
  pipeline::DatasetRunSettings run;  // the render window, samples and methods of every dataset
  std::vector<DatasetSpec> datasets;
  nlohmann::json document;           // as read (recorded in suite.json)
  std::filesystem::path path;        // where it was read from (errors name it)
};
// Errors name the file and the JSON pointer of the value and what was expected.
Expected<Manifest> readManifest(const std::filesystem::path& path);
// The same of a manifest already parsed (`path` names it in errors).
Expected<Manifest> parseManifest(const nlohmann::json& document, const std::filesystem::path& path);

// A capture folder's digest, what /datasets/N/sha256/capture pins: every file in it (Capture.txt,
// LICENSES.txt, models/*.txt; names starting with '.' aside) as sha256Listing (core/checksum.h)
// lists them.
Expected<std::string> captureDigest(const std::filesystem::path& folder);

}  // namespace dynbench::suite
