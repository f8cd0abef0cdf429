// `dynbench demo`: the fly-through's camera path (known answers on a synthetic dataset), and the
// whole chain on a short Cube 2 match (skipped, saying why, without the game).
#include <cmath>

#include <gtest/gtest.h>

#include "frames/feature_frame.h"
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "capture/cube2.h"
#include "core/files.h"
#include "core/math.h"
#include "pipeline/demo.h"
#include "gltf_builder.h"
#include "external_tools.h"
#include "run_cli.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;

TEST(Demo, FlythroughPassesThroughTheKeysAndTurnsSlowly) {
  // A camera that zigzags: (0,0,0) -> (10,0,0) -> (10,0,-10) -> (20,0,-10) -> (20,0,-20) over 4 s.
  const fs::path dir = test::freshDir("demo_fly");
  test::GltfBuilder b;
  const int cam = b.node({{"name", "eye"}, {"camera", b.perspectiveCamera()}});
  b.channel(cam, "translation", {0, 1, 2, 3, 4}, {0, 0, 0, 10, 0, 0, 10, 0, -10, 20, 0, -10, 20, 0, -20});
  const fs::path dataset = b.write(dir, "zigzag");
  ASSERT_TRUE(demo::writeFlythroughCsv(dataset, dir / "fly.csv", 5, 60.0));
  const std::string csv = test::slurp(dir / "fly.csv");
  std::vector<std::array<double, 8>> rows;
  std::size_t start = csv.find('\n') + 1;
  for (std::size_t end; (end = csv.find('\n', start)) != std::string::npos; start = end + 1) {
    std::array<double, 8> r{};
    ASSERT_EQ(std::sscanf(csv.substr(start, end - start).c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &r[0], &r[1], &r[2], &r[3], &r[4],
                          &r[5], &r[6], &r[7]),
              8);
    rows.push_back(r);
  }
  ASSERT_EQ(rows.size(), 241u);  // 4 s at 60 poses/s, both ends
  // Catmull-Rom interpolates its control points: at t = 0, 1, 2, 3, 4 s the keys themselves.
  const double keys[5][3] = {{0, 0, 0}, {10, 0, 0}, {10, 0, -10}, {20, 0, -10}, {20, 0, -20}};
  for (int k = 0; k < 5; ++k) {
    const auto& r = rows[static_cast<std::size_t>(60 * k)];
    EXPECT_NEAR(r[0], k, 1e-9);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(r[static_cast<std::size_t>(1 + c)], keys[k][c], 1e-6) << k;
  }
  // Level (rotation about +Y only) and never faster than 30 degrees per second.
  double fastest = 0;
  for (std::size_t n = 0; n < rows.size(); ++n) {
    EXPECT_NEAR(rows[n][4], 0.0, 1e-12);
    EXPECT_NEAR(rows[n][6], 0.0, 1e-12);
    if (n == 0) continue;
    const glm::dquat a(rows[n - 1][7], rows[n - 1][4], rows[n - 1][5], rows[n - 1][6]), c(rows[n][7], rows[n][4], rows[n][5], rows[n][6]);
    fastest = std::max(fastest, degrees(geodesicAngle(a, c)) * 60.0);
  }
  EXPECT_LE(fastest, 30.0 + 1e-6);
  EXPECT_GT(fastest, 29.0);  // the zigzag's corners make it turn at the limit
}

