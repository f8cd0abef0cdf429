// Job files (docs/cli.md, "Job files"): a render job, a Cube 2 capture's options and the demo's
// options as one JSON document each, which `--job FILE` reads and Slurm tasks run. Each writer and
// reader round-trips every field, bad documents are named by JSON pointer, and `render --job`
// writes the same bytes as the same job given as options.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "capture/cube2_job.h"
#include "core/files.h"
#include "gltf_builder.h"
#include "pipeline/dataset_run.h"
#include "suite/demo.h"
#include "render/render_job_json.h"
#include "run_cli.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;


// Every key of `changed` but `version` holds another value than in `defaults`: a round trip of
// `changed` then covers every field (a field the reader forgot would come back as its default).
void expectEveryFieldChanged(const nlohmann::json& changed, const nlohmann::json& defaults, const std::string& version) {
  for (const auto& [key, value] : changed.items()) {
    if (key == version) continue;
    EXPECT_NE(value, defaults.value(key, nlohmann::json())) << key << " is its default: the round trip would not test it";
  }
}

render::RenderJob everyRenderField() {
  render::RenderJob job;
  job.dataset = "/data/match.gltf";
  job.output = "frames out";
  job.engine = "cycles";
  job.fps = 30.0;
  job.frames = {12, 40, 2};
  job.camera = "Camera.001";
  job.animation = "1";
  job.threads = 3;
  job.float32 = true;
  job.blender = "/opt/blender/blender";
  auto& s = job.settings;
  s.width = 320;
  s.height = 180;
  s.samplesPerPixel = 7;
  s.bounces = 9;
  s.seed = 12345678901234ULL;
  s.constantEnvironment = glm::dvec3(0.25, 0.5, 1.0);
  s.jitter = true;
  s.pixelFilter = {render::PixelFilterType::kBox, 1.25};
  s.converge = true;
  s.tolerance = 0.125;
  s.maxSamplesPerPixel = 333;
  s.pairs = true;
  s.maxPairs = 96;
  s.lightsPerPoint = 0;
  s.everyLightUpTo = 5;
  s.learnedLightSelection = false;
  s.directThresholdFraction = 0.2;
  s.indirectThresholdFraction = 0.3;
  return job;
}

TEST(JobFiles, RenderJobRoundTripsEveryField) {
  const auto job = everyRenderField();
  const auto document = render::renderJobJson(job);
  expectEveryFieldChanged(document, render::renderJobJson(render::RenderJob{}), "dynbench_render_job");
  auto parsed = render::parseRenderJob(document, "job.json");
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_EQ(render::renderJobJson(*parsed), document);
  EXPECT_EQ(parsed->settings.seed, 12345678901234ULL);
  EXPECT_EQ(parsed->frames.step, 2);
  // The environment's other spellings.
  for (const char* environment : {"dataset", "none"}) {
    auto d = document;
    d["environment"] = environment;
    auto p = render::parseRenderJob(d, "job.json");
    ASSERT_TRUE(p) << p.error().message;
    EXPECT_FALSE(p->settings.constantEnvironment);
    EXPECT_EQ(p->settings.useEnvironment, std::string(environment) == "dataset");
  }
  // Keys left out take the defaults, pairs following converge on the embree engine as on the command line.
  auto minimal = render::parseRenderJob({{"dynbench_render_job", 1}, {"dataset", "a.gltf"}, {"output", "o"}, {"converge", true}}, "job.json");
  ASSERT_TRUE(minimal) << minimal.error().message;
  EXPECT_TRUE(minimal->settings.pairs);
  EXPECT_EQ(minimal->settings.width, render::RenderSettings{}.width);
  EXPECT_EQ(minimal->settings.pixelFilter.width, render::RenderSettings{}.pixelFilter.width);
}

