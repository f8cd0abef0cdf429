// `dynbench demo`: the fly-through's camera path (known answers on a synthetic dataset), and the
// whole chain on a short Cube 2 match (skipped, saying why, without the game).
#include <array>
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "frames/feature_frame.h"
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "capture/cube2.h"
#include "core/files.h"
#include "core/math.h"
#include "suite/demo.h"
#include "camera/flythrough.h"
#include "render/raytracing_scene.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "scene/queries.h"
#include "gltf_builder.h"
#include "external_tools.h"
#include "run_cli.h"
#include "shared_run.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;

std::vector<std::array<double, 8>> readPoses(const fs::path& csv) {
  const std::string text = test::slurp(csv);
  std::vector<std::array<double, 8>> rows;
  std::size_t start = text.find('\n') + 1;
  for (std::size_t end; (end = text.find('\n', start)) != std::string::npos; start = end + 1) {
    std::array<double, 8> r{};
    EXPECT_EQ(std::sscanf(text.substr(start, end - start).c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &r[0], &r[1], &r[2], &r[3], &r[4],
                          &r[5], &r[6], &r[7]),
              8);
    rows.push_back(r);
  }
  return rows;
}

// The ORCA ranges come from the thesis's data file, the one copy of its numbers: known answers from
// its Tables 6.4-6.6 (the smallest and largest of Bistro Interior, Bistro Exterior and Emerald
// Square), and the fly-through's bounds are those ranges' ends.
TEST(Flythrough, OrcaRangesAreTheThesisRowsExtremes) {
  using camera::orcaRange;
  EXPECT_DOUBLE_EQ(orcaRange("6.4", 0).low, 0.013);
  EXPECT_DOUBLE_EQ(orcaRange("6.4", 2).high, 0.248);
  EXPECT_DOUBLE_EQ(orcaRange("6.5", 0).low, 0.134);  // Bistro Exterior, below the Wine camera's 0.136
  EXPECT_DOUBLE_EQ(orcaRange("6.5", 0).high, 0.258);
  EXPECT_DOUBLE_EQ(orcaRange("6.6", 2).low, 0.265);
  EXPECT_DOUBLE_EQ(orcaRange("6.6", 3).high, 0.095);
  EXPECT_DOUBLE_EQ(orcaRange("6.6", 5).high, 0.0);
  EXPECT_TRUE(std::isnan(orcaRange("6.6", 9).low));  // no such column
  EXPECT_TRUE(std::isnan(orcaRange("9.9", 0).low));  // no such table
  const camera::FlythroughOptions o;
  EXPECT_DOUBLE_EQ(o.maxYawMean, 0.511);
  EXPECT_DOUBLE_EQ(o.maxPitchVariance, 0.004);
  EXPECT_DOUBLE_EQ(o.minPitchMean, 0.014);
}

