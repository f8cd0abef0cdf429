// `dynbench report` end to end: two runs made by the real chain (stats, render, discard), the
// Markdown twin's tables, and the HTML opened in headless Chromium (Debian `chromium`), which
// must find every table row and decode every inline image.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "core/files.h"
#include "core/image_io.h"
#include "report/tables.h"
#include "gltf_builder.h"
#include "external_tools.h"
#include "run_cli.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;


void makeRun(const fs::path& run, const std::string& frames, const std::string& sampling = "--spp 2 --pairs --max-pairs 16") {
  for (const auto& args : {fmt::format("stats {} --json {} --series {}", kOrbit.string(), (run / "stats.json").string(), run.string()),
                           fmt::format("render {} -o {} --frames {} --res 32x18 {}", kOrbit.string(), (run / "frames").string(), frames, sampling),
                           fmt::format("discard {} --json {} --masks {}", (run / "frames").string(), (run / "discard.json").string(),
                                       (run / "masks").string())}) {
    const auto r = dynbench(args, run.parent_path());
    ASSERT_EQ(r.status, 0) << args << ": " << r.err;
  }
}


std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(Report, TablesAndImagesInTheBrowser) {
  DYNBENCH_NEEDS(test::missingFfmpeg());
  const auto dir = test::freshDir("report");
  makeRun(dir / "slow", "0:4");
  makeRun(dir / "fast", "20:24", "--converge --spp 4 --max-spp 16");
  // The slow run also scores two temporal methods on a 1-spp render of its frames.
  const fs::path slow = dir / "slow";
  for (const auto& args :
       {fmt::format("render {} -o {} --frames 0:4 --res 32x18 --spp 1 --seed 2", kOrbit.string(), (slow / "input").string()),
        fmt::format("evaluate {} --reference {} --methods none,accumulate --json {} --out {}", (slow / "input").string(), (slow / "frames").string(),
                    (slow / "evaluate.json").string(), (slow / "evaluate").string())}) {
    const auto e = dynbench(args, dir);
    ASSERT_EQ(e.status, 0) << args << ": " << e.err;
  }
  const auto r = dynbench(fmt::format("report {} {} -o {} --title 'Two runs'", (dir / "slow").string(), (dir / "fast").string(),
                                      (dir / "out" / "report.html").string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // The command reports the page's size and what it holds.
  const std::string html = test::slurp(dir / "out" / "report.html");
  EXPECT_NE(r.out.find(fmt::format("report.html: {:.2f} MB, self-contained (25 images, 2 videos inline)", html.size() / 1e6)), std::string::npos)
      << r.out;
  const std::string md = test::slurp(dir / "out" / "report.md");
  for (int t = 1; t <= 7; ++t) EXPECT_NE(md.find(fmt::format("Table 6.{}.", t)), std::string::npos) << t;
  EXPECT_EQ(count(md, "| slow "), 9u);  // one row per table, and one per temporal method
  EXPECT_EQ(count(md, "| fast "), 7u);
  EXPECT_NE(md.find("Temporal methods against the converged reference"), std::string::npos);
  EXPECT_NE(md.find(" | accumulate |"), std::string::npos);
  // Every run on shared axes: rotation per frame, its distribution, discard per frame, Table 6.7's
  // bars; per run: A.1, A.2, the discard series, 3 thumbnails, 3 masks; the slow run's two
  // worst-frame heatmaps; the methods' per-frame plot.
  EXPECT_EQ(count(md, "!["), 25u);
  for (const char* png : {"all_rotation.png", "all_cdf_rotation_cdf.png", "all_discard.png", "all_table67.png"}) {
    auto header = readImageHeader(dir / "out" / "report_files" / png);
    ASSERT_TRUE(header) << png << ": " << header.error().message;
    EXPECT_EQ(header->width, 1200) << png;
  }
  // The shared plots name every run in their legend.
  const std::string bars = test::slurp(dir / "out" / "report_files" / "all_table67.svg");
  EXPECT_NE(bars.find(">slow<"), std::string::npos);
  EXPECT_NE(bars.find(">fast<"), std::string::npos);
  EXPECT_EQ(html.find("http://"), std::string::npos);  // self-contained: nothing to fetch
  EXPECT_EQ(html.find("src=\"report_files"), std::string::npos);
  // A video per run (linked from the Markdown, inline in the page), and what the frames show: the
  // slow run's fixed 2 spp, the fast run's converged render.
  EXPECT_EQ(count(md, "_motion.webm)"), 2u);
  EXPECT_EQ(count(html, "<video src=\"data:video/webm;base64,"), 2u);
  EXPECT_NE(md.find("Video and thumbnails: slow/frames, 2 spp;"), std::string::npos) << md;
  {
    const std::string prefix = "Video and thumbnails: fast/frames, converged (render --converge, tolerance 0.25): ";
    const auto at = md.find(prefix);
    ASSERT_NE(at, std::string::npos) << md;
    int low = 0, high = 0;  // "4-16 spp per pixel", or "16 spp per pixel" when every pixel took the same
    const int read = std::sscanf(md.c_str() + at + prefix.size(), "%d-%d spp per pixel", &low, &high);
    ASSERT_GE(read, 1) << md.substr(at, 200);
    EXPECT_GE(low, 4);
    EXPECT_LE(read == 2 ? high : low, 16);
  }
  EXPECT_NE(md.find("Frames 0-4 at 24 fps (5 frames)"), std::string::npos) << md;
  EXPECT_NE(md.find("Frames 20-24 at 24 fps (5 frames)"), std::string::npos) << md;

  DYNBENCH_NEEDS(test::missingChromium());
  std::string dom;
  ASSERT_EQ(runShell(fmt::format("timeout 120 chromium --headless --no-sandbox --disable-gpu --virtual-time-budget=5000 --dump-dom "
                                 "file://{} 2>/dev/null",
                                 fs::absolute(dir / "out" / "report.html").string()),
                     dom),
            0);
  EXPECT_NE(dom.find("data-images-decoded=\"25\""), std::string::npos) << dom.substr(0, 400);
  EXPECT_NE(dom.find("data-images=\"25\""), std::string::npos);
  EXPECT_EQ(count(dom, "<table>"), 8u);
  EXPECT_EQ(count(dom, "<th scope=\"row\">slow</th>"), 9u);
  EXPECT_EQ(count(dom, "<th scope=\"row\">fast</th>"), 7u);

  // Every image decodes, and every video plays to its end in Chromium with the frames and the size
  // it was made with: 5 frames of 32x18, the discard mask beside each.
  std::string media;
  ASSERT_EQ(runShell(fmt::format("{0}/tests/tools/chromium_eval.py file://{1} --script {0}/tests/tools/decode_media.js", DYNBENCH_SOURCE_DIR,
                                 fs::absolute(dir / "out" / "report.html").string()),
                     media),
            0);
  const auto decoded = nlohmann::json::parse(media, nullptr, false);
  ASSERT_TRUE(decoded.is_object()) << media;
  EXPECT_EQ(decoded["images"], 25) << media;
  EXPECT_EQ(decoded["imagesDecoded"], 25) << media;
  ASSERT_EQ(decoded["videos"].size(), 2u) << media;
  for (const auto& v : decoded["videos"]) {
    EXPECT_EQ(v["frames"], 5) << media;
    EXPECT_EQ(v["declaredFrames"], 5) << media;
    EXPECT_EQ(v["width"], 64) << media;
    EXPECT_EQ(v["height"], 18) << media;
  }
}

TEST(Report, VideosAreOptionalAndNeedFfmpeg) {
  DYNBENCH_NEEDS(test::missingFfmpeg());
  const auto dir = test::freshDir("report_video");
  makeRun(dir / "run", "0:2");
  // --video-frames 0: no video.
  auto r = dynbench(fmt::format("report {} -o {} --video-frames 0", (dir / "run").string(), (dir / "none.html").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(test::slurp(dir / "none.html").find("<video"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "none_files" / "run1_motion.webm"));
  // 4 shared plots, A.1, A.2, the discard series, 3 thumbnails and the run's 2 masks.
  EXPECT_NE(r.out.find("(12 images, 0 videos inline)"), std::string::npos) << r.out;
  // --video-frames 2: the first two frames, and the caption says they are part of three.
  r = dynbench(fmt::format("report {} -o {} --video-frames 2", (dir / "run").string(), (dir / "two.html").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(test::slurp(dir / "two.md").find("Frames 0-1 at 24 fps (2 frames): direct + indirect radiance, tone-mapped; beside it, the discard mask"),
            std::string::npos);
  EXPECT_NE(test::slurp(dir / "two.md").find("the first 2 of the run's 3 frames"), std::string::npos);
  // A mask that is not its frame's size: status 5, naming the file, and no page.
  fs::copy(dir / "run", dir / "odd", fs::copy_options::recursive);
  ASSERT_TRUE(writeImage(dir / "odd" / "masks" / "discard_00001.png", FloatImage{10, 10, 3, std::vector<float>(300, 0.5f), {}, {}, {}}));
  r = dynbench(fmt::format("report {} -o {}", (dir / "odd").string(), (dir / "odd.html").string()), dir);
  EXPECT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find("odd/masks/discard_00001.png: 10x10 with 3 channels, but its frame is 32x18 RGB"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "odd.html"));
  // Without ffmpeg on PATH (gnuplot still there): a clear error naming the package, status 7, and no
  // page and no temporary files left.
  const fs::path bin = dir / "bin";
  fs::create_directories(bin);
  fs::create_symlink(findOnPath("gnuplot"), bin / "gnuplot");
  std::string out;
  const int status = runShell(fmt::format("PATH={} {} report {} -o {} 2>{}", bin.string(), DYNBENCH_EXE, (dir / "run").string(),
                                          (dir / "out" / "r.html").string(), (dir / "err.txt").string()),
                              out);
  EXPECT_EQ(status, 7);
  const std::string err = test::slurp(dir / "err.txt");
  EXPECT_NE(err.find("ffmpeg"), std::string::npos) << err;
  EXPECT_NE(err.find("install Debian's ffmpeg"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir / "out" / "r.html"));
  for (const auto& e : fs::directory_iterator(dir / "out" / "r_files"))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
}

TEST(Report, ThesisReferenceRowsAreMarkedPublishedAndConverted) {
  const auto dir = test::freshDir("report_reference");
  makeRun(dir / "run", "0:4");
  auto r = dynbench(fmt::format("report {} -o {} --thumbnails 0 --video-frames 0 --reference thesis", (dir / "run").string(), (dir / "r.html").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string md = test::slurp(dir / "r.md");
  // Six published rows in each of Tables 6.1-6.7, beside the measured one.
  EXPECT_EQ(count(md, "| Eternal Valley FPS (published) "), 7u);
  EXPECT_EQ(count(md, "| Emerald Square (published) "), 7u);
  EXPECT_EQ(count(md, "| run "), 7u);
  EXPECT_NE(md.find("not measured"), std::string::npos);
  // Table 6.5 in dynbench's full angle: 2 x 1.931, 4 x 4.526, 2 x 13.665.
  const auto t65 = md.find("Table 6.5."), t66 = md.find("Table 6.6.");
  const auto row = md.find("| Eternal Valley FPS (published) ", t65);
  ASSERT_LT(row, t66);
  const std::string line = md.substr(row, md.find('\n', row) - row);
  for (const char* cell : {"3.862", "18.104", "27.330"}) EXPECT_NE(line.find(cell), std::string::npos) << line;
  // Table 6.7 as published.
  const auto t67 = md.find("Table 6.7.");
  const auto discardRow = md.find("| Eternal Valley FPS (published) ", t67);
  ASSERT_NE(discardRow, std::string::npos);
  EXPECT_NE(md.substr(discardRow, 120).find("29.085"), std::string::npos);
  const std::string html = test::slurp(dir / "r.html");
  EXPECT_NE(html.find("<p class=\"reference\">"), std::string::npos);
  // Table 6.7's bars show the published rows beside the measured one.
  const std::string bars = test::slurp(dir / "r_files" / "all_table67.svg");
  EXPECT_NE(bars.find("Eternal Valley FPS (published)"), std::string::npos);
  EXPECT_NE(bars.find(">run<"), std::string::npos);
  r = dynbench(fmt::format("report {} -o {} --reference orca", (dir / "run").string(), (dir / "bad.html").string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--reference: orca not in {thesis}"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "bad.html"));
}

TEST(Report, BadRunsFailClearly) {
  const auto dir = test::freshDir("report_bad");
  fs::create_directories(dir / "empty");
  auto r = dynbench(fmt::format("report {} -o {}", (dir / "empty").string(), (dir / "r.html").string()), dir);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("empty/stats.json: missing"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "r.html"));
  // A real run, then one malformed value at a time: the error names the file and the JSON
  // pointer, the status is 5, and no report is written (it used to print "-" and exit 0).
  makeRun(dir / "good", "0:1");
  const std::string stats = test::slurp(dir / "good" / "stats.json"), discard = test::slurp(dir / "good" / "discard.json");
  struct Case {
    std::string file, from, to, message;
  };
  for (const Case& c : {Case{"stats.json", "\"faces\": ", "\"faces\": \"many\", \"was\": ",
                             "stats.json: /datasets/0/properties/faces: expected a whole number >= 0, found \"many\""},
                        Case{"stats.json", "\"animated_camera\": ", "\"animated_camera\": 3, \"was\": ",
                             "stats.json: /datasets/0/properties/animated_camera: expected true or false, found 3"},
                        Case{"stats.json", "\"variance\": ", "\"variance\": null, \"was\": ",
                             "stats.json: /datasets/0/camera_motion/pitch_degrees/variance: expected a number, found null"},
                        Case{"discard.json", "\"frustum\": ", "\"frustum\": \"x\", \"was\": ",
                             "discard.json: /frames/0/frustum: expected a number, found \"x\""},
                        Case{"discard.json", "\"mean\"", "\"average\"", "discard.json: /mean/frustum: missing"}}) {
    fs::remove_all(dir / "bad");
    fs::create_directories(dir / "bad");
    std::string text = c.file == "stats.json" ? stats : discard;
    const auto at = text.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    text.replace(at, c.from.size(), c.to);
    ASSERT_TRUE(writeFileAtomic(dir / "bad" / "stats.json", c.file == "stats.json" ? text : stats));
    ASSERT_TRUE(writeFileAtomic(dir / "bad" / "discard.json", c.file == "discard.json" ? text : discard));
    r = dynbench(fmt::format("report {} -o {}", (dir / "bad").string(), (dir / "r.html").string()), dir);
    EXPECT_EQ(r.status, 5) << c.message << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "r.html"));
  }
  r = dynbench(fmt::format("report {} -o {}", (dir / "empty").string(), (dir / "r.txt").string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
}

}  // namespace
}  // namespace dynbench

namespace dynbench::report {
namespace {

// The temporal methods' table as the demo and the suites read it: each method with its input and
// its ratio to `none` on that input; ≈ where the difference with `none` is within the reference's
// noise floor (strictly less), and a row for the floor; losesToNone only beyond the floor.
TEST(Report, MethodsTableMarksWhatTheNoiseFloorCannotRank) {
  auto scores = [](const std::string& name, double flip) {
    evaluate::MethodScores s;
    s.name = name;
    s.flip = {flip, 0.001, 12};
    return s;
  };
  const evaluate::MeanWithError floor{0.02, 0.002, 4};
  const std::vector<MethodsRow> rows = {{"bot", "jittered", scores("none", 0.10), 0.10, floor},
                                        {"bot", "jittered", scores("taa", 0.09), 0.10, floor},      // 0.01 better: within
                                        {"bot", "still", scores("accumulate", 0.05), 0.08, floor},  // 0.03 better: ranked
                                        {"bot", "still", scores("svgf", 0.11), 0.08, floor},        // 0.03 worse: loses
                                        {"fly", "still", scores("svgf", 0.099), 0.08, floor}};      // 0.019 worse: within
  const Table t = temporalMethodsTable(rows);
  ASSERT_EQ(t.rows.size(), 7u);  // a floor row before each dataset's methods
  EXPECT_EQ(t.rows[0][1], "reference noise floor");
  EXPECT_EQ(t.rows[0][3], "0.0200 ± 0.0020");
  EXPECT_EQ(t.rows[1][3], "0.1000 ± 0.0010");  // none: never marked
  EXPECT_EQ(t.rows[2][3], "≈ 0.0900 ± 0.0010");
  EXPECT_EQ(t.rows[2][4], "0.900");
  EXPECT_EQ(t.rows[3][2], "still");
  EXPECT_EQ(t.rows[3][3], "0.0500 ± 0.0010");
  EXPECT_EQ(t.rows[3][4], "0.625");
  EXPECT_EQ(t.rows[5][1], "reference noise floor");
  EXPECT_EQ(t.rows[6][3], "≈ 0.0990 ± 0.0010");
  EXPECT_FALSE(rows[0].losesToNone());
  EXPECT_FALSE(rows[1].losesToNone());
  EXPECT_FALSE(rows[2].losesToNone());
  EXPECT_TRUE(rows[3].losesToNone());
  EXPECT_FALSE(rows[4].losesToNone());
  // Without a floor nothing is marked, and any loss counts.
  MethodsRow bare = rows[4];
  bare.floor.reset();
  EXPECT_TRUE(bare.losesToNone());
  EXPECT_EQ(temporalMethodsTable({bare}).rows.front()[3], "0.0990 ± 0.0010");
}

}  // namespace
}  // namespace dynbench::report
