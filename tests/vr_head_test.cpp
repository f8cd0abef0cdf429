// The VR head camera (camera/vr_head.h): the head-trace reader against the traces' published
// statistics and on bad input, slerp resampling (known answers), the wall clamp, the suite's
// "vr" camera in a manifest, and the same bytes as another machine.
#include <cmath>
#include <fstream>
#include <optional>

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "camera/vr_head.h"
#include "core/math.h"
#include "gltf_builder.h"
#include "other_machine.h"
#include "run_cli.h"
#include "suite/manifest.h"

namespace dynbench::camera {
namespace {

namespace fs = std::filesystem;

const fs::path kTraces = fs::path(DYNBENCH_SOURCE_DIR) / "data" / "vr-head";

// Roll as data/vr-head/README.md defines it: atan2(right.y, up.y) of the head's axes, degrees.
double readmeRoll(const glm::dquat& q) {
  const glm::dvec3 right = q * glm::dvec3(1, 0, 0), up = q * glm::dvec3(0, 1, 0);
  return degrees(std::atan2(right.y, up.y));
}

// The four bundled traces read whole, and two of the statistics their README publishes (computed by
// the trace's own head_stats.py from the same files) come out of dynbench's reading: the mean angular
// speed (total geodesic angle over the duration) and the mean |roll|. A reader that swapped the
// quaternion's w or its axes, or lost lines, would miss them.
TEST(VrHead, TheBundledTracesReadAndGiveTheirPublishedStatistics) {
  struct Published {
    const char* file;
    std::size_t poses;
    double degreesPerSecond, meanAbsRoll;
  };
  const Published traces[] = {{"eyenavgs_nthu_london_user7_quickturns.csv", 1848, 52.9, 3.89},
                              {"eyenavgs_nthu_treehill_user6_fastturn.csv", 1747, 47.6, 2.67},
                              {"eyenavgs_nthu_truck_user8_walking.csv", 1762, 37.3, 4.91},
                              {"eyenavgs_nthu_berlin_user12_headroll.csv", 1598, 28.8, 7.67}};
  for (const Published& p : traces) {
    auto trace = readHeadTrace(kTraces / p.file);
    ASSERT_TRUE(trace) << trace.error().message;
    EXPECT_EQ(trace->size(), p.poses) << p.file;
    double angle = 0, roll = 0;
    for (std::size_t k = 0; k < trace->size(); ++k) {
      if (k > 0) angle += degrees(geodesicAngle((*trace)[k - 1].rotation, (*trace)[k].rotation));
      roll += std::abs(readmeRoll((*trace)[k].rotation));
    }
    EXPECT_NEAR(angle / (trace->back().time - trace->front().time), p.degreesPerSecond, 0.05) << p.file;
    EXPECT_NEAR(roll / static_cast<double>(trace->size()), p.meanAbsRoll, 0.005) << p.file;
  }
}

TEST(VrHead, BadTracesAreRefusedNamingFileAndLine) {
  const fs::path dir = test::freshDir("vr_bad");
  const fs::path csv = dir / "head.csv";
  auto refused = [&](const std::string& text, const std::string& where, const std::string& what) {
    std::ofstream(csv, std::ios::trunc) << text;
    const auto r = readHeadTrace(csv);
    ASSERT_FALSE(r) << text;
    EXPECT_NE(r.error().message.find(where), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(what), std::string::npos) << r.error().message;
  };
  const std::string header = "time,x,y,z,qx,qy,qz,qw\n";
  refused(header + "0,0,0,0,0,0,0,1\n0.1,0,0,x,0,0,0,1\n", "head.csv:3:", "not a number");
  refused(header + "0,0,0,0,0,0,0,1\n0.1,0,0,0,0,0,0.1,0.9\n", "head.csv:3:", "unit quaternion");  // length 0.906
  refused(header + "0,0,0,0,0,0,0,1\n0,0,0,0,0,0,0,1\n", "head.csv:3:", "times must increase");
  refused(header + "0,0,0,0,0,0,0,1\n0.2,0,0,0,0,0,0,1\n0.1,0,0,0,0,0,0,1\n", "head.csv:4:", "times must increase");
  refused(header + "0,0,0,0,0,0,0,1\n", "head.csv", "at least 2");
  refused(header + "0,0,0,0,0,0,1\n", "head.csv:2:", "expected 8");
  // merge-camera's own reading of a CSV normalises such a quaternion (a recorded camera run may be
  // written with few digits); only a head trace is held to unit length.
  std::ofstream(csv, std::ios::trunc) << header << "0,0,0,0,0,0,0,2\n0.1,0,0,0,0,0,0,2\n";
  EXPECT_TRUE(readCameraRun(csv));
  EXPECT_FALSE(readHeadTrace(csv));

  // The command: a bad trace exits non-zero naming the line, and writes no dataset.
  const auto [dataset, stretchEnd] = test::writeUTurnDataset(dir);
  std::ofstream(csv, std::ios::trunc) << header << "0,0,0,0,0,0,0,1\n0.1,0,0,0,0,0,0.5,0.5\n";
  const auto r = dynbench::dynbench(fmt::format("vr-camera {} --trace {} -o {}", dataset.string(), csv.string(), (dir / "vr.gltf").string()), dir);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("head.csv:3:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "vr.gltf"));
  // A trace shorter than the dataset: refused, saying how much is needed.
  std::ofstream(csv, std::ios::trunc) << header << "0,0,0,0,0,0,0,1\n2,0,0,0,0,0,0,1\n";
  const auto shorter = dynbench::dynbench(fmt::format("vr-camera {} --trace {} -o {}", dataset.string(), csv.string(), (dir / "vr.gltf").string()), dir);
  EXPECT_NE(shorter.status, 0);
  EXPECT_NE(shorter.err.find("the trace covers 2.000 s"), std::string::npos) << shorter.err;
  EXPECT_FALSE(fs::exists(dir / "vr.gltf"));
}

// A head rolling at a constant 30°/s, sampled at a headset's uneven 14 and 28 ms, comes out of the
// resampling rolling the same amount every frame: slerp between poses about one axis is exact.
// Through the whole VR dataset (the play space turning with the path's yaw, which adds no roll)
// `stats` then measures 30/24 degrees of roll a frame at 24 fps with no variance.
TEST(VrHead, AConstantRollRateGivesTheSameRollEveryFrame) {
  const fs::path dir = test::freshDir("vr_roll");
  const fs::path csv = dir / "roll.csv";
  const double rate = 30.0;  // degrees a second
  {
    std::ofstream out(csv);
    out << "time,x,y,z,qx,qy,qz,qw\n";
    double t = 0;
    for (int k = 0; t <= 25.0; ++k, t += (k % 3 == 0 ? 0.028 : 0.014)) {
      const glm::dquat q = glm::angleAxis(radians(rate * t), glm::dvec3(0, 0, 1));
      out << fmt::format("{:.3f},0,0,0,{:.9f},{:.9f},{:.9f},{:.9f}\n", t, q.x, q.y, q.z, q.w);
    }
  }
  auto trace = readHeadTrace(csv);
  ASSERT_TRUE(trace) << trace.error().message;
  for (int f = 0; f < 200; ++f) {
    const double t = f / 24.0;
    const CameraPoseKey pose = headPoseAt(*trace, t);
    EXPECT_NEAR(wrapDegrees(degrees(eulerYawPitchRoll(pose.rotation).roll) - rate * t), 0.0, 1e-5) << "frame " << f;
  }
  // Clamped at the ends.
  EXPECT_EQ(headPoseAt(*trace, -1.0).rotation, trace->front().rotation);
  EXPECT_EQ(headPoseAt(*trace, 1e3).rotation, trace->back().rotation);

  const auto [dataset, stretchEnd] = test::writeUTurnDataset(dir);
  VrCameraOptions o;
  o.trace = csv;
  o.body.frameRate = 24.0;
  auto made = makeVrCameraDataset(dataset, dir / "vr.gltf", dir / "vr.csv", o);
  ASSERT_TRUE(made) << made.error().message;
  EXPECT_NEAR(made->motion.roll.mean, rate / 24.0, 1e-3);
  EXPECT_LT(made->motion.roll.variance, 1e-5);
  EXPECT_EQ(made->report.maxOffset, 0.0);  // the head never left where it started
}

// A head stepping 3 m (24 units) to its left within its first second and staying there. On the
// U-turn's first leg (x = -10, facing +Z) the left is +x, towards the wall at x = 0; round the U the
// play space turns with the path, and on the way back (x = +10, facing -Z) the left is -x, towards
// the wall's other side. Every head stays `clearance` clear of the wall and no chord between poses
// crosses it; where the step points at the wall the head stops short, at the clearance.
TEST(VrHead, AHeadOffsetIntoAWallStopsShortOfIt) {
  const fs::path dir = test::freshDir("vr_wall");
  const fs::path csv = dir / "step.csv";
  {
    std::ofstream out(csv);
    out << "time,x,y,z,qx,qy,qz,qw\n";
    for (int k = 0; k <= 25 * 50; ++k) {
      const double t = k / 50.0;
      out << fmt::format("{:.3f},{:.6f},0,0,0,0,0,1\n", t, -3.0 * std::min(1.0, t));  // 3 m to the left within 1 s
    }
  }
  const auto [dataset, stretchEnd] = test::writeUTurnDataset(dir);
  VrCameraOptions o;
  o.trace = csv;
  auto report = writeVrCameraCsv(dataset, dir / "vr.csv", o);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_GT(report->clamped, 0u);
  EXPECT_NEAR(report->maxOffset, 3.0, 1e-6);  // where no wall is in the way, the step is whole
  auto keys = readCameraRun(dir / "vr.csv");
  ASSERT_TRUE(keys);
  const double clearance = o.clearance / o.metresPerUnit;  // 1.2 units
  bool stoppedAtClearance = false;
  for (std::size_t n = 0; n < keys->size(); ++n) {
    const glm::dvec3 p = (*keys)[n].position;
    if (p.z < 5.0) {
      EXPECT_GE(std::abs(p.x), 0.99 * clearance - 1e-3) << "pose " << n << " is within the clearance of the wall";
      if (std::abs(std::abs(p.x) - clearance) < 0.01) stoppedAtClearance = true;
    }
    if (n == 0) continue;
    const glm::dvec3 a = (*keys)[n - 1].position;
    if ((a.x < 0) != (p.x < 0) && a.x != p.x) {  // a chord crossing the plane x = 0 must pass beyond the wall's end
      const double s = a.x / (a.x - p.x);
      EXPECT_GT(a.z + s * (p.z - a.z), 5.0) << "the chord into pose " << n << " goes through the wall";
    }
  }
  EXPECT_TRUE(stoppedAtClearance);
}

// The same VR dataset, byte for byte, when made as another machine would (other_machine.h: other
// Embree kernels, glibc without its AVX2 and FMA paths), with a real trace.
TEST(VrHead, TheSameBytesAsAnotherMachine) {
  const fs::path dir = test::freshDir("vr_machines");
  const auto [dataset, stretchEnd] = test::writeUTurnDataset(dir);
  const fs::path trace = kTraces / "eyenavgs_nthu_truck_user8_walking.csv";
  std::string bytes[2][2];
  for (int machine = 0; machine < 2; ++machine) {
    std::optional<test::OtherMachine> other;
    if (machine == 1) other.emplace();
    const std::string name = fmt::format("vr{}", machine);
    const auto r = dynbench::dynbench(fmt::format("vr-camera {} --trace {} -o {}", dataset.string(), trace.string(), (dir / (name + ".gltf")).string()), dir);
    ASSERT_EQ(r.status, 0) << r.err;
    bytes[machine][0] = test::slurp(dir / (name + ".gltf"));
    bytes[machine][1] = test::slurp(dir / (name + ".bin"));
  }
  EXPECT_GT(bytes[0][1].size(), 1000u);
  // The .gltf names its own .bin: equal once the file names are.
  std::string other = bytes[1][0];
  for (std::size_t at; (at = other.find("vr1.bin")) != std::string::npos;) other.replace(at, 7, "vr0.bin");
  EXPECT_EQ(bytes[0][0], other);
  EXPECT_EQ(bytes[0][1], bytes[1][1]);
}

// A suite's "vr" camera names its trace, relative to the manifest; only "vr" has one.
TEST(VrHead, TheSuiteCameraNamesItsTrace) {
  nlohmann::json doc = {{"dynbench_suite", 1},
                        {"name", "vr"},
                        {"datasets", {{{"name", "a"}, {"preset", "fps"}, {"seed", 1u}, {"seconds", 10}, {"camera", "vr"},
                                       {"trace", "../data/vr-head/eyenavgs_nthu_london_user7_quickturns.csv"}}}}};
  auto m = suite::parseManifest(doc, "/repo/suites/x.json");
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_EQ(m->datasets[0].tracePath, fs::path("/repo/data/vr-head/eyenavgs_nthu_london_user7_quickturns.csv"));
  EXPECT_EQ(m->datasets[0].cameraLabel(), "vr-eyenavgs_nthu_london_user7_quickturns");
  doc["datasets"][0].erase("trace");
  auto missing = suite::parseManifest(doc, "x.json");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("x.json: /datasets/0/trace: expected the head trace"), std::string::npos) << missing.error().message;
  doc["datasets"][0]["camera"] = "bot";
  doc["datasets"][0]["trace"] = "a.csv";
  auto stray = suite::parseManifest(doc, "x.json");
  ASSERT_FALSE(stray);
  EXPECT_NE(stray.error().message.find("/datasets/0/trace: expected no trace"), std::string::npos) << stray.error().message;
  doc["datasets"][0]["camera"] = "headset";
  auto unknown = suite::parseManifest(doc, "x.json");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find("\"vr\""), std::string::npos) << unknown.error().message;
}

}  // namespace
}  // namespace dynbench::camera
