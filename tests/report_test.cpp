// `dynbench report` end to end: two runs made by the real chain (stats, render, discard), the
// Markdown twin's tables, and the HTML opened in headless Chromium (Debian `chromium`), which
// must find every table row and decode every inline image.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include "core/files.h"
#include "core/image_io.h"
#include "gltf_builder.h"
#include "external_tools.h"
#include "run_cli.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;

const fs::path kOrbit = fs::path(DYNBENCH_SOURCE_DIR) / "examples" / "orbit" / "orbit.gltf";

void makeRun(const fs::path& run, const std::string& frames) {
  for (const auto& args : {fmt::format("stats {} --json {} --series {}", kOrbit.string(), (run / "stats.json").string(), run.string()),
                           fmt::format("render {} -o {} --frames {} --res 32x18 --spp 2", kOrbit.string(), (run / "frames").string(), frames),
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
  const auto dir = test::freshDir("report");
  makeRun(dir / "slow", "0:4");
  makeRun(dir / "fast", "20:24");
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
  const std::string html = test::slurp(dir / "out" / "report.html");
  EXPECT_EQ(html.find("http://"), std::string::npos);  // self-contained: nothing to fetch
  EXPECT_EQ(html.find("src=\"report_files"), std::string::npos);

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
}

TEST(Report, ThesisReferenceRowsAreMarkedPublishedAndConverted) {
  const auto dir = test::freshDir("report_reference");
  makeRun(dir / "run", "0:4");
  auto r = dynbench(fmt::format("report {} -o {} --thumbnails 0 --reference thesis", (dir / "run").string(), (dir / "r.html").string()), dir);
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
