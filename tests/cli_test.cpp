// The dynbench executable end to end: outputs checked by reading them back, errors by exit status
// and message, and no output file left behind by a failed run.
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "core/image_io.h"
#include "dynbench/version.h"
#include "gltf_builder.h"
#include "external_tools.h"
#include "golden.h"
#include "run_cli.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;


fs::path yawScene(const fs::path& dir) {
  test::GltfBuilder b;
  const int n = b.node({{"name", "eye"}, {"camera", b.perspectiveCamera()}});
  std::vector<float> times, values, positions;
  for (int k = 0; k <= 48; ++k) {
    times.push_back(static_cast<float>(k / 24.0));
    for (float v : test::yawQuat(7.5 * k)) values.push_back(v);
  }
  b.channel(n, "rotation", times, values);
  b.channel(n, "translation", {0, 2}, {0, 0, 0, 0, 0, -96});  // 2 units per frame
  return b.write(dir, "yaw");
}

TEST(Cli, VersionAndHelp) {
  const auto dir = test::freshDir("cli_help");
  auto r = dynbench("--version", dir);
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find(kVersion), std::string::npos);
  r = dynbench("help stats", dir);
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("--fps"), std::string::npos);
  EXPECT_NE(r.out.find("--fps FLOAT:POSITIVE=24"), std::string::npos) << r.out;  // the default, from the options struct
  r = dynbench("--help", dir);
  EXPECT_NE(r.out.find("stats"), std::string::npos);
  r = dynbench("help frobnicate", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("frobnicate"), std::string::npos);
  r = dynbench("stats", dir);  // FILE is required
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("FILE is required"), std::string::npos) << r.err;
}

// docs/cli.md: the same mistake gets the same status, 2, in every command, with a message naming
// the option.
TEST(Cli, SameMistakeSameStatusInEveryCommand) {
  const auto dir = test::freshDir("cli_same_status");
  for (const std::string command : {"stats x.gltf", "capture-check x", "convert x -o y.gltf", "merge-camera a.gltf b.csv -o c.gltf",
                                    "render x.gltf -o y", "discard x", "report x -o y.html", "capture cube2 -o x", "demo",
                                    "compare a.exr b.exr", "evaluate x --reference y"}) {
    const auto r = dynbench(command + " --no-such-option", dir);
    EXPECT_EQ(r.status, 2) << command << ": " << r.err;
    EXPECT_NE(r.err.find("dynbench: error: The following argument was not expected: --no-such-option"), std::string::npos)
        << command << ": " << r.err;
  }
  struct Case {
    std::string args, message;
  };
  for (const Case& c : {Case{"stats x.gltf --fps -3", "--fps: must be positive (got -3)"},
                        Case{"render x.gltf -o y --fps -3", "--fps: must be positive (got -3)"},
                        Case{"demo --fps -3", "--fps: must be positive (got -3)"},
                        Case{"capture cube2 -o x --fps -3", "--fps: must be from 0.001 to 1000 (got -3)"},
                        Case{"stats x.gltf --sequence-rate 0", "--sequence-rate: must be positive (got 0)"},
                        Case{"render x.gltf -o y --threads -2", "--threads: must be 0 or more (got -2)"},
                        Case{"render x.gltf -o y --bounces -1", "--bounces: must be 0 or more (got -1)"},
                        Case{"demo --spp 0", "--spp: must be positive (got 0)"},
                        Case{"demo --bots 40", "--bots: must be from 1 to 32 (got 40)"},
                        Case{"demo --game-cpu arm", "--game-cpu 'arm': expected emulated or host"},
                        Case{"discard x --threshold-normal -1", "--threshold-normal: must be 0 or more (got -1)"},
                        Case{"report x -o y.html --thumbnails -1", "--thumbnails: must be 0 or more (got -1)"},
                        Case{"convert x -o y.gltf --turbidity 1", "--turbidity: must be from 1.7 to 10 (got 1)"},
                        Case{"render x.gltf -o y --spp many", "--spp: expected a number, got 'many'"},
                        Case{"compare a.exr b.exr --ppd 0", "--ppd: must be positive (got 0)"},
                        Case{"evaluate x --reference y --ppd -1", "--ppd: must be positive (got -1)"}}) {
    const auto r = dynbench(c.args, dir);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << ": " << r.err;
  }
}