TEST(Demo, WholeChainOnAShortMatch) {
  DYNBENCH_NEEDS(test::missingCube2());
  const fs::path dir = test::freshDir("demo_chain");
  const auto r = dynbench(fmt::format("demo -o {} --seconds 3 --bots 4 --res 32x18 --spp 1 --max-spp 32 --render-frames 12 --bounces 1", (dir / "demo").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("report: "), std::string::npos) << r.out;
  const std::string md = test::slurp(dir / "demo" / "report.md");
  EXPECT_NE(md.find("| colos_bot "), std::string::npos);
  EXPECT_NE(md.find("| colos_flythrough "), std::string::npos);
  // Table 6.5: the fly-through turns no faster than 30 deg/s, i.e. 1.25 deg per frame at 24 fps.
  const auto table = md.find("Table 6.5.");
  const auto row = md.find("| colos_flythrough ", table);
  ASSERT_NE(row, std::string::npos);
  double mean = 0, variance = 0, max = 0;
  ASSERT_EQ(std::sscanf(md.c_str() + md.find('|', row + 2), "| %lf | %lf | %lf", &mean, &variance, &max), 3) << md.substr(row, 80);
  EXPECT_LE(max, 1.25 + 1e-3);
  EXPECT_TRUE(fs::exists(dir / "demo" / "report.html"));
  EXPECT_TRUE(fs::exists(dir / "demo" / "runs" / "colos_bot" / "discard.json"));
  // The demo renders a converged window and Table 6.7 prints the radiance columns' intervals.
  EXPECT_NE(md.find(" ± "), std::string::npos) << md;
  const auto discardJson = nlohmann::json::parse(test::slurp(dir / "demo" / "runs" / "colos_bot" / "discard.json"));
  EXPECT_EQ(discardJson["frames"].size(), 11u);
  EXPECT_EQ(discardJson["mean"]["interval"]["direct_radiance"].size(), 2u);
  // Temporal methods on both datasets: every method scored on every frame of the window, the
  // first frame a reset, and the Markdown's table with a row per dataset and method.
  for (const char* run : {"colos_bot", "colos_flythrough"}) {
    const auto evaluation = nlohmann::json::parse(test::slurp(dir / "demo" / "runs" / run / "evaluate.json"));
    ASSERT_EQ(evaluation["methods"].size(), 4u) << run;
    for (const auto& method : evaluation["methods"]) {
      EXPECT_EQ(method["frames"].size(), 12u) << run;
      EXPECT_EQ(method["frames"][0]["history_use"].get<double>(), 0.0) << run;
      EXPECT_GT(method["mean"]["flip"]["mean"].get<double>(), 0.0) << run;
      // A line of the Markdown with the dataset in its first column and the method in its second
      // (cells padded to the column's width).
      bool found = false;
      for (std::size_t at = md.find(fmt::format("| {} ", run)); at != std::string::npos && !found; at = md.find(fmt::format("| {} ", run), at + 1)) {
        const std::size_t second = md.find('|', at + 1), third = md.find('|', second + 1);
        std::string cell = md.substr(second + 1, third - second - 1);
        cell.erase(0, cell.find_first_not_of(' '));
        cell.erase(cell.find_last_not_of(' ') + 1);
        found = cell == method["name"].get<std::string>();
      }
      EXPECT_TRUE(found) << run << " " << method["name"];
    }
  }

  // Convergence (the acceptance, at a size the suite affords): the seeded segment (colos,
  // 4 bots, 3 s, seed 1), frames 40-47, rendered to convergence with two seeds gives direct and
  // indirect discard means within 0.5 percentage points of each other, each inside the other's
  // interval; the same with half the tolerance.
  const fs::path dataset = dir / "demo" / "datasets" / "colos_bot.gltf";
  for (const double tolerance : {0.5, 0.25}) {
    nlohmann::json discarded[2];
    for (int seed = 1; seed <= 2; ++seed) {
      const fs::path frames = dir / fmt::format("converged_{}_{}", tolerance, seed);
      const auto rendered = dynbench(fmt::format("render {} -o {} --res 32x18 --frames 40:47 --bounces 2 --converge --tolerance {} "
                                                 "--max-spp 4096 --seed {}",
                                                 dataset.string(), frames.string(), tolerance, seed),
                                     dir);
      ASSERT_EQ(rendered.status, 0) << rendered.err;
      const auto d = dynbench(fmt::format("discard {} --relative-position --json {}", frames.string(), (frames / "d.json").string()), dir);
      ASSERT_EQ(d.status, 0) << d.err;
      discarded[seed - 1] = nlohmann::json::parse(test::slurp(frames / "d.json"));
    }
    for (const char* column : {"direct_radiance", "indirect_radiance"}) {
      const double a = discarded[0]["mean"][column], b = discarded[1]["mean"][column];
      const auto& ia = discarded[0]["mean"]["interval"][column];
      const auto& ib = discarded[1]["mean"]["interval"][column];
      std::printf("tolerance %.2f %s: seed 1 %.3f [%.3f, %.3f], seed 2 %.3f [%.3f, %.3f]\n", tolerance, column, a, ia[0].get<double>(),
                  ia[1].get<double>(), b, ib[0].get<double>(), ib[1].get<double>());
      EXPECT_NEAR(a, b, 0.5) << column << " at tolerance " << tolerance;
      EXPECT_GE(a, ib[0].get<double>()) << column;
      EXPECT_LE(a, ib[1].get<double>()) << column;
      EXPECT_GE(b, ia[0].get<double>()) << column;
      EXPECT_LE(b, ia[1].get<double>()) << column;
    }
  }

  // Frames a disk can hold (docs/feature-buffers.md, "Precision on disk"): the same render stored
  // at the contract's precision and at 32 bits gives the same discard means within 0.01
  // percentage points, in at most 40 bytes per pixel.
  {
    nlohmann::json discarded[2];
    double bytesPerPixel[2] = {0, 0};
    for (int full = 0; full < 2; ++full) {
      const fs::path frames = dir / (full ? "storage_float32" : "storage_contract");
      const auto rendered = dynbench(fmt::format("render {} -o {} --res 96x54 --frames 40:47 --bounces 2 --spp 8{}", dataset.string(),
                                                 frames.string(), full ? " --float32" : ""),
                                     dir);
      ASSERT_EQ(rendered.status, 0) << rendered.err;
      std::uintmax_t bytes = 0;
      for (long f = 40; f <= 47; ++f) bytes += fs::file_size(frames::frameImagePath(frames, f));
      bytesPerPixel[full] = static_cast<double>(bytes) / (8.0 * 96 * 54);
      const auto d = dynbench(fmt::format("discard {} --relative-position --json {}", frames.string(), (frames / "d.json").string()), dir);
      ASSERT_EQ(d.status, 0) << d.err;
      discarded[full] = nlohmann::json::parse(test::slurp(frames / "d.json"));
    }
    std::printf("bytes per pixel: %.2f at the contract's precision, %.2f at 32 bits\n", bytesPerPixel[0], bytesPerPixel[1]);
    EXPECT_LE(bytesPerPixel[0], 40.0);
    EXPECT_LT(bytesPerPixel[0], 0.75 * bytesPerPixel[1]);
    for (const auto& [column, value] : discarded[1]["mean"].items()) {
      if (!value.is_number()) continue;
      std::printf("%s: %.4f (contract) vs %.4f (32-bit)\n", column.c_str(), discarded[0]["mean"][column].get<double>(), value.get<double>());
      EXPECT_NEAR(discarded[0]["mean"][column].get<double>(), value.get<double>(), 0.01) << column;
    }
  }

  // A rerun with the same options reuses the capture; with another seed it captures again (it
  // used to measure the old match under the new options' name).
  const std::string capture = test::slurp(dir / "demo" / "capture" / "Capture.txt");
  const std::string args = fmt::format("demo -o {} --seconds 3 --bots 4 --res 32x18 --spp 1 --max-spp 32 --render-frames 12 --bounces 1", (dir / "demo").string());
  auto again = dynbench(args, dir);
  ASSERT_EQ(again.status, 0) << again.err << again.out;
  EXPECT_NE(again.out.find("exists, reused"), std::string::npos) << again.out;
  EXPECT_EQ(test::slurp(dir / "demo" / "capture" / "Capture.txt"), capture);
  again = dynbench(args + " --seed 2", dir);
  ASSERT_EQ(again.status, 0) << again.err << again.out;
  EXPECT_NE(again.out.find("was made with other options, capturing again"), std::string::npos) << again.out;
  EXPECT_NE(test::slurp(dir / "demo" / "capture" / "Capture.txt"), capture);
  EXPECT_NE(test::slurp(dir / "demo" / "capture" / "dynbench-demo-capture.json").find("\"seed\": 2"), std::string::npos);
  EXPECT_NE(again.out.find("convert: capture ->"), std::string::npos) << again.out;  // the dataset follows the new capture
}

}  // namespace
}  // namespace dynbench
