// `dynbench render` end to end: the feature-buffer contract on disk (EXR channel names, sidecar),
// resuming, the dataset's environment, and bad input.
#include <cmath>

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>
#include <glm/glm.hpp>

#include "core/files.h"
#include "core/image_io.h"
#include "discard/discard.h"
#include "frames/frame_io.h"
#include "gltf_builder.h"
#include "render/backend.h"
#include "render/render_job_json.h"
#include "run_cli.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;


nlohmann::json readJson(const fs::path& p) {
  auto text = readWholeFile(p);
  EXPECT_TRUE(text) << p;
  return nlohmann::json::parse(text ? *text : "{}");
}

glm::dmat4 matrix(const nlohmann::json& a) {
  glm::dmat4 m;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m[c][r] = a[static_cast<std::size_t>(4 * c + r)].get<double>();
  return m;
}

TEST(RenderCli, WritesTheContractAndResumes) {
  const auto dir = test::freshDir("render_cli");
  const fs::path out = dir / "frames";
  auto r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 2 --frames 0:4:2", kOrbit.string(), out.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("3 frame(s) rendered, 0 already complete"), std::string::npos) << r.out;
  for (long f : {0L, 2L, 4L}) {
    const fs::path exr = out / fmt::format("frame_{:05d}.exr", f);
    auto image = readImage(exr);
    ASSERT_TRUE(image) << image.error().message;
    EXPECT_EQ(image->width, 32);
    EXPECT_EQ(image->height, 18);
    const std::vector<std::string> expected{"P.X",    "P.Y",    "P.Z",      "N.X",        "N.Y",          "N.Z",
                                            "direct.R", "direct.G", "direct.B", "indirect.R", "indirect.G",   "indirect.B",
                                            "albedo.R", "albedo.G", "albedo.B", "Z",          "id",           "motion.X",
                                            "motion.Y", "direct.var", "indirect.var", "hit", "spp"};
    // EXR stores channels sorted by name; compare as sets.
    auto names = image->channelNames;
    auto sorted = expected;
    std::sort(names.begin(), names.end());
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(names, sorted);
    const auto j = readJson(out / fmt::format("frame_{:05d}.json", f));
    EXPECT_EQ(j["frame"], f);
    EXPECT_NEAR(j["time"].get<double>(), f / 24.0, 1e-12);  // orbit's animation starts at 0
    EXPECT_EQ(j["width"], 32);
    EXPECT_EQ(j["render"]["samples_per_pixel"], 2);
    const glm::dmat4 product = matrix(j["camera"]["view"]) * matrix(j["camera"]["world"]);
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(product[c][k], c == k ? 1.0 : 0.0, 1e-9);
    EXPECT_NEAR(matrix(j["camera"]["projection"])[1][1], 1.0 / std::tan(j["camera"]["yfov"].get<double>() / 2), 1e-9);
  }
  EXPECT_FALSE(fs::exists(out / "frame_00001.exr"));  // step 2

  r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 2 --frames 0:4:2", kOrbit.string(), out.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("0 frame(s) rendered, 3 already complete"), std::string::npos) << r.out;

  // The sidecar names the dataset by file name and content, not by where it is (issue 47: the
  // absolute path, and a file time read against the wrong epoch, negative, made the same frames
  // rendered in two folders differ): a copy of the dataset elsewhere resumes from these frames.
  {
    const auto j = readJson(out / "frame_00000.json");
    EXPECT_EQ(j["render"]["dataset"], kOrbit.filename().string());
    EXPECT_EQ(j["render"]["dataset_sha256"].get<std::string>().size(), 64u);
    EXPECT_FALSE(j["render"].contains("dataset_modified_ns"));
    const fs::path copy = dir / "copy";
    fs::create_directories(copy);
    fs::copy(kOrbit.parent_path(), copy, fs::copy_options::recursive);
    r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 2 --frames 0:4:2", (copy / kOrbit.filename()).string(), out.string()), dir);
    EXPECT_NE(r.out.find("0 frame(s) rendered, 3 already complete"), std::string::npos) << r.out;
    // The copy edited (orbit keeps its buffers in the .gltf as data: URIs): its frames are not
    // complete for it any more.
    std::ofstream(copy / kOrbit.filename(), std::ios::app) << "\n";
    r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 2 --frames 0:4:2", (copy / kOrbit.filename()).string(), (dir / "edited").string()), dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto edited = readJson(dir / "edited" / "frame_00000.json");
    EXPECT_NE(edited["render"]["dataset_sha256"], j["render"]["dataset_sha256"]);
  }

  // A frame whose sidecar is missing (interrupted before it was written) is rendered again, and
  // so is every frame when the settings change.
  fs::remove(out / "frame_00002.json");
  r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 2 --frames 0:4:2", kOrbit.string(), out.string()), dir);
  EXPECT_NE(r.out.find("1 frame(s) rendered, 2 already complete"), std::string::npos) << r.out;
  r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 3 --frames 0:4:2", kOrbit.string(), out.string()), dir);
  EXPECT_NE(r.out.find("3 frame(s) rendered, 0 already complete"), std::string::npos) << r.out;
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
}