TEST(Cli, StatsWritesTablesJsonCsvSeriesAndPlots) {
  const auto dir = test::freshDir("cli_stats");
  const auto scene = yawScene(dir);
  const auto r = dynbench(fmt::format("stats {} --json {} --csv {} --series {} --plots {}", scene.string(),
                                      (dir / "s.json").string(), (dir / "s.csv").string(), (dir / "series").string(),
                                      (dir / "plots").string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // Markdown tables on stdout with the known answers.
  for (const char* title : {"Table 6.1", "Table 6.2", "Table 6.3", "Table 6.4", "Table 6.5", "Table 6.6"})
    EXPECT_NE(r.out.find(title), std::string::npos) << title;
  EXPECT_NE(r.out.find("| yaw.gltf |"), std::string::npos);
  EXPECT_NE(r.out.find("7.500"), std::string::npos);
  EXPECT_NE(r.out.find("2.000"), std::string::npos);

  const auto json = nlohmann::json::parse(test::slurp(dir / "s.json"));
  const auto& d = json["datasets"][0];
  EXPECT_EQ(d["properties"]["animation_frames"], 49);
  EXPECT_TRUE(d["properties"]["animated_camera"].get<bool>());
  EXPECT_NEAR(d["camera_motion"]["yaw_degrees"]["mean"].get<double>(), 7.5, 1e-4);
  EXPECT_NEAR(d["camera_motion"]["rotation_degrees"]["max"].get<double>(), 7.5, 1e-4);
  // The thesis's Table 6.5 convention: Eq. 2.4 taken literally, half the angle (a 7.5-degree turn
  // is ||ln q|| = 3.75 degrees); the variance of a constant turn stays 0.
  EXPECT_NEAR(d["camera_motion"]["rotation_eq24"]["mean"].get<double>(), 3.75, 1e-4);
  EXPECT_NEAR(d["camera_motion"]["rotation_eq24"]["max"].get<double>(), 3.75, 1e-4);
  EXPECT_NEAR(d["camera_motion"]["rotation_eq24"]["variance"].get<double>(), d["camera_motion"]["rotation_degrees"]["variance"].get<double>() / 4, 1e-12);
  EXPECT_NEAR(d["camera_motion"]["position"]["mean"].get<double>(), 2.0, 1e-4);
  EXPECT_EQ(d["camera_motion"]["camera"], "eye");

  std::istringstream csv(test::slurp(dir / "s.csv"));
  std::string header, row, extra;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_FALSE(std::getline(csv, extra));
  auto column = [&](const std::string& name) {
    std::vector<std::string> h, v;
    for (std::istringstream hs(header), vs(row); ;) {
      std::string a, b;
      if (!std::getline(hs, a, ',') || !std::getline(vs, b, ',')) break;
      h.push_back(a);
      v.push_back(b);
    }
    for (std::size_t i = 0; i < h.size(); ++i)
      if (h[i] == name) return v[i];
    return std::string("missing");
  };
  EXPECT_NEAR(std::stod(column("yaw_mean_deg")), 7.5, 1e-4);
  EXPECT_EQ(column("animation_frames"), "49");

  const std::string series = test::slurp(dir / "series/yaw.gltf_camera.csv");
  EXPECT_EQ(std::count(series.begin(), series.end(), '\n'), 50);  // header + 49 frames

  for (const char* figure : {"rotation_per_axis", "rotation_geodesic"}) {
    const std::string png = test::slurp(dir / "plots" / fmt::format("yaw.gltf_{}.png", figure));
    ASSERT_GT(png.size(), 1000u) << figure;
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    // IHDR: big-endian width and height at bytes 16-23; the plots are 1200 x 450.
    auto be32 = [&](std::size_t at) {
      return (static_cast<unsigned char>(png[at]) << 24) | (static_cast<unsigned char>(png[at + 1]) << 16) |
             (static_cast<unsigned char>(png[at + 2]) << 8) | static_cast<unsigned char>(png[at + 3]);
    };
    EXPECT_EQ(png.substr(12, 4), "IHDR");
    EXPECT_EQ(be32(16), 1200);
    EXPECT_EQ(be32(20), 450);
    const std::string svg = test::slurp(dir / "plots" / fmt::format("yaw.gltf_{}.svg", figure));
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
  }
  for (const auto& entry : fs::directory_iterator(dir / "plots"))  // no temporaries left over
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();

  // Titles are literal text: an underscore in a dataset name is not a gnuplot subscript.
  fs::copy_file(scene, dir / "yaw_scene.gltf");
  const auto named = dynbench(fmt::format("stats {} --plots {}", (dir / "yaw_scene.gltf").string(), (dir / "plots2").string()), dir);
  ASSERT_EQ(named.status, 0) << named.err;
  const std::string svg = test::slurp(dir / "plots2" / "yaw_scene.gltf_rotation_geodesic.svg");
  EXPECT_NE(svg.find("yaw_scene.gltf: geodesic change"), std::string::npos) << svg.substr(0, 3000);
}

TEST(Cli, BadInputFailsClearlyAndWritesNothing) {
  const auto dir = test::freshDir("cli_bad");
  test::GltfBuilder b;
  const int n = b.node({{"name", "cam"}});
  b.channel(n, "translation", {0, 1}, {0, 0, 0, std::nanf(""), 0, 0});
  const auto scene = b.write(dir, "nan");
  auto r = dynbench(fmt::format("stats {} --json {}", scene.string(), (dir / "out.json").string()), dir);
  EXPECT_EQ(r.status, 5);  // ErrorCode::kInvalidData
  EXPECT_NE(r.err.find("nan.gltf: /animations/0/samplers/0/output"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.json"));
  EXPECT_TRUE(r.out.empty());

  r = dynbench(fmt::format("stats {} --camera nobody", yawScene(dir).string()), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("nobody"), std::string::npos);

  r = dynbench(fmt::format("stats {} --animation nope", yawScene(dir).string()), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("animations in the file: 0 ''"), std::string::npos) << r.err;

  r = dynbench(fmt::format("stats {}", (dir / "does-not-exist.glb").string()), dir);
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("does-not-exist.glb"), std::string::npos);

  r = dynbench(fmt::format("stats {} --fps -3", yawScene(dir).string()), dir);
  EXPECT_NE(r.status, 0);
}

TEST(Cli, CompareAndEvaluateMapErrorsToStatuses) {
  const auto dir = test::freshDir("cli_compare");
  for (const auto& [name, w] : {std::pair{"a.exr", 16}, std::pair{"b.exr", 8}}) {
    FloatImage image;
    image.width = w, image.height = 16, image.channels = 3, image.pixels.assign(static_cast<std::size_t>(3 * w * 16), 0.5f);
    ASSERT_TRUE(writeImage(dir / name, image).has_value());
  }
  const std::string a = (dir / "a.exr").string(), b = (dir / "b.exr").string(), missing = (dir / "missing.exr").string();
  auto r = dynbench(fmt::format("compare {} {}", a, a), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| a.exr | 0.0000 |"), std::string::npos) << r.out;
  r = dynbench(fmt::format("compare {} {}", a, b), dir);
  EXPECT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find(b + ": 8x16 pixels, but the reference " + a + " is 16x16"), std::string::npos) << r.err;
  r = dynbench(fmt::format("compare {} {} --json {}", a, missing, (dir / "out.json").string()), dir);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("missing.exr"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.json"));
  r = dynbench(fmt::format("evaluate {0} --reference {0}", (dir / "nowhere").string()), dir);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("nowhere: not a folder of frames"), std::string::npos) << r.err;
}

TEST(Cli, SeveralDatasetsOneRowEach) {
  const auto dir = test::freshDir("cli_many");
  const fs::path testdata = DYNBENCH_TESTDATA_DIR;
  const auto r = dynbench(fmt::format("stats {} {} --json {}", (testdata / "SimpleSkin/SimpleSkin.gltf").string(),
                                      yawScene(dir).string(), (dir / "m.json").string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto json = nlohmann::json::parse(test::slurp(dir / "m.json"));
  ASSERT_EQ(json["datasets"].size(), 2u);
  EXPECT_EQ(json["datasets"][0]["properties"]["armatures"], 1);
  EXPECT_TRUE(json["datasets"][0]["camera_motion"]["camera"].is_null());
  EXPECT_NE(r.out.find("| SimpleSkin.gltf |"), std::string::npos);
}

// Golden output of `stats` on fixed inputs: the bundled orbit scene and two Khronos samples.
TEST(Golden, StatsMarkdown) {
  const auto dir = test::freshDir("golden_stats");
  const fs::path samples = fs::path(DYNBENCH_TESTDATA_DIR);
  const auto r = dynbench(fmt::format("stats {} {} {}", (fs::path(DYNBENCH_SOURCE_DIR) / "examples/orbit/orbit.gltf").string(),
                                      (samples / "BoxAnimated/BoxAnimated.gltf").string(),
                                      (samples / "RiggedFigure/RiggedFigure.gltf").string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  test::expectGolden(r.out, "stats.md");
}

}  // namespace
}  // namespace dynbench

namespace dynbench {
namespace {

// Run only on purpose (below): a test that needs a tool no machine has.
TEST(ExternalTools, DISABLED_NeedsAMissingTool) { DYNBENCH_NEEDS(std::string("the tool frobnicate is not installed")); }

// DYNBENCH_NEEDS skips a test whose tool is missing, and with DYNBENCH_REQUIRE_ALL=1 (.ci/run)
// fails it instead.
TEST(ExternalTools, RequireAllTurnsASkipIntoAFailure) {
  const auto dir = test::freshDir("require_all");
  std::error_code ec;
  const std::string self = fs::read_symlink("/proc/self/exe", ec).string();
  const std::string args = " --gtest_also_run_disabled_tests --gtest_filter=ExternalTools.DISABLED_NeedsAMissingTool 2>&1";
  std::string out;
  EXPECT_EQ(runShell("env -u DYNBENCH_REQUIRE_ALL " + self + args, out), 0) << out;
  EXPECT_NE(out.find("[  SKIPPED ]"), std::string::npos) << out;
  out.clear();
  EXPECT_NE(runShell("DYNBENCH_REQUIRE_ALL=1 " + self + args, out), 0) << out;
  EXPECT_NE(out.find("the tool frobnicate is not installed (DYNBENCH_REQUIRE_ALL=1: no skips)"), std::string::npos) << out;
}

}  // namespace
}  // namespace dynbench