TEST(Demo, FlythroughFollowsTheBotsLongestStretchAroundAWallAndTurnsGently) {
  // A wall in the plane x = 0 for z in [-100, 5]. The camera walks a U around its end: from
  // (-10, 0, -60) up to z = 10, across to x = 10, back down to z = -60 (160 units, keys every 10
  // units, 16 s), then jumps (a cut) to (200, 0, 200) and walks 5 units. A 64-unit moving average
  // pulls the U's apex to z = 2.4, behind the wall's end; the path must stay out of it.
  const fs::path dir = test::freshDir("demo_fly");
  const auto [dataset, stretchEnd] = test::writeUTurnDataset(dir);
  const double t = stretchEnd + 1.0;
  const auto report = camera::writeFlythroughCsv(dataset, dir / "fly.csv");
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_NEAR(report->stretchStart, 0.0, 1e-9);
  EXPECT_NEAR(report->stretchEnd, stretchEnd, 1.0 / 60);
  EXPECT_NEAR(report->stretchLength, 160.0, 0.5);
  EXPECT_LT(report->length, 160.0);          // 20 units/s would fly 340: the whole (smoothed, shorter) stretch
  EXPECT_GT(report->length, 140.0);
  EXPECT_LT(report->smoothing, 64.0);       // the widest average went through the wall
  const auto rows = readPoses(dir / "fly.csv");
  ASSERT_EQ(rows.size(), report->poses);
  const double duration = t + 1.0;
  ASSERT_EQ(rows.size(), static_cast<std::size_t>(std::ceil(duration * 60)) + 1);
  // No segment between consecutive poses reaches the wall: a segment crosses the plane x = 0
  // at z < 0 (and |y| < 50) only by changing the sign of x there. Checked here by plain geometry.
  double step = 0, longest = 0, shortest = 1e9;
  for (std::size_t n = 1; n < rows.size(); ++n) {
    const glm::dvec3 a(rows[n - 1][1], rows[n - 1][2], rows[n - 1][3]), c(rows[n][1], rows[n][2], rows[n][3]);
    if ((a.x < 0) != (c.x < 0) && a.x != c.x) {
      const double s = a.x / (a.x - c.x);
      EXPECT_GT(a.z + s * (c.z - a.z), 0.0) << "pose " << n << " goes through the wall";
    }
    step = glm::length(c - a);
    longest = std::max(longest, step);
    shortest = std::min(shortest, step);
    EXPECT_LE(std::abs(a.y), 1e-9);  // the path stays at the bot's height
  }
  // Constant speed along the (smoothed) path: every step the same, up to the polyline's corners.
  EXPECT_NEAR(longest, report->length / (rows.size() - 1), 0.01);
  EXPECT_GT(shortest, 0.5 * longest);
  // The path starts and ends where the bot's stretch does.
  EXPECT_NEAR(rows.front()[1], -10, 1e-6);
  EXPECT_NEAR(rows.front()[3], -60, 1e-6);
  EXPECT_NEAR(rows.back()[1], 10, 1e-6);
  EXPECT_NEAR(rows.back()[3], -60, 1e-6);
  // The heading: the camera turns round the U (about 180 degrees in all), at a mean rate at most
  // the option's, looking along the path (+Z at the start, -Z at the end), level (the path is flat).
  double turned = 0;
  for (std::size_t n = 1; n < rows.size(); ++n) {
    const glm::dquat a(rows[n - 1][7], rows[n - 1][4], rows[n - 1][5], rows[n - 1][6]), c(rows[n][7], rows[n][4], rows[n][5], rows[n][6]);
    turned += degrees(geodesicAngle(a, c));
  }
  // Per frame at 24 fps the yaw turns about turned / (24 duration) degrees on average; the bounds
  // hold unless even a window as long as the flight could not meet them.
  EXPECT_NEAR(report->yawMean, turned / (24.0 * duration), 0.1 * report->yawMean);
  const camera::FlythroughOptions bounds;
  if (report->headingWindow <= duration) {
    EXPECT_LE(report->yawMean, bounds.maxYawMean);
    EXPECT_LE(report->yawVariance, bounds.maxYawVariance);
  }
  // A flat path has no pitch of its own: the nod gives it ORCA's (at least the least row's 0.014°
  // a frame, about the target 0.03).
  const camera::FlythroughOptions defaults;
  EXPECT_GT(report->nodAmplitude, 0.0);
  EXPECT_GE(report->pitchMean, defaults.pitchTarget);
  EXPECT_LT(report->pitchMean, 1.2 * defaults.pitchTarget);
  EXPECT_LE(report->pitchVariance, defaults.maxPitchVariance);
  EXPECT_GT(turned, 170.0);
  EXPECT_LT(turned, 190.0);
  auto forward = [](const std::array<double, 8>& r) { return glm::dquat(r[7], r[4], r[5], r[6]) * glm::dvec3(0, 0, -1); };
  EXPECT_GT(forward(rows.front()).z, 0.9);  // up the first leg, towards +Z
  EXPECT_LT(forward(rows.back()).z, -0.9);  // down the second leg, towards -Z
  for (const auto& r : rows) EXPECT_LE(std::abs(forward(r).y), std::sin(radians(report->nodAmplitude)) + 1e-9);
  // Without the nod the flat path is flown level.
  camera::FlythroughOptions level;
  level.pitchTarget = 0;
  const auto flat = camera::writeFlythroughCsv(dataset, dir / "level.csv", level);
  ASSERT_TRUE(flat) << flat.error().message;
  EXPECT_EQ(flat->nodAmplitude, 0.0);
  EXPECT_LE(flat->pitchMean, 1e-9);
  for (const auto& r : readPoses(dir / "level.csv")) EXPECT_NEAR(forward(r).y, 0.0, 1e-9);
  // Of the two stretches the U is flown: the 5-unit one after the cut neither turns nor is long.
  EXPECT_EQ(report->stretchesCompared, 1 + (report->insideOrca() ? 0 : 1));
  // An empty dataset (no camera animation) is an error naming the file.
  test::GltfBuilder still;
  still.node({{"name", "eye"}, {"camera", still.perspectiveCamera()}});
  const auto none = camera::writeFlythroughCsv(still.write(dir, "still"), dir / "none.csv");
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message.find("still.gltf"), std::string::npos) << none.error().message;
  EXPECT_FALSE(fs::exists(dir / "none.csv"));
}