TEST(JobFiles, BadRenderJobsAreNamedByPointer) {
  const nlohmann::json good = {{"dynbench_render_job", 1}, {"dataset", "a.gltf"}, {"output", "o"}};
  struct Case {
    const char* pointer;
    nlohmann::json value;  // null: the key removed
    const char* message;
  };
  for (const auto& c : {Case{"/spp", 4, "job.json: /spp: expected one of the render job's keys"},
                        Case{"/samples_per_pixel", 0, "job.json: /samples_per_pixel: expected a whole number in [1, "},
                        Case{"/samples_per_pixel", "4", "job.json: /samples_per_pixel: expected a whole number, found \"4\""},
                        Case{"/engine", "mitsuba", "job.json: /engine: expected one of embree, cycles, found \"mitsuba\""},
                        Case{"/environment", "sky", "job.json: /environment: expected \"dataset\", \"none\" or a radiance [R, G, B] >= 0"},
                        Case{"/environment", {1, -1, 1}, "job.json: /environment: expected"},
                        Case{"/frames", {{"first", 5}, {"last", 3}}, "job.json: /frames/last: expected -1 (to the end) or at least /frames/first (5), found 3"},
                        Case{"/pixel_filter", {{"type", "gauss"}}, "job.json: /pixel_filter/type: expected a pixel filter"},
                        Case{"/tolerance", 0.0, "job.json: /tolerance: expected a number in [0.0001, 10], found 0"},
                        Case{"/seed", -1, "job.json: /seed: expected a whole number >= 0, found -1"},
                        Case{"/dynbench_render_job", 2, "job.json: /dynbench_render_job: expected a whole number in [1, 1], found 2"},
                        Case{"/dataset", nullptr, "job.json: /dataset: expected a path, missing"},
                        Case{"/output", "", "job.json: /output: expected a path, found \"\""}}) {
    auto d = good;
    const nlohmann::json::json_pointer p(c.pointer);
    if (c.value.is_null()) d.erase(std::string(c.pointer).substr(1));
    else d[p] = c.value;
    auto parsed = render::parseRenderJob(d, "job.json");
    ASSERT_FALSE(parsed) << c.pointer;
    EXPECT_EQ(parsed.error().code, ErrorCode::kInvalidData);
    EXPECT_NE(parsed.error().message.find(c.message), std::string::npos) << parsed.error().message;
  }
  EXPECT_FALSE(render::parseRenderJob(nlohmann::json::array(), "job.json"));
}

TEST(JobFiles, RenderJobFileRendersWhatTheOptionsRender) {
  const auto dir = test::freshDir("job_file_render");
  auto r = dynbench(fmt::format("render {} -o {} --res 24x14 --spp 2 --frames 1:3 --seed 7 --pixel-filter box --jitter", kOrbit.string(),
                                (dir / "options").string()),
                    dir);
  ASSERT_EQ(r.status, 0) << r.err;
  render::RenderJob job;
  job.dataset = kOrbit;
  job.output = dir / "file";
  job.settings.width = 24;
  job.settings.height = 14;
  job.settings.samplesPerPixel = 2;
  job.settings.seed = 7;
  job.settings.pixelFilter = {render::PixelFilterType::kBox, 1.0};
  job.settings.jitter = true;
  job.frames = {0, -1, 1};  // the command line's --frames wins
  ASSERT_TRUE(render::writeRenderJob(job, dir / "job.json"));
  r = dynbench(fmt::format("render --job {} --frames 1:3 --threads 1", (dir / "job.json").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("3 frame(s) rendered"), std::string::npos) << r.out;
  for (int f = 1; f <= 3; ++f)
    for (const char* ext : {"exr", "json"}) {
      const auto name = fmt::format("frame_{:05d}.{}", f, ext);
      EXPECT_EQ(test::slurp(dir / "file" / name), test::slurp(dir / "options" / name)) << name;
    }
  EXPECT_FALSE(fs::exists(dir / "file" / "frame_00000.exr"));

  // The file holds the job: its options beside it are an error, as is a bad file.
  r = dynbench(fmt::format("render --job {} --spp 4 --res 8x8", (dir / "job.json").string()), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("cannot be given with it"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--spp"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--res"), std::string::npos) << r.err;
  ASSERT_TRUE(writeFileAtomic(dir / "bad.json", R"({"dynbench_render_job": 1, "dataset": "a.gltf", "output": "o", "width": "wide"})"));
  r = dynbench(fmt::format("render --job {}", (dir / "bad.json").string()), dir);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("bad.json: /width: expected a whole number, found \"wide\""), std::string::npos) << r.err;
  r = dynbench("render -o x", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("DATASET and -o DIR are required (or --job FILE)"), std::string::npos) << r.err;
}

