#pragma once
// `dynbench report`: datasets side by side in the thesis's layout (Tables 6.1-6.7), with the
// camera rotation plots (Figures A.1, A.2), discard time series, thumbnails, discard masks and a
// video of each run's frames beside their discard masks (report/video.h).
// One self-contained HTML file (images inline, no network) and a Markdown twin whose images sit
// in a folder beside it.
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"

namespace dynbench::report {

// A RUN folder (docs/cli.md, `dynbench report`):
//   stats.json      from `dynbench stats DATASET --json RUN/stats.json` (required)
//   discard.json    from `dynbench discard FRAMES --json RUN/discard.json` (required)
//   *_camera.csv    from `dynbench stats DATASET --series RUN` (optional: Figures A.1, A.2)
//   frames/         the feature-buffer frames (optional: thumbnails and a video)
//   masks/          from `dynbench discard ... --masks RUN/masks` (optional)
struct ReportOptions {
  std::vector<std::filesystem::path> runs;
  std::filesystem::path output;  // report.html; the Markdown twin is report.md beside it
  std::string title = "dynbench report";
  int thumbnails = 3;  // per run, evenly spaced
  int videoFrames = 240;  // per run, a video of its first this many frames beside their discard masks (0: none)
  std::string reference;  // "thesis": add the thesis's published rows to Tables 6.1-6.7 (report/reference.h)
};

struct ReportFiles {
  std::filesystem::path html, markdown, assets;
  std::uintmax_t htmlBytes = 0;  // the self-contained page's size
  int images = 0, videos = 0;    // inline in the page
};

Expected<ReportFiles> writeReport(const ReportOptions& options);

// RFC 4648 base64 (a dozen lines; no Debian library in our set offers a plain encoder).
std::string base64Encode(const std::string& bytes);

}  // namespace dynbench::report