// A mesh hidden at rest that appears in frame 1 and morphs until frame 2 onto itself: 96 pairs of
// quads, each pair's two quads (one facing the camera, one tilted towards the light) 2 units apart
// where it appears and coincident from frame 2 on, so that which of the two a ray reports is
// decided by the order Embree's BVH visits them. Embree builds a moving mesh's BVH where it is
// first enabled and refits it after (raytracing_scene.cpp), so that order depends on where the
// stepping through the frames began.
fs::path writeCoincidingQuads(const fs::path& dir) {
  test::GltfBuilder b;
  std::vector<float> positions, normals, moved;
  std::vector<std::uint32_t> indices;
  for (int pair = 0; pair < 96; ++pair) {
    const float x = -1.2f + 0.2f * static_cast<float>(pair % 12), y = -0.7f + 0.2f * static_cast<float>(pair / 12);
    for (int side = 0; side < 2; ++side) {
      const auto base = static_cast<std::uint32_t>(positions.size() / 3);
      for (const auto& [dx, dy] : {std::pair{0.f, 0.f}, {0.2f, 0.f}, {0.2f, 0.2f}, {0.f, 0.2f}}) {
        positions.insert(positions.end(), {x + dx + 2.0f * static_cast<float>(side), y + dy, -3.0f});
        moved.insert(moved.end(), {-2.0f * static_cast<float>(side), 0.f, 0.f});
        if (side == 0) normals.insert(normals.end(), {0.f, 0.f, 1.f});
        else normals.insert(normals.end(), {0.6f, 0.f, 0.8f});
      }
      indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
  }
  nlohmann::json prim = {{"attributes", {{"POSITION", b.accessor(positions, "VEC3")}, {"NORMAL", b.accessor(normals, "VEC3")}}},
                         {"indices", b.indices(indices)},
                         {"targets", {{{"POSITION", b.accessor(moved, "VEC3")}}}}};
  b.doc["meshes"] = {{{"primitives", nlohmann::json::array({prim})}, {"weights", {0.0}}}};
  const int quads = b.node({{"mesh", 0}, {"scale", {0.0, 0.0, 0.0}}});
  b.channel(quads, "scale", {0.0f, 1.0f / 24}, {0, 0, 0, 1, 1, 1}, "STEP");
  b.channel(quads, "weights", {1.0f / 24, 2.0f / 24, 6.0f / 24}, {0.0f, 1.0f, 1.0f});
  b.node({{"camera", b.perspectiveCamera(1.0)}});
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "directional"}, {"intensity", 3.0}}};
  b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}, {"rotation", {0.0, 0.38268343, 0.0, 0.92387953}}});
  return b.write(dir, "quads");
}