TEST(Demo, FlythroughCommandWritesTheDatasetAndChecksItAgainstOrca) {
  const fs::path dir = test::freshDir("demo_fly_cli");
  const auto [dataset, stretchEnd] = test::writeUTurnDataset(dir);
  const auto r = dynbench(fmt::format("flythrough {} -o {} --json {}", dataset.string(), (dir / "fly.gltf").string(), (dir / "fly.json").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  // The new dataset's camera follows the pose log written beside it, and its motion is measured
  // from the dataset: the checks' position mean is the flight's speed (units/s, 24 fps, 1/8 m).
  EXPECT_TRUE(fs::exists(dir / "fly.csv"));
  auto fly = scene::loadScene(dir / "fly.gltf");
  ASSERT_TRUE(fly) << fly.error().message;
  const auto doc = nlohmann::json::parse(test::slurp(dir / "fly.json"));
  ASSERT_EQ(doc["checks"].size(), 12u);
  EXPECT_EQ(doc["checks"][0]["measure"], "Table 6.4 position mean (m)");
  EXPECT_NEAR(doc["checks"][0]["value"].get<double>(), doc["speed"].get<double>() / 24.0 * 0.125, 2e-3);
  bool inside = true;
  for (const auto& c : doc["checks"]) {
    const bool in = c["value"].get<double>() >= c["low"].get<double>() - 5e-4 && c["value"].get<double>() <= c["high"].get<double>() + 5e-4;
    EXPECT_EQ(c["inside"].get<bool>(), in) << c.dump();
    inside = inside && in;
    // Each check is printed, marked when outside.
    EXPECT_NE(r.out.find(c["measure"].get<std::string>()), std::string::npos);
  }
  EXPECT_EQ(doc["inside_orca"].get<bool>(), inside);
  // --require-orca fails (status 5) exactly when a check is outside.
  const auto strict = dynbench(fmt::format("flythrough {} -o {} --require-orca", dataset.string(), (dir / "fly2.gltf").string()), dir);
  EXPECT_EQ(strict.status, inside ? 0 : 5) << strict.err;
  // Bad input: a missing dataset names the file (status 3); a negative speed is a usage error.
  const auto missing = dynbench(fmt::format("flythrough {} -o {}", (dir / "nope.gltf").string(), (dir / "x.gltf").string()), dir);
  EXPECT_EQ(missing.status, 3);
  EXPECT_NE(missing.err.find("nope.gltf"), std::string::npos) << missing.err;
  EXPECT_FALSE(fs::exists(dir / "x.gltf"));
  EXPECT_EQ(dynbench(fmt::format("flythrough {} -o {} --speed -1", dataset.string(), (dir / "y.gltf").string()), dir).status, 2);
}

TEST(Demo, WholeChainOnAShortMatch) {
  DYNBENCH_NEEDS(test::missingCube2());
  DYNBENCH_NEEDS(test::missingFfmpeg());
  const fs::path dir = test::freshDir("demo_chain");
  // Shared with Slurm.DemoAsAChainOfJobsGivesTheLocalDemosTables (shared_run.h), copied here to
  // resume in.
  const auto shared = test::sharedRun("demo", "demo -o {out} --seconds 3 --bots 4 --res 32x18 --spp 1 --max-spp 32 --render-frames 12 --bounces 1");
  const auto& r = shared.run;
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  test::copyOf(shared, dir / "demo");
  EXPECT_NE(r.out.find("report: "), std::string::npos) << r.out;
  const std::string md = test::slurp(dir / "demo" / "report.md");
  EXPECT_NE(md.find("| colos_bot "), std::string::npos);
  EXPECT_NE(md.find("| colos_flythrough "), std::string::npos);
  // Table 6.6: the fly-through's yaw and pitch within the ORCA bounds (the largest of the thesis's
  // three rows) where the demo's log says it made them so, and above one where it says not. A short
  // match may leave no stretch long enough to smooth within them: the log then says which measure
  // is outside (seen on the seed's match after Cube 2's rebuild of 2026-11-27: pitch 0.087 against
  // ORCA's 0.053, on a 1.5 s stretch).
  const auto table = md.find("Table 6.6.");
  const auto row = md.find("| colos_flythrough ", table);
  ASSERT_NE(row, std::string::npos);
  double pitchMean = 0, pitchVariance = 0, yawMean = 0, yawVariance = 0;
  ASSERT_EQ(std::sscanf(md.c_str() + md.find('|', row + 2), "| %lf | %lf | %lf | %lf", &pitchMean, &pitchVariance, &yawMean, &yawVariance), 4)
      << md.substr(row, 80);
  const camera::FlythroughOptions orca;
  const bool inside = r.out.find("inside every ORCA range") != std::string::npos;
  if (inside) {
    EXPECT_LE(yawMean, orca.maxYawMean + 1e-3);
    EXPECT_LE(yawVariance, orca.maxYawVariance + 1e-3);
    EXPECT_LE(pitchMean, orca.maxPitchMean + 1e-3);
    EXPECT_LE(pitchVariance, orca.maxPitchVariance + 1e-3);
  } else {
    const bool outsideInTable66 = r.out.find("outside ORCA's range in Table 6.6") != std::string::npos;
    EXPECT_TRUE(outsideInTable66) << r.out;
    if (outsideInTable66) EXPECT_TRUE(yawMean > orca.maxYawMean || yawVariance > orca.maxYawVariance || pitchMean > orca.maxPitchMean ||
                                      pitchVariance > orca.maxPitchVariance);
  }
  // No segment between consecutive camera positions of the fly-through, at the render's 24 fps
  // and at the capture's 60 fps, passes through the map's static geometry (rays against it).
  {
    auto fly = scene::loadScene(dir / "demo" / "datasets" / "colos_flythrough.gltf");
    ASSERT_TRUE(fly) << fly.error().message;
    const auto cameraNode = scene::selectCameraNode(*fly, std::nullopt);
    ASSERT_TRUE(cameraNode && *cameraNode >= 0);
    const scene::Evaluator evaluator(*fly);
    const auto range = fly->timeRange();
    for (const double fps : {24.0, 60.0}) {
      std::vector<glm::dvec3> positions;
      for (double t = range.start; t <= range.end + 1e-9; t += 1.0 / fps) positions.emplace_back(evaluator.worldMatrix(*cameraNode, t)[3]);
      ASSERT_GT(positions.size(), 2u);
      const auto crossing = render::segmentsThroughStaticGeometry(*fly, positions);
      ASSERT_TRUE(crossing) << crossing.error().message;
      EXPECT_TRUE(crossing->empty()) << crossing->size() << " segments at " << fps << " fps cross static geometry";
    }
  }
  EXPECT_TRUE(fs::exists(dir / "demo" / "report.html"));
  // The report shows each dataset's converged window as a video beside its discard masks, and says
  // how it was sampled.
  EXPECT_NE(r.out.find("self-contained ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" images, 2 videos inline)"), std::string::npos) << r.out;
  for (const char* run : {"colos_bot", "colos_flythrough"})
    EXPECT_NE(md.find(fmt::format("Video and thumbnails: {}/frames, converged (render --converge, tolerance 0.5): ", run)),
              std::string::npos)
        << md;
  EXPECT_TRUE(fs::exists(dir / "demo" / "runs" / "colos_bot" / "discard.json"));
  // The demo renders a converged window and Table 6.7 prints the radiance columns' intervals.
  EXPECT_NE(md.find(" ± "), std::string::npos) << md;
  const auto discardJson = nlohmann::json::parse(test::slurp(dir / "demo" / "runs" / "colos_bot" / "discard.json"));
  EXPECT_EQ(discardJson["frames"].size(), 11u);
  EXPECT_EQ(discardJson["mean"]["interval"]["direct_radiance"].size(), 2u);
  // Temporal methods on both datasets, each on the input it is built for, as the suites score them
  // (TAA jittered; accumulate and SVGF still; `none` on both): every method scored on every frame
  // of the window, the first frame a reset, and the Markdown's table with a row per dataset, method
  // and input, beside the reference's noise floor.
  const std::map<std::string, std::vector<std::string>> byInput = {{"jittered", {"none", "taa"}}, {"still", {"none", "accumulate", "svgf"}}};
  for (const char* run : {"colos_bot", "colos_flythrough"}) {
    for (const auto& [input, methods] : byInput) {
      const auto evaluation =
          nlohmann::json::parse(test::slurp(dir / "demo" / "runs" / run / (input == "still" ? "evaluate-still.json" : "evaluate.json")));
      ASSERT_EQ(evaluation["methods"].size(), methods.size()) << run << " " << input;
      for (std::size_t k = 0; k < methods.size(); ++k) {
        const auto& method = evaluation["methods"][k];
        EXPECT_EQ(method["name"], methods[k]) << run << " " << input;
        EXPECT_EQ(method["frames"].size(), 12u) << run;
        EXPECT_EQ(method["frames"][0]["history_use"].get<double>(), 0.0) << run;
        EXPECT_GT(method["mean"]["flip"]["mean"].get<double>(), 0.0) << run;
        // A line of the Markdown with the dataset, the method and its input in its first three
        // columns (cells padded to the column's width).
        bool found = false;
        for (std::size_t at = md.find(fmt::format("| {} ", run)); at != std::string::npos && !found; at = md.find(fmt::format("| {} ", run), at + 1)) {
          std::vector<std::string> cells;
          for (std::size_t from = at; cells.size() < 3;) {
            const std::size_t next = md.find('|', from + 1);
            std::string cell = md.substr(from + 1, next - from - 1);
            cell.erase(0, cell.find_first_not_of(' '));
            cell.erase(cell.find_last_not_of(' ') + 1);
            cells.push_back(cell);
            from = next;
          }
          found = cells[1] == methods[k] && cells[2] == input;
        }
        EXPECT_TRUE(found) << run << " " << methods[k] << " " << input;
      }
    }
    // The noise floor: four frames of the window rendered with another seed, written beside the
    // scores, and a row of the table.
    const auto floor = nlohmann::json::parse(test::slurp(dir / "demo" / "runs" / run / "floor.json"));
    EXPECT_EQ(floor["frames"], 4);
    EXPECT_GT(floor["flip"]["mean"].get<double>(), 0.0);
  }
  {
    std::size_t rows = 0;
    for (std::size_t at = md.find("| reference noise floor "); at != std::string::npos; at = md.find("| reference noise floor ", at + 1)) ++rows;
    EXPECT_EQ(rows, 2u) << md;
  }

  // Convergence (the acceptance, at a size the suite affords): the seeded segment (colos,
  // 4 bots, 3 s, seed 1), frames 40-43, rendered to convergence with two seeds gives direct and
  // indirect discard means within their combined 95 % interval (at least 0.5 points) of each
  // other, each inside the other's interval. (Half the tolerance was tried too until the pairs
  // test decided the radiance columns: at 0.25, 4,386 of 4,608 pixels stopped at --max-spp 4096,
  // so it repeated this check at the cap for 56 s of the suite's 12 minutes. Frames 40-47 until
  // 2026-11-29: 160 s of CPU of the test's 210 on a 2-core AMD EPYC; four frames, three pairs,
  // check the same agreement at half the cost.)
  const fs::path dataset = dir / "demo" / "datasets" / "colos_bot.gltf";
  for (const double tolerance : {0.5}) {
    nlohmann::json discarded[2];
    for (int seed = 1; seed <= 2; ++seed) {
      const fs::path frames = dir / fmt::format("converged_{}_{}", tolerance, seed);
      const auto rendered = dynbench(fmt::format("render {} -o {} --res 32x18 --frames 40:43 --bounces 2 --converge --tolerance {} "
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
      // Two independent estimates: their difference lies within the 95 % half widths combined in
      // quadrature (the fixed 0.5 points this used to be predates the pixel filter, whose edges
      // widen the indirect column's interval here to about 1.2 points).
      const double halfA = 0.5 * (ia[1].get<double>() - ia[0].get<double>()), halfB = 0.5 * (ib[1].get<double>() - ib[0].get<double>());
      EXPECT_NEAR(a, b, std::max(0.5, std::hypot(halfA, halfB))) << column << " at tolerance " << tolerance;
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
      // The image channels' storage: compared with the image-against-image test (these frames have no pairs).
      const auto d = dynbench(fmt::format("discard {} --relative-position --radiance-test expected --json {}", frames.string(),
                                          (frames / "d.json").string()),
                              dir);
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
  // The datasets part is enough to see it capture and convert again (the renders would follow the
  // new dataset as the frames' dataset digest says, RenderCli.AChangedDatasetIsRenderedAgain).
  again = dynbench(args + " --seed 2 --part datasets", dir);
  ASSERT_EQ(again.status, 0) << again.err << again.out;
  EXPECT_NE(again.out.find("was made with other options, capturing again"), std::string::npos) << again.out;
  EXPECT_NE(test::slurp(dir / "demo" / "capture" / "Capture.txt"), capture);
  EXPECT_NE(test::slurp(dir / "demo" / "capture" / "dynbench-demo-capture.json").find("\"seed\": 2"), std::string::npos);
  EXPECT_NE(again.out.find("convert: capture ->"), std::string::npos) << again.out;  // the dataset follows the new capture
}

}  // namespace
}  // namespace dynbench