TEST(JobFiles, Cube2CaptureJobRoundTripsEveryField) {
  capture::Cube2Options o;
  o.output = "/captures/x";
  o.map = "zoom";
  o.mode = "instagib";
  o.bots = 9;
  o.skill = 50;
  o.seconds = 12.5;
  o.fps = 30;
  o.seed = 4000000000u;
  o.gameFrames = {3, 70};
  o.follow = "one";
  o.warmup = 4;
  o.width = 320;
  o.height = 200;
  o.window = true;
  o.client = "/opt/cube2/client";
  o.data = "/srv/cube2-data";
  const auto document = capture::cube2JobJson(o);
  auto defaults = capture::cube2JobJson(capture::Cube2Options{});
  defaults["output"] = defaults["client"] = "";
  expectEveryFieldChanged(document, defaults, "dynbench_cube2_capture");
  auto parsed = capture::parseCube2Job(document, "capture.json");
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_EQ(capture::cube2JobJson(*parsed), document);

  for (const auto& [key, value, message] :
       {std::tuple{"bot", nlohmann::json(3), "capture.json: /bot: expected one of the Cube 2 capture job's keys"},
        std::tuple{"game_frames", nlohmann::json({1, -2}), "capture.json: /game_frames/1: expected a whole number in [0, "},
        std::tuple{"game_frames", nlohmann::json(5), "capture.json: /game_frames: expected an array of frame numbers, found 5"},
        std::tuple{"seed", nlohmann::json(4294967296LL), "capture.json: /seed: expected a whole number in [0, 4294967295], found 4294967296"},
        std::tuple{"window", nlohmann::json("yes"), "capture.json: /window: expected true or false, found \"yes\""}}) {
    auto d = document;
    d[key] = value;
    auto bad = capture::parseCube2Job(d, "capture.json");
    ASSERT_FALSE(bad) << key;
    EXPECT_NE(bad.error().message.find(message), std::string::npos) << bad.error().message;
  }
}

TEST(JobFiles, DemoJobRoundTripsEveryField) {
  demo::DemoOptions o;
  o.output = "/runs/demo";
  o.engine = "openarena";
  o.map = "oa_dm4";
  o.bots = 3;
  o.seconds = 7.5;
  o.gameCpu = capture::GameCpu::kHost;
  o.fps = 30;
  o.width = 160;
  o.height = 90;
  o.samplesPerPixel = 8;
  o.bounces = 3;
  o.tolerance = 0.25;
  o.maxSamplesPerPixel = 256;
  o.maxPairs = 128;
  o.renderFrames = 12;
  o.inputSamplesPerPixel = 2;
  o.floorFrames = 3;
  o.methods = {"none", "taa"};
  o.seed = 9;
  o.threads = 1;
  const auto document = demo::demoJobJson(o);
  expectEveryFieldChanged(document, demo::demoJobJson(demo::DemoOptions{}), "dynbench_demo");
  auto parsed = demo::parseDemoJob(document, "demo.json");
  ASSERT_TRUE(parsed) << parsed.error().message;
  EXPECT_EQ(demo::demoJobJson(*parsed), document);

  for (const auto& [key, value, message] :
       {std::tuple{"engine", nlohmann::json("quake"), "demo.json: /engine: expected \"cube2\" or \"openarena\", found \"quake\""},
        std::tuple{"game_cpu", nlohmann::json("arm"), "demo.json: /game_cpu: expected \"emulated\" or \"host\", found \"arm\""},
        std::tuple{"max_spp", nlohmann::json(4), "demo.json: /max_spp: expected at least /spp"},
        std::tuple{"methods", nlohmann::json({"none", 3}), "demo.json: /methods/1: expected a string, found 3"},
        std::tuple{"res", nlohmann::json("96x54"), "demo.json: /res: expected one of the demo job's keys"}}) {
    auto d = document;
    d[key] = value;
    auto bad = demo::parseDemoJob(d, "demo.json");
    ASSERT_FALSE(bad) << key;
    EXPECT_NE(bad.error().message.find(message), std::string::npos) << bad.error().message;
  }
}

}  // namespace
}  // namespace dynbench

namespace dynbench::pipeline {
namespace {

// Each method's input when a job names none for it: the one it is built for (the demo's case, as
// every suite scores it), an entry overriding it, an unknown method jittered; the still input is
// rendered only when some method takes it.
TEST(JobFiles, AMethodWithoutAnInputGetsTheOneItIsBuiltFor) {
  DatasetRunSettings s;
  EXPECT_EQ(methodInput(s, "none"), "jittered");
  EXPECT_EQ(methodInput(s, "taa"), "jittered");
  EXPECT_EQ(methodInput(s, "accumulate"), "still");
  EXPECT_EQ(methodInput(s, "svgf"), "still");
  EXPECT_EQ(methodInput(s, "my_method.py"), "jittered");
  EXPECT_TRUE(needsStillInput(s));  // the built-in four include accumulate and SVGF
  EXPECT_EQ(s.floorFrames, kDefaultFloorFrames);
  s.methodInputs["accumulate"] = "jittered";
  EXPECT_EQ(methodInput(s, "accumulate"), "jittered");
  s.methods = {"none", "taa", "accumulate"};
  EXPECT_FALSE(needsStillInput(s));
  s.methods.push_back("svgf");
  EXPECT_TRUE(needsStillInput(s));
  // The frame renders a dataset needs: the reference, both inputs and the floor's frames.
  EXPECT_EQ(datasetFrameRenders(s), 3 * s.renderFrames + kDefaultFloorFrames);
}

}  // namespace
}  // namespace dynbench::pipeline
