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
  for (const auto& spec : contractBuffers())  // the radiance-change pairs too
    if (spec.onRequest) (f.*spec.member).assign(f.pixelCount() * spec.channels.size(), 0.0f);
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
  EXPECT_EQ(contractChannelNames().size(), 30u);
  EXPECT_FALSE(read->sampling);  // none written
}

// Precision on disk (docs/feature-buffers.md): each buffer as its Storage says, half only where
// the frame's values allow it, 32-bit everywhere with --float32.
TEST(Frames, EachBufferIsStoredAtTheContractsPrecision) {
  const fs::path dir = freshDir("frames_precision");
  FeatureFrame f = patterned(4, 2);
  for (std::size_t i = 0; i < f.pixelCount(); ++i) {
    const float k = static_cast<float>(i);
    for (int c = 0; c < 3; ++c) {
      f.position[3 * i + c] = 1234.567f + 0.001f * k + c;  // not exact in half
      f.normal[3 * i + c] = 0.1234567f * (c + 1) - 0.01f * k;
      f.direct[3 * i + c] = 12.34567f + k;
      f.indirect[3 * i + c] = 0.0123457f * (k + 1);
    }
    f.motion[2 * i] = 3.14159f * k;
    f.motion[2 * i + 1] = -1.5f;
    f.id[i] = static_cast<float>(i % 3);
  }
  auto channelFormat = [](const FloatImage& image, const std::string& name) {
    const auto at = std::find(image.channelNames.begin(), image.channelNames.end(), name) - image.channelNames.begin();
    return image.formats.at(static_cast<std::size_t>(at));
  };
  auto roundTrip = [&](const FeatureFrame& frame, const WriteOptions& options) {
    EXPECT_TRUE(writeFrame(dir, frame, {{"engine", "test"}}, options));
    auto image = readImage(frameImagePath(dir, frame.frame));
    EXPECT_TRUE(image);
    auto read = readFrame({frame.frame, frameImagePath(dir, frame.frame), frameSidecarPath(dir, frame.frame)});
    EXPECT_TRUE(read);
    return std::pair{*image, *read};
  };
  {
    const auto [image, read] = roundTrip(f, {});
    EXPECT_EQ(channelFormat(image, "P.X"), SampleFormat::kFloat32);
    EXPECT_EQ(read.position, f.position);  // positions exactly
    for (const char* name : {"N.X", "direct.R", "indirect.B", "albedo.G", "direct.var", "motion.X", "hit", "id", "spp"})
      EXPECT_EQ(channelFormat(image, name), SampleFormat::kFloat16) << name;
    for (const char* name : {"Z"}) EXPECT_EQ(channelFormat(image, name), SampleFormat::kFloat32) << name;
    EXPECT_NE(read.normal, f.normal);  // rounded, within half's relative error
    for (std::size_t i = 0; i < f.normal.size(); ++i) EXPECT_NEAR(read.normal[i], f.normal[i], std::abs(f.normal[i]) * 0x1p-11);
    for (std::size_t i = 0; i < f.direct.size(); ++i) EXPECT_NEAR(read.direct[i], f.direct[i], f.direct[i] * 0x1p-11);
    for (std::size_t i = 0; i < f.motion.size(); ++i) EXPECT_NEAR(read.motion[i], f.motion[i], 1.0 / 64);  // within 256 px: 1/64 px here
    EXPECT_EQ(read.id, f.id);  // small integers: exact
  }
  {
    // Values half cannot hold keep 32 bits, buffer by buffer: radiance over 65504, a vector longer
    // than 256 pixels (or "behind the camera"), a node id with no exact half.
    FeatureFrame g = f;
    g.direct[4] = 70000.0f;
    g.motion[1] = -1e9f;
    g.id[2] = 2049.0f;
    const auto [image, read] = roundTrip(g, {});
    for (const char* name : {"direct.R", "motion.Y", "id"}) EXPECT_EQ(channelFormat(image, name), SampleFormat::kFloat32) << name;
    EXPECT_EQ(channelFormat(image, "indirect.R"), SampleFormat::kFloat16);
    EXPECT_EQ(read.direct, g.direct);
    EXPECT_EQ(read.motion, g.motion);
    EXPECT_EQ(read.id, g.id);
  }
  {
    const auto [image, read] = roundTrip(f, {.float32 = true});
    for (const auto format : image.formats) EXPECT_EQ(format, SampleFormat::kFloat32);
    for (const auto& spec : contractBuffers()) EXPECT_EQ(read.*spec.member, f.*spec.member) << spec.name;
  }
}

TEST(Frames, TheSamplingSummaryRoundTrips) {
  const fs::path dir = freshDir("frames_sampling");
  FeatureFrame written = patterned(4, 2);
  written.sampling = frames::SamplingSummary{true, 0.25, 1.5, 0.75, 16, 4096, 123.5, 3, 4};
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
  EXPECT_EQ(s.lightsPerPoint, 4);
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
