// The feature-buffer contract module: a frame written with every buffer reads back bit for bit, a
// frame with only some buffers (as Cycles writes) reads back with the others empty, and the
// writer refuses frames that break the contract.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "core/files.h"
#include "core/image_io.h"
#include "frames/frame_io.h"
#include "frames/preview.h"
#include "gltf_builder.h"
#include "run_cli.h"

#include <fstream>

namespace dynbench::frames {
namespace {

namespace fs = std::filesystem;
using test::freshDir;

FeatureFrame patterned(int width, int height) {
  FeatureFrame f;
  f.frame = 7;
  f.time = 0.25;
  f.resize(width, height);
  f.camera.view = glm::dmat4(1.0);
  f.camera.view[3] = glm::dvec4(1, 2, 3, 1);
  f.camera.world = glm::inverse(f.camera.view);
  f.camera.position = glm::dvec3(f.camera.world[3]);
  f.camera.projection = glm::dmat4(2.0);
  f.camera.yfov = 0.7;
  f.camera.znear = 0.1;
  f.camera.zfar = 1000;
  float v = 0.5f;
  for (const auto& spec : contractBuffers())
    for (auto& x : f.*spec.member) x = (v += 0.25f);  // every value distinct
  return f;
}

TEST(Frames, EveryBufferRoundTripsExactly) {
  const fs::path dir = freshDir("frames_round_trip");
  const FeatureFrame written = patterned(5, 3);
  ASSERT_TRUE(writeFrame(dir, written, {{"engine", "test"}}));
  EXPECT_TRUE(frameComplete(dir, 7, {{"engine", "test"}}));
  EXPECT_FALSE(frameComplete(dir, 7, {{"engine", "other"}}));
  auto entries = listFrames(dir);
  ASSERT_TRUE(entries) << entries.error().message;
  ASSERT_EQ(entries->size(), 1u);
  EXPECT_EQ((*entries)[0].image.filename(), "frame_00007.exr");
  auto read = readFrame((*entries)[0]);
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(read->frame, 7);
  EXPECT_EQ(read->time, 0.25);
  EXPECT_EQ(read->width, 5);
  EXPECT_EQ(read->height, 3);
  for (const auto& spec : contractBuffers()) EXPECT_EQ((*read).*spec.member, written.*spec.member) << spec.name;
  EXPECT_EQ(read->camera.view, written.camera.view);
  EXPECT_EQ(read->camera.world, written.camera.world);
  EXPECT_EQ(read->camera.projection, written.camera.projection);
  EXPECT_EQ(read->camera.yfov, 0.7);
  EXPECT_EQ(read->camera.zfar, 1000);
  // The image's channels are exactly the contract's (OpenEXR keeps them sorted by name).
  auto header = readImage((*entries)[0].image);
  ASSERT_TRUE(header);
  auto names = header->channelNames, expected = contractChannelNames();
  std::sort(names.begin(), names.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(names, expected);
  EXPECT_EQ(contractChannelNames().size(), 23u);
  EXPECT_FALSE(read->sampling);  // none written
}

TEST(Frames, TheSamplingSummaryRoundTrips) {
  const fs::path dir = freshDir("frames_sampling");
  FeatureFrame written = patterned(4, 2);
  written.sampling = frames::SamplingSummary{true, 0.25, 1.5, 0.75, 16, 4096, 123.5, 3, 0.01, 2.5};
  ASSERT_TRUE(writeFrame(dir, written, {{"engine", "test"}}));
  auto entries = listFrames(dir);
  ASSERT_TRUE(entries);
  auto read = readFrame((*entries)[0]);
  ASSERT_TRUE(read) << read.error().message;
  ASSERT_TRUE(read->sampling);
  const auto& s = *read->sampling;
  EXPECT_TRUE(s.adaptive);
  EXPECT_EQ(s.tolerance, 0.25);
  EXPECT_EQ(s.directTarget, 1.5);
  EXPECT_EQ(s.indirectTarget, 0.75);
  EXPECT_EQ(s.minSamples, 16);
  EXPECT_EQ(s.maxSamples, 4096);
  EXPECT_EQ(s.meanSamples, 123.5);
  EXPECT_EQ(s.cappedPixels, 3);
  EXPECT_EQ(s.lightCutoff, 0.01);
  EXPECT_EQ(s.droppedIrradianceBound, 2.5);
  // A malformed value is named by its JSON pointer.
  auto j = nlohmann::json::parse(test::slurp(frameSidecarPath(dir, 7)));
  j["sampling"]["mean_spp"] = "many";
  std::ofstream(frameSidecarPath(dir, 7)) << j.dump();
  auto bad = readFrame((*entries)[0]);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("/sampling/mean_spp: expected a number"), std::string::npos) << bad.error().message;
}

TEST(Frames, OptionalBuffersMayBeAbsentButRequiredOnesMayNot) {
  const fs::path dir = freshDir("frames_subset");
  FeatureFrame f = patterned(4, 2);
  f.id.clear();
  f.motion.clear();
  f.directVariance.clear();
  f.indirectVariance.clear();
  ASSERT_TRUE(writeFrame(dir, f, nullptr));
  auto read = readFrame({7, frameImagePath(dir, 7), frameSidecarPath(dir, 7)});
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_TRUE(read->id.empty());
  EXPECT_TRUE(read->motion.empty());
  EXPECT_FALSE(read->hasVariance());
  EXPECT_EQ(read->albedo, f.albedo);
  auto strict = readFrame({7, frameImagePath(dir, 7), frameSidecarPath(dir, 7)}, {.requireVariance = true});
  ASSERT_FALSE(strict);
  EXPECT_NE(strict.error().message.find("lacks the channel(s) direct.var"), std::string::npos) << strict.error().message;

  f.hit.clear();
  auto refused = writeFrame(dir, f, nullptr);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message, "frame 7: the hit buffer is required by the contract");
  f = patterned(4, 2);
  f.normal.pop_back();
  refused = writeFrame(dir, f, nullptr);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message, "frame 7: the N buffer has 23 values, expected 24");
}

TEST(Frames, PreviewMapsTheMeanToMiddleGrey) {
  // A uniform frame of luminance L maps to 0.18 / 1.18 before gamma, whatever L is.
  FeatureFrame f;
  f.resize(2, 2);
  for (float L : {0.01f, 1.0f, 5000.0f}) {
    std::fill(f.direct.begin(), f.direct.end(), L * 0.75f);
    std::fill(f.indirect.begin(), f.indirect.end(), L * 0.25f);
    const auto rgb = previewImage(f);
    for (float c : rgb) EXPECT_NEAR(c, std::pow(0.18 / 1.18, 1 / 2.2), 1e-6) << L;
  }
}

}  // namespace
}  // namespace dynbench::frames