// A resumed job steps through the frames it skips, so the frame it renders is the same bytes as
// the whole job's (frame-level resume and the suite's records rest on it); so does a job over part
// of a range told to step from the range's first frame (what a Slurm render task is).
TEST(RenderCli, AResumedJobStepsThroughTheFramesItSkips) {
  const auto dir = test::freshDir("render_history");
  const fs::path dataset = writeCoincidingQuads(dir);
  const std::string options = "--res 96x54 --spp 1 --env-constant 0 --threads 2 --frames 0:5";
  auto r = dynbench(fmt::format("render {} -o {} {}", dataset.string(), (dir / "whole").string(), options), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // Started at frame 5, the mesh's BVH is built where it lies from frame 2 on: another order.
  r = dynbench(fmt::format("render {} -o {} --res 96x54 --spp 1 --env-constant 0 --threads 2 --frames 5", dataset.string(), (dir / "alone").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto bytes = [](const fs::path& file) { return readWholeFile(file).value_or(""); };
  const fs::path frame5 = fs::path("frame_00005.exr");
  ASSERT_FALSE(bytes(dir / "whole" / frame5).empty());
  EXPECT_TRUE(bytes(dir / "whole" / frame5) != bytes(dir / "alone" / frame5)) << "the scene no longer tells where the stepping began";
  // Resumed with frames 3 and 5 missing: the same bytes as the whole job's.
  fs::copy(dir / "whole", dir / "resumed");
  for (const char* f : {"frame_00003.exr", "frame_00003.json", "frame_00005.exr", "frame_00005.json"}) fs::remove(dir / "resumed" / f);
  r = dynbench(fmt::format("render {} -o {} {}", dataset.string(), (dir / "resumed").string(), options), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("2 frame(s) rendered, 4 already complete"), std::string::npos) << r.out;
  for (const char* f : {"frame_00003.exr", "frame_00005.exr"}) EXPECT_TRUE(bytes(dir / "whole" / f) == bytes(dir / "resumed" / f)) << f;
  // A part of the job's range, as a Slurm task runs it (`render --job FILE --frames PART`): stepped
  // from the file's first frame, the whole job's bytes.
  render::RenderJob job;
  job.dataset = dataset;
  job.settings.width = 96;
  job.settings.height = 54;
  job.settings.samplesPerPixel = 1;
  job.threads = 2;
  job.frames = {0, 5, 1};
  for (const char* name : {"whole", "part"}) {
    job.output = dir / "job" / name;
    ASSERT_TRUE(render::writeRenderJob(job, dir / (std::string(name) + ".json")));
  }
  r = dynbench(fmt::format("render --job {}", (dir / "whole.json").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = dynbench(fmt::format("render --job {} --frames 4:5", (dir / "part.json").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("2 frame(s) rendered, 0 already complete"), std::string::npos) << r.out;
  for (const char* f : {"frame_00004.exr", "frame_00005.exr"})
    EXPECT_TRUE(bytes(dir / "job" / "whole" / f) == bytes(dir / "job" / "part" / f)) << f;
}

// Frames are written while the next one renders: a frame that cannot be written still stops the
// job with its file named, the frames before it complete and none after it.
TEST(RenderCli, AFrameThatCannotBeWrittenStopsTheJob) {
  const auto dir = test::freshDir("render_write_fails");
  const fs::path out = dir / "frames";
  // Frame 2's image path is a folder with a file in it: the image cannot be renamed over it.
  fs::create_directories(out / "frame_00002.exr");
  ASSERT_TRUE(writeFileAtomic(out / "frame_00002.exr" / "keep", "x"));
  const auto r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 2 --frames 0:6:2", kOrbit.string(), out.string()), dir);
  EXPECT_EQ(r.status, 3);  // kIo
  EXPECT_NE(r.err.find("frame_00002.exr: cannot move finished file into place: Is a directory"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(out / "frame_00000.json"));
  EXPECT_TRUE(fs::is_regular_file(out / "frame_00000.exr"));
  for (const char* name : {"frame_00002.json", "frame_00004.exr", "frame_00004.json", "frame_00006.exr", "frame_00006.json"})
    EXPECT_FALSE(fs::exists(out / name)) << name;
}

TEST(RenderCli, JitterOffsetsEachFramesSamplesByTheHaltonSequence) {
  // Halton (2, 3) at index 1 + (frame mod 8), minus 0.5: by hand, index 1 = (1/2, 1/3),
  // index 2 = (1/4, 2/3), index 8 = (1/16, 8/9).
  EXPECT_NEAR(frames::jitterOffset(0).x, 0.0, 1e-15);
  EXPECT_NEAR(frames::jitterOffset(0).y, 1.0 / 3 - 0.5, 1e-15);
  EXPECT_NEAR(frames::jitterOffset(1).x, -0.25, 1e-15);
  EXPECT_NEAR(frames::jitterOffset(1).y, 2.0 / 3 - 0.5, 1e-15);
  EXPECT_NEAR(frames::jitterOffset(7).x, 1.0 / 16 - 0.5, 1e-15);
  EXPECT_NEAR(frames::jitterOffset(7).y, 8.0 / 9 - 0.5, 1e-15);
  EXPECT_EQ(frames::jitterOffset(9), frames::jitterOffset(1));

  const auto dir = test::freshDir("render_jitter");
  const fs::path out = dir / "frames";
  auto r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 1 --frames 0:1", kOrbit.string(), out.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // Jittered frames are not the same settings: both are rendered again.
  r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 1 --frames 0:1 --jitter", kOrbit.string(), out.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("2 frame(s) rendered, 0 already complete"), std::string::npos) << r.out;
  auto entries = frames::listFrames(out);
  ASSERT_TRUE(entries.has_value());
  for (const auto& entry : *entries) {
    auto frame = frames::readFrame(entry);
    ASSERT_TRUE(frame.has_value()) << frame.error().message;
    EXPECT_EQ(frame->camera.jitter, frames::jitterOffset(entry.frame));
    // Every hit's world position projects (unjittered matrices) onto its pixel's centre + jitter.
    int hits = 0;
    for (int y = 0; y < frame->height; ++y)
      for (int x = 0; x < frame->width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * frame->width + x;
        if (frame->hit[i] <= 0) continue;
        const auto q = reprojection::reproject(frame->camera, {frame->position[3 * i], frame->position[3 * i + 1], frame->position[3 * i + 2]});
        ASSERT_TRUE(q.has_value());
        EXPECT_NEAR(q->x, x + 0.5 + frame->camera.jitter.x, 2e-3);
        EXPECT_NEAR(q->y, y + 0.5 + frame->camera.jitter.y, 2e-3);
        ++hits;
      }
    EXPECT_GT(hits, 50);
  }
  r = dynbench(fmt::format("render {} -o {} --res 32x18 --spp 1 --frames 0 --jitter --engine cycles", kOrbit.string(), (dir / "c").string()), dir);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--jitter is implemented by the embree engine only"), std::string::npos) << r.err;
}

TEST(RenderCli, AChangedDatasetIsRenderedAgain) {
  const auto dir = test::freshDir("render_changed");
  fs::copy_file(kOrbit, dir / "orbit.gltf");
  const std::string args = fmt::format("render {} -o {} --res 16x9 --spp 1 --frames 3", (dir / "orbit.gltf").string(), (dir / "f").string());
  auto r = dynbench(args, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = dynbench(args, dir);
  EXPECT_NE(r.out.find("0 frame(s) rendered, 1 already complete"), std::string::npos) << r.out;
  // The same content with a newer time (copied again, touched): still complete, the record names
  // the dataset by content.
  fs::last_write_time(dir / "orbit.gltf", fs::last_write_time(dir / "orbit.gltf") + std::chrono::seconds(5));
  r = dynbench(args, dir);
  EXPECT_NE(r.out.find("0 frame(s) rendered, 1 already complete"), std::string::npos) << r.out;
  // The same path, other content (re-converted, edited): its old frames are not complete for it.
  std::ofstream(dir / "orbit.gltf", std::ios::app) << " ";
  r = dynbench(args, dir);
  EXPECT_NE(r.out.find("1 frame(s) rendered, 0 already complete"), std::string::npos) << r.out;
}

// The resume record covers --animation: frames rendered with one animation selection are not
// taken as complete for another.
TEST(RenderCli, AnotherAnimationIsRenderedAgain) {
  const auto dir = test::freshDir("render_animation");
  const std::string base = fmt::format("render {} -o {} --frames 0 --res 8x4 --spp 1", kOrbit.string(), (dir / "out").string());
  auto r = dynbench(base, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("1 frame(s) rendered, 0 already complete"), std::string::npos) << r.out;
  EXPECT_FALSE(readJson(dir / "out" / "frame_00000.json")["render"].contains("animation"));
  r = dynbench(base + " --animation orbit", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("1 frame(s) rendered, 0 already complete"), std::string::npos) << r.out;
  EXPECT_EQ(readJson(dir / "out" / "frame_00000.json")["render"]["animation"], "orbit");
  r = dynbench(base + " --animation orbit", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("0 frame(s) rendered, 1 already complete"), std::string::npos) << r.out;
}

TEST(RenderCli, TheDatasetEnvironmentLightsTheBackground) {
  const auto dir = test::freshDir("render_env");
  FloatImage sky;
  sky.width = 8;
  sky.height = 4;
  sky.channels = 3;
  sky.pixels.assign(8 * 4 * 3, 0.0f);
  for (std::size_t i = 0; i < sky.pixels.size(); i += 3) {
    sky.pixels[i] = 0.25f;
    sky.pixels[i + 1] = 0.5f;
    sky.pixels[i + 2] = 1.0f;
  }
  ASSERT_TRUE(writeImage(dir / "sky.hdr", sky));
  test::GltfBuilder b;
  b.node({{"name", "eye"}, {"camera", b.perspectiveCamera()}});
  b.doc["extensions"]["DYNBENCH_environment"] = {{"uri", "sky.hdr"}, {"intensity", 2.0}};
  b.doc["extensionsUsed"] = {"DYNBENCH_environment"};
  const fs::path scene = b.write(dir, "env");
  auto r = dynbench(fmt::format("render {} -o {} --res 8x4 --spp 1", scene.string(), (dir / "out").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  auto image = readImage(dir / "out" / "frame_00000.exr");
  ASSERT_TRUE(image);
  auto channel = [&](const std::string& name) {
    const auto it = std::find(image->channelNames.begin(), image->channelNames.end(), name);
    return static_cast<std::size_t>(it - image->channelNames.begin());
  };
  for (std::size_t p = 0; p < 32; ++p) {
    const float* px = &image->pixels[p * static_cast<std::size_t>(image->channels)];
    EXPECT_FLOAT_EQ(px[channel("direct.R")], 0.5f);
    EXPECT_FLOAT_EQ(px[channel("direct.G")], 1.0f);
    EXPECT_FLOAT_EQ(px[channel("direct.B")], 2.0f);
    EXPECT_EQ(px[channel("hit")], 0.0f);
    EXPECT_EQ(px[channel("P.X")], 0.0f);
  }
  // --no-environment: black.
  r = dynbench(fmt::format("render {} -o {} --res 8x4 --spp 1 --no-environment", scene.string(), (dir / "dark").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  image = readImage(dir / "dark" / "frame_00000.exr");
  ASSERT_TRUE(image);
  ASSERT_EQ(image->pixels.size(), 32u * static_cast<std::size_t>(image->channels));
  for (std::size_t p = 0; p < 32; ++p) {  // the whole image: nothing hit, nothing lit
    const float* px = &image->pixels[p * static_cast<std::size_t>(image->channels)];
    for (const char* c : {"direct.R", "direct.G", "direct.B", "indirect.R", "indirect.G", "indirect.B", "hit", "P.X", "P.Y", "P.Z"})
      EXPECT_EQ(px[channel(c)], 0.0f) << c << " at pixel " << p;
  }

  // The environment image missing: the error names the file and the JSON pointer.
  fs::remove(dir / "sky.hdr");
  r = dynbench(fmt::format("render {} -o {}", scene.string(), (dir / "out2").string()), dir);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("env.gltf: /extensions/DYNBENCH_environment/uri"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out2"));
}

TEST(RenderCli, BadOptionsFailClearly) {
  const auto dir = test::freshDir("render_bad");
  const std::string base = fmt::format("render {} -o {} ", kOrbit.string(), (dir / "out").string());
  struct Case {
    std::string args, message;
    int status;
  };
  for (const Case& c : {Case{"--frames 5:2", "--frames '5:2'", 2}, Case{"--frames 9999", "the animation has frames 0 to", 2},
                        Case{"--frames a:b", "--frames 'a:b'", 2}, Case{"--res 0x5", "--res '0x5'", 2},
                        Case{"--res 64", "--res '64'", 2}, Case{"--engine optix", "--engine: optix not in {embree,cycles}", 2},
                        Case{"--spp 0", "--spp: must be positive (got 0)", 2}, Case{"--camera nobody", "nobody", 2},
                        Case{"--env-constant x", "--env-constant 'x'", 2},
                        Case{"--threads -2", "--threads: must be 0 or more (got -2)", 2}}) {
    const auto r = dynbench(base + c.args, dir);
    EXPECT_EQ(r.status, c.status) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "frame_00000.exr"));
  const auto r = dynbench(fmt::format("render {} -o {}", (dir / "missing.gltf").string(), (dir / "out").string()), dir);
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("missing.gltf"), std::string::npos);
}

}  // namespace
}  // namespace dynbench

namespace dynbench {
namespace {

// Backends are found by name; an unknown one is a usage error listing the names.
TEST(RenderBackends, FoundByNameAndListedWhenNot) {
  ASSERT_GE(render::renderBackends().size(), 2u);
  EXPECT_STREQ(render::renderBackends().front().name, "embree");  // the default first
  auto cycles = render::findBackend("cycles");
  ASSERT_TRUE(cycles);
  EXPECT_STREQ((*cycles)->name, "cycles");
  auto none = render::findBackend("optix");
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().code, ErrorCode::kUsage);
  EXPECT_EQ(none.error().message, "--engine 'optix': expected one of embree, cycles");
}

}  // namespace
}  // namespace dynbench
