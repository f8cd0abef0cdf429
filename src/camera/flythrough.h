#pragma once
// The fly-through: the kind of camera the thesis compared against (the artist-placed paths of
// ORCA's Bistro and Emerald Square), over a captured match (`dynbench flythrough`, and the demo's
// second dataset). Its path is one of the bot's own stretches without a camera cut (so it stays
// where a player can be), smoothed by a moving average as wide as keeps every segment between
// consecutive poses out of static geometry; it is flown at constant speed over the dataset's whole
// duration, looking ahead along the path, its heading smoothed until its turn rates are within
// ORCA's (Table 6.6), its pitch given a slow nod where the path is too flat to reach ORCA's least
// pitch rate. Of the cut-free stretches it takes the longest whose flight falls inside the ORCA
// ranges of Tables 6.4-6.6, or, where none does, the one closest to them.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "camera/merge_camera.h"
#include "core/error.h"
#include "core/rates.h"
#include "metrics/camera_motion.h"

namespace dynbench::render {
class StaticGeometry;
}

namespace dynbench::camera {

// A column of the thesis's Tables 6.4-6.6 over its three ORCA rows (Bistro Interior, Bistro
// Exterior, Emerald Square; Table 6.5's Bistro Interior row is its "Wine" camera): the smallest and
// largest value, as printed, read from data/thesis-alanko2021.json (compiled in: report/reference.h),
// the one copy of those numbers. NaN if that file were unreadable (the build checks it).
struct OrcaRange {
  double low = 0, high = 0;
};
OrcaRange orcaRange(const std::string& table, std::size_t column);

// One measure of Tables 6.4-6.6 against the range of the thesis's three ORCA rows (Bistro
// Interior, Bistro Exterior, Emerald Square): [low, high] in the thesis's units and conventions
// (metres per frame; rotation as the thesis's half angle, Eq. 2.4 taken literally).
struct OrcaCheck {
  std::string measure;  // e.g. "Table 6.6 yaw mean (°)"
  double value = 0, low = 0, high = 0;
  std::string table;        // the thesis's table ("6.4", "6.5", "6.6") and column the measure is
  std::size_t column = 0;   // (report/reference.h's cells): where another row's value stands
  bool inside() const { return value >= low - 5e-4 && value <= high + 5e-4; }  // the thesis prints 3 decimals
  // How far outside, relative to the range's width (0 inside).
  double distance() const;
};
// The checks of a camera's motion at the dataset's frame rate; metresPerUnit converts positions.
std::vector<OrcaCheck> orcaChecks(const metrics::CameraMotionSummary& motion, double metresPerUnit);

struct FlythroughOptions {
  double rate = 60.0;            // poses per second in the CSV
  double metresPerUnit = 0.125;  // Cube 2: 8 units to the metre
  double speed = 2.5;            // m/s (ORCA's Table 6.4 rows: 0.3-3.7 m/s at 24 fps); less when the stretch is shorter
  double lookAhead = 4.0;        // m along the path
  double maxSmoothing = 64.0;    // scene units: the widest moving average of the path tried (halved until clear of walls)
  double frameRate = kDefaultFrameRate;  // the rate the dataset is rendered at: its chords are checked, its turn rates bounded
  // Bounds on the per-frame yaw and pitch changes at frameRate (degrees, Table 6.6): the largest of
  // the thesis's three ORCA rows (yaw: Emerald Square's 0.511 and 0.095; pitch: Bistro Interior's
  // 0.053 and 0.004). The yaw's and the pitch's smoothing each widen until their two hold.
  double maxYawMean = orcaRange("6.6", 2).high, maxYawVariance = orcaRange("6.6", 3).high;
  double maxPitchMean = orcaRange("6.6", 0).high, maxPitchVariance = orcaRange("6.6", 1).high;
  // And on the largest change in a frame (yaw's and pitch's each): Table 6.5's largest ORCA maximum,
  // Emerald Square's 0.554° as the thesis's half angle, is 1.108° of rotation; 1° leaves the rest
  // to the other axis.
  double maxYawChange = 1.0;
  // The pitch's floor: where the smoothed pitch changes less than ORCA's least row (Bistro
  // Exterior's 0.014° a frame), a slow nod (period nodPeriod) is added until its mean change per
  // frame is pitchTarget, the middle of ORCA's range. 0 turns the nod off.
  double pitchTarget = 0.03, minPitchMean = orcaRange("6.6", 0).low, nodPeriod = 8.0;
  // How many of the longest cut-free stretches are flown and compared.
  int candidates = 8;
};
struct FlythroughReport {
  double stretchStart = 0, stretchEnd = 0;  // s: the bot's cut-free stretch the path follows
  double stretchLength = 0, length = 0;     // scene units: the stretch, and the path flown
  double speed = 0;                         // scene units per second flown
  double smoothing = 0;                     // scene units: width of the path's moving average
  double headingWindow = 0, pitchWindow = 0;  // s: width of the yaw's and the pitch's moving averages
  double nodAmplitude = 0;                    // degrees: the pitch's nod (0: none needed)
  // Per-frame changes at frameRate, degrees (Table 6.6's definitions, |wrapped difference|).
  double yawMean = 0, yawVariance = 0, pitchMean = 0, pitchVariance = 0;
  std::size_t poses = 0;
  int stretchesCompared = 0;           // cut-free stretches flown
  std::vector<OrcaCheck> checks;       // the chosen flight against ORCA's ranges (from its poses at frameRate)
  bool insideOrca() const;
};
// The flight's poses (times from 0, at options.rate poses/s) and its report.
struct FlythroughPoses {
  FlythroughReport report;
  std::vector<CameraPoseKey> keys;
};
Expected<FlythroughPoses> flyThroughPoses(const std::filesystem::path& dataset, const FlythroughOptions& options = {});
// The same over a dataset already loaded with its static geometry built (`dataset` names it in
// errors): for a caller that needs both too, as the VR camera does.
Expected<FlythroughPoses> flyThroughPoses(const AnimatedCamera& camera, const render::StaticGeometry& walls, const std::filesystem::path& dataset,
                                          const FlythroughOptions& options);
// Written as a merge-camera CSV pose log (time,x,y,z,qx,qy,qz,qw) at options.rate poses/s.
Expected<FlythroughReport> writeFlythroughCsv(const std::filesystem::path& dataset, const std::filesystem::path& csv,
                                              const FlythroughOptions& options = {});

// The fly-through as a dataset: the CSV (writeFlythroughCsv) merged into a copy of `dataset` as its
// camera (merge-camera), then the new dataset's camera measured as `stats` measures it (Tables
// 6.4-6.6 at options.frameRate) and checked against ORCA's ranges: `checks` from the dataset
// written, not from the poses.
struct FlythroughDataset {
  FlythroughReport flight;
  std::vector<OrcaCheck> checks;
  bool insideOrca() const;
};
Expected<FlythroughDataset> makeFlythroughDataset(const std::filesystem::path& dataset, const std::filesystem::path& output,
                                                  const std::filesystem::path& csv, const FlythroughOptions& options = {});
// One line: the stretch, the widths and rates chosen, and the ORCA verdict (the checks outside).
std::string describe(const FlythroughDataset& made);
// The `flythrough --json` document (docs/cli.md): the files, the stretch, widths and rates, and the
// ORCA checks.
nlohmann::json flythroughJson(const FlythroughDataset& made, const std::filesystem::path& dataset, const std::filesystem::path& output,
                              const std::filesystem::path& csv);

}  // namespace dynbench::camera
