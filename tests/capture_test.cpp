// The capture SDK (C API) writes, the reader reads back, capture-check summarises; broken
// captures fail with file:line. Everything here is written by the test itself.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "capture/check.h"
#include "capture/reader.h"
#include "core/math.h"
#include "dynbench/capture.h"
#include "capture_fixture.h"
#include "gltf_builder.h"
#include "run_cli.h"

namespace dynbench::capture {
namespace {

namespace fs = std::filesystem;
using namespace dynbench::test;

TEST(DualQuaternion, RoundTripsRotationAndTranslation) {
  const glm::dquat r = glm::angleAxis(radians(70.0), glm::normalize(glm::dvec3(1, 2, -1)));
  const glm::dvec3 t(3, -4, 5);
  const DualQuaternion q = dualQuaternionFromRigid(r, t);
  EXPECT_NEAR(glm::length(translationOf(q) - t), 0.0, 1e-12);
  EXPECT_NEAR(geodesicAngle(rotationOf(q), r), 0.0, 1e-12);
  // Pure translation: d = (0, t/2).
  const DualQuaternion p = dualQuaternionFromRigid(glm::dquat(1, 0, 0, 0), {2, 4, 6});
  EXPECT_DOUBLE_EQ(p.dual.x, 1.0);
  EXPECT_DOUBLE_EQ(p.dual.y, 2.0);
  EXPECT_DOUBLE_EQ(p.dual.z, 3.0);
  EXPECT_DOUBLE_EQ(p.dual.w, 0.0);
  // The matrix applies the rotation, then the translation.
  const glm::dvec3 x = glm::dvec3(matrixOf(q) * glm::dvec4(1, 0, 0, 1));
  EXPECT_NEAR(glm::length(x - (r * glm::dvec3(1, 0, 0) + t)), 0.0, 1e-12);
}

TEST(Capture, WriteThenReadBack) {
  const auto dir = writeCapture("capture_roundtrip");
  auto reader = CaptureReader::open(dir);
  ASSERT_TRUE(reader) << reader.error().message;
  const auto& r = **reader;
  EXPECT_EQ(r.settings().source, "dynbench tests");
  EXPECT_EQ(r.settings().mapName, "testmap");
  EXPECT_EQ(r.settings().mapOffset, glm::dvec3(1, 2, 3));
  EXPECT_EQ(r.settings().dataRoot, "/data/game");
  ASSERT_TRUE(r.settings().camera);
  EXPECT_NEAR(r.settings().camera->yfovDegrees, 75.0, 1e-6);
  ASSERT_EQ(r.models().size(), 2u);
  const int arm = r.modelIndex("chars/arm");
  ASSERT_GE(arm, 0);
  const auto& model = r.models()[static_cast<std::size_t>(arm)];
  ASSERT_EQ(model.meshes.size(), 1u);
  EXPECT_EQ(model.meshes[0].texture, "chars/arm.png");
  EXPECT_EQ(model.meshes[0].maskTexture, "chars/arm_mask.png");
  EXPECT_EQ(model.meshes[0].positions[2], glm::vec3(1, 2, 0));
  EXPECT_EQ(model.meshes[0].uvs[3], glm::vec2(0, 1));
  EXPECT_EQ(model.meshes[0].joints[3], glm::u16vec4(0, 1, 0, 0));
  EXPECT_EQ(model.meshes[0].weights[3], glm::vec4(0.25f, 0.75f, 0, 0));
  EXPECT_EQ(model.meshes[0].indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(model.joints.size(), 2u);
  EXPECT_EQ(model.joints[1].name, "elbow");
  EXPECT_EQ(model.joints[1].parent, 0);
  EXPECT_NEAR(translationOf(model.joints[1].inverseBindPose).y, -1.0, 1e-6);
  EXPECT_GE(r.modelIndex("mapmodel/crate:1"), 0);

  CaptureFrame frame;
  std::size_t frames = 0, crateFrames = 0, flashFrames = 0;
  while (true) {
    auto more = (*reader)->next(frame);
    ASSERT_TRUE(more) << more.error().message;
    if (!*more) break;
    const int f = static_cast<int>(frames);
    EXPECT_EQ(frame.number, 100u + frames);
    EXPECT_DOUBLE_EQ(frame.time, f / 60.0);  // times round-trip exactly (17 digits)
    ASSERT_EQ(frame.cameras.size(), 1u);
    ASSERT_EQ(frame.cuts.size(), f == 7 ? 1u : 0u);
    if (f == 7) {
      EXPECT_EQ(frame.cuts[0].id, frame.cameras[0].id);
      EXPECT_EQ(frame.cuts[0].reason, "respawn");
    }
    EXPECT_FLOAT_EQ(static_cast<float>(frame.cameras[0].yaw), 3.0f * f);
    EXPECT_FLOAT_EQ(static_cast<float>(frame.cameras[0].position.z), static_cast<float>(f));
    EXPECT_EQ(frame.staticModels.size(), f == 0 ? 1u : 0u);  // static: recorded once
    EXPECT_EQ(frame.lights.size(), (f == 0 ? 1u : 0u) + (f == 2 || f == 3 ? 1u : 0u));
    for (const auto& l : frame.lights)
      if (l.dynamic) {
        ++flashFrames;
        EXPECT_EQ(l.modelType, "flash");
        EXPECT_DOUBLE_EQ(l.color.r, f == 2 ? 1.0 : 0.5);
      }
    ASSERT_EQ(frame.joints.size(), 1u);
    ASSERT_EQ(frame.joints[0].joints.size(), 2u);
    EXPECT_NEAR(degrees(geodesicAngle(glm::dquat(1, 0, 0, 0), rotationOf(frame.joints[0].joints[1]))), 10.0 * f, 1e-4);
    for (const auto& m : frame.models)
      if (m.model == r.modelIndex("mapmodel/crate:1")) {
        ++crateFrames;
        EXPECT_NEAR(translationOf(m.pose).x, 2.0, 1e-6);
      } else {
        EXPECT_NEAR(translationOf(m.pose).x, 0.1 * f, 1e-6);
      }
    ++frames;
  }
  EXPECT_EQ(frames, 10u);
  EXPECT_EQ(crateFrames, 7u);  // absent in frames 4, 5 and 6
  EXPECT_EQ(flashFrames, 2u);
  EXPECT_TRUE(r.closed());
  EXPECT_TRUE(r.warnings().empty());
}

TEST(Capture, CheckSummarises) {
  const auto dir = writeCapture("capture_check");
  auto s = checkCapture(dir);
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->frames, 10u);
  EXPECT_EQ(s->firstFrame, 100u);
  EXPECT_EQ(s->lastFrame, 109u);
  EXPECT_DOUBLE_EQ(s->endTime - s->startTime, 9 / 60.0);
  EXPECT_EQ(s->cameras, 1u);
  EXPECT_EQ(s->staticModels, 1u);
  EXPECT_EQ(s->rigidModels, 1u);
  EXPECT_EQ(s->skinnedModels, 1u);
  EXPECT_EQ(s->staticLights, 1u);
  EXPECT_EQ(s->dynamicLights, 1u);
  EXPECT_EQ(s->lightsByModelType.at("flash"), 1u);
  EXPECT_EQ(s->capturables, 6u);
  EXPECT_EQ(s->models, 2u);
  EXPECT_EQ(s->triangles, 3u);
  EXPECT_EQ(s->joints, 2u);
  EXPECT_TRUE(s->closed);
  const std::string text = summaryText(dir, *s);
  EXPECT_NE(text.find("frames:      10 (numbers 100..109)"), std::string::npos) << text;
  EXPECT_NE(text.find("60.00 frames/s"), std::string::npos) << text;
  EXPECT_EQ(s->cutsByReason, (std::map<std::string, std::size_t>{{"respawn", 1}}));
  EXPECT_NE(text.find("camera cuts: 1 (1 respawn)"), std::string::npos) << text;
}

TEST(CaptureSdk, RejectsBadCallsAndWritesNothingForThem) {
  const auto dir = test::freshDir("capture_sdk_errors");
  dbc_session* s = nullptr;
  ASSERT_EQ(dbc_open(dir.c_str(), nullptr, &s), DBC_OK);
  recordModels(s);
  const float p[] = {0, 0, 0};
  EXPECT_EQ(dbc_camera(s, 1, p, 0, 0, 0), DBC_ERROR_ORDER);  // outside a frame
  EXPECT_NE(std::string(dbc_last_error()).find("outside a frame"), std::string::npos);
  ASSERT_EQ(dbc_frame_begin(s, 1, 0.0), DBC_OK);
  EXPECT_EQ(dbc_camera(s, 1, p, std::nanf(""), 0, 0), DBC_ERROR_ARGUMENT);
  EXPECT_EQ(dbc_model(s, 2, "no/such/model", rigid(0, {})), DBC_ERROR_ARGUMENT);
  EXPECT_NE(std::string(dbc_last_error()).find("no/such/model"), std::string::npos);
  const dbc_dual_quat one[] = {rigid(0, {})};
  EXPECT_EQ(dbc_joints(s, 3, "chars/arm", 1, one), DBC_ERROR_ARGUMENT);  // the arm has 2 joints
  EXPECT_NE(std::string(dbc_last_error()).find("has 2 joints"), std::string::npos);
  const dbc_dual_quat two[] = {rigid(0, {}), rigid(0, {})};
  EXPECT_EQ(dbc_joints(s, 3, "chars/arm", 2, two), DBC_ERROR_ORDER);  // no dbc_model for id 3 yet
  EXPECT_EQ(dbc_camera_cut(s, 1, "respawn"), DBC_ERROR_ORDER);  // camera 1 has no record in this frame yet
  EXPECT_NE(std::string(dbc_last_error()).find("no dbc_camera record earlier in this frame"), std::string::npos) << dbc_last_error();
  ASSERT_EQ(dbc_camera(s, 1, p, 0, 0, 0), DBC_OK);
  EXPECT_EQ(dbc_model(s, 1, "chars/arm", rigid(0, {})), DBC_ERROR_ARGUMENT);  // id 1 is a camera
  EXPECT_EQ(dbc_model_begin(s, "late"), DBC_ERROR_ORDER);
  EXPECT_EQ(dbc_frame_begin(s, 2, 0.1), DBC_ERROR_ORDER);  // frame 1 has not ended
  ASSERT_EQ(dbc_frame_end(s), DBC_OK);
  EXPECT_EQ(dbc_frame_begin(s, 1, 0.2), DBC_ERROR_ARGUMENT);  // frame numbers must increase
  // the lens is set once, before any frame: readers refuse a 'C' record between frames (OpenArena's
  // underwater view changed its field of view mid-match and left a capture no reader took)
  EXPECT_EQ(dbc_set_camera_settings(s, 16.0f / 9, 60.0f, 0.1f, 100.0f), DBC_ERROR_ORDER);
  EXPECT_NE(std::string(dbc_last_error()).find("set once, before any frame"), std::string::npos) << dbc_last_error();
  ASSERT_EQ(dbc_close(s), DBC_OK);
  auto summary = checkCapture(dir);
  ASSERT_TRUE(summary) << summary.error().message;  // only the valid records were written
  EXPECT_EQ(summary->frames, 1u);
  EXPECT_EQ(summary->cameraRecords, 1u);
  EXPECT_EQ(summary->modelRecords, 0u);
}

TEST(CaptureSdk, CrashKeepsEveryCompleteFrame) {
  const auto dir = test::freshDir("capture_crash");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    dbc_session* s = nullptr;
    if (dbc_open(dir.c_str(), "crashing host", &s) != DBC_OK) ::_exit(3);
    recordModels(s);
    recordFrames(s, 5);
    dbc_frame_begin(s, 999, 1.0);  // a frame in progress when the host dies
    const float p[] = {0, 0, 0};
    dbc_camera(s, 1, p, 0, 0, 0);
    ::_exit(0);  // no dbc_close, no stdio flush: as abrupt as a crash for our buffers
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  auto summary = checkCapture(dir);
  ASSERT_TRUE(summary) << summary.error().message;
  EXPECT_EQ(summary->frames, 5u);
  EXPECT_FALSE(summary->closed);
  ASSERT_FALSE(summary->warnings.empty());
  EXPECT_NE(summary->warnings.back().find("not closed"), std::string::npos);
}

TEST(CaptureCheckCli, PrintsSummaryWritesJsonAndFailsWithFileLine) {
  const auto dir = writeCapture("capture_cli");
  auto r = dynbench(fmt::format("capture-check {} --json {}", dir.string(), (dir / "summary.json").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("frames:      10 (numbers 100..109)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 skinned models"), std::string::npos) << r.out;
  std::ifstream in(dir / "summary.json");
  const auto json = nlohmann::json::parse(in);
  EXPECT_EQ(json["frames"], 10);
  EXPECT_EQ(json["capturables"]["skinned_models"], 1);
  EXPECT_EQ(json["map"], "testmap");

  std::ofstream(dir / "Capture.txt", std::ios::app) << "f:200:1\nt:1:0:0:0:0:0\n";
  r = dynbench(fmt::format("capture-check {}", dir.string()), dir);
  EXPECT_EQ(r.status, 5) << r.err;  // "z" closed the session: a record after it is invalid
  EXPECT_NE(r.err.find("Capture.txt:"), std::string::npos) << r.err;
  r = dynbench(fmt::format("capture-check {}", (dir / "nowhere").string()), dir);
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("not a capture directory"), std::string::npos) << r.err;
}

// ---- broken captures written by hand ---------------------------------------------------------

fs::path handCapture(const std::string& name, const std::string& capture) {
  const auto dir = writeCapture(name);
  std::ofstream(dir / "Capture.txt", std::ios::trunc) << capture;
  return dir;
}

const std::string kHeader = "dynbench-capture:2\ns:hand\n";
const std::string kGoodFrame = "f:1:0\nt:1:0:0:0:0:0:0\nm:2:0:0:0:1:0:0:0:0:chars/arm\n"
                               "j:2:2:0:0:0:1:0:0:0:0:0:0:0:1:0:0:0:0:chars/arm\ne:1\n";

void expectCaptureError(const fs::path& dir, ErrorCode code, std::vector<std::string> fragments) {
  auto s = checkCapture(dir);
  ASSERT_FALSE(s) << "expected an error";
  EXPECT_EQ(s.error().code, code) << s.error().message;
  for (const auto& f : fragments) EXPECT_NE(s.error().message.find(f), std::string::npos) << "missing '" << f << "' in " << s.error().message;
}

TEST(BadCapture, HandWrittenGoodFrameReads) {
  auto s = checkCapture(handCapture("bad_none", kHeader + kGoodFrame + "z:1\n"));
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->frames, 1u);
  EXPECT_EQ(s->skinnedModels, 1u);
}

TEST(BadCapture, MalformedNumber) {
  expectCaptureError(handCapture("bad_number", kHeader + "f:1:0\nt:1:0:zero:0:0:0:0\ne:1\n"), ErrorCode::kParse,
                     {"Capture.txt:4:", "'zero', not a number"});
}

TEST(BadCapture, UnknownToken) {
  expectCaptureError(handCapture("bad_token", kHeader + "f:1:0\nq:1:2\ne:1\n"), ErrorCode::kParse, {"Capture.txt:4:", "unknown record 'q'"});
}

TEST(BadCapture, WrongFieldCount) {
  expectCaptureError(handCapture("bad_fields", kHeader + "f:1:0\nt:1:0:0:0:0:0\ne:1\n"), ErrorCode::kParse,
                     {"Capture.txt:4:", "needs 7 fields", "got 6"});
}

TEST(BadCapture, NaN) {
  expectCaptureError(handCapture("bad_nan", kHeader + "f:1:0\nt:1:0:nan:0:0:0:0\ne:1\n"), ErrorCode::kInvalidData,
                     {"Capture.txt:4:", "must be finite"});
}

TEST(BadCapture, JointCountDisagreesWithModel) {
  expectCaptureError(handCapture("bad_joints", kHeader + "f:1:0\nm:2:0:0:0:1:0:0:0:0:chars/arm\nj:2:1:0:0:0:1:0:0:0:0:chars/arm\ne:1\n"),
                     ErrorCode::kInvalidData, {"Capture.txt:5:", "1 joints for model 'chars/arm', which has 2"});
}

TEST(BadCapture, UnknownModelAndUnknownCapturable) {
  expectCaptureError(handCapture("bad_model", kHeader + "f:1:0\nm:2:0:0:0:1:0:0:0:0:chars/leg\ne:1\n"), ErrorCode::kInvalidData,
                     {"Capture.txt:4:", "unknown model 'chars/leg'"});
  // Joints for capturable 7, which has no model transform in this frame.
  expectCaptureError(handCapture("bad_capturable", kHeader + "f:1:0\nj:7:2:0:0:0:1:0:0:0:0:0:0:0:1:0:0:0:0:chars/arm\ne:1\n"),
                     ErrorCode::kInvalidData, {"Capture.txt:4:", "capturable 7", "no model transform"});
  expectCaptureError(handCapture("bad_kind", kHeader + kGoodFrame + "f:2:1\nt:2:0:0:0:0:0:0\ne:2\n"), ErrorCode::kInvalidData,
                     {"Capture.txt:9:", "capturable 2 was a model"});
}

TEST(BadCapture, CutWithoutItsCamera) {
  expectCaptureError(handCapture("bad_cut", kHeader + "f:1:0\nc:1:respawn\nt:1:0:0:0:0:0:0\ne:1\n"), ErrorCode::kInvalidData,
                     {"Capture.txt:4:", "cut of camera 1", "no camera transform"});
  expectCaptureError(handCapture("bad_cut_fields", kHeader + "f:1:0\nt:1:0:0:0:0:0:0\nc:1\ne:1\n"), ErrorCode::kParse,
                     {"Capture.txt:5:", "needs 2 fields"});
}

TEST(BadCapture, TruncatedLastFrameIsAWarning) {
  const std::string cut = kHeader + kGoodFrame + "f:2:0.5\nt:1:0:0:1:0:0:0\nm:2:0:0:0:1:0:0";  // no newline, no e:2
  auto s = checkCapture(handCapture("bad_truncated", cut));
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->frames, 1u);
  ASSERT_EQ(s->warnings.size(), 1u);
  EXPECT_NE(s->warnings[0].find("Capture.txt:10:"), std::string::npos) << s->warnings[0];
  EXPECT_NE(s->warnings[0].find("frame 2 is dropped"), std::string::npos) << s->warnings[0];
  // Cut between records: the frame has no end record.
  auto t = checkCapture(handCapture("bad_truncated2", kHeader + kGoodFrame + "f:2:0.5\nt:1:0:0:1:0:0:0\n"));
  ASSERT_TRUE(t);
  EXPECT_EQ(t->frames, 1u);
  EXPECT_NE(t->warnings.at(0).find("frame 2 has no end record"), std::string::npos) << t->warnings[0];
}

TEST(BadCapture, OrderAndVersion) {
  expectCaptureError(handCapture("bad_version", "dynbench-capture:9\n"), ErrorCode::kParse, {"Capture.txt:1:", "version 9 is not supported"});
  expectCaptureError(handCapture("bad_version_header", "capture\n"), ErrorCode::kParse, {"Capture.txt:1:", "expected the version line"});
  // A version 1 capture (before the lights' range and the signed normals) is named as such.
  expectCaptureError(handCapture("old_version", "dynbench-capture:1\ns:hand\n" + kGoodFrame), ErrorCode::kParse,
                     {"Capture.txt:1:", "version 1 is not supported", "reads versions 2 and 3", "capture again"});
  expectCaptureError(handCapture("bad_order", kHeader + "f:2:0\ne:2\nf:1:1\ne:1\n"), ErrorCode::kInvalidData,
                     {"Capture.txt:5:", "frame numbers must increase"});
  expectCaptureError(handCapture("bad_nested", kHeader + "f:1:0\nf:2:0\n"), ErrorCode::kInvalidData, {"Capture.txt:4:", "before frame 1"});
}

TEST(BadCapture, LightRangeFalloffAndMapLighting) {
  const std::string light = "f:1:0\nl:5:0:1:0:1:0.5:0.25:{}:{}:point:0:none\ne:1\n";
  auto good = checkCapture(handCapture("light_range", kHeader + "L:1:2:2:0.8:0.8:0.7:0.1:0.1:0.1:0.4:0.4:0.5\n" + fmt::format(fmt::runtime(light), 40, "linear")));
  ASSERT_TRUE(good) << good.error().message;
  auto reader = CaptureReader::open(handCapture("light_range_read", kHeader + "L:1:2:2:0.8:0.8:0.7:0.1:0.1:0.1:0.4:0.4:0.5\n" +
                                                                         fmt::format(fmt::runtime(light), 40, "quadratic")));
  ASSERT_TRUE(reader) << reader.error().message;
  ASSERT_TRUE((*reader)->settings().lighting);
  const MapLighting& m = *(*reader)->settings().lighting;
  EXPECT_NEAR(m.sunDirection.y, 2.0 / 3.0, 1e-12);  // normalised
  EXPECT_EQ(m.sun, glm::dvec3(0.8, 0.8, 0.7));
  EXPECT_EQ(m.sky, glm::dvec3(0.4, 0.4, 0.5));
  CaptureFrame frame;
  ASSERT_TRUE((*reader)->next(frame));
  ASSERT_EQ(frame.lights.size(), 1u);
  EXPECT_EQ(frame.lights[0].range, 40.0);
  EXPECT_EQ(frame.lights[0].falloff, LightFalloff::kQuadratic);
  expectCaptureError(handCapture("bad_falloff", kHeader + fmt::format(fmt::runtime(light), 40, "cubic")), ErrorCode::kInvalidData,
                     {"Capture.txt:4:", "light falloff 'cubic'"});
  expectCaptureError(handCapture("bad_falloff_none", kHeader + fmt::format(fmt::runtime(light), 40, "none")), ErrorCode::kInvalidData,
                     {"Capture.txt:4:", "falloff exactly when it has a range"});
  expectCaptureError(handCapture("bad_range", kHeader + fmt::format(fmt::runtime(light), -1, "linear")), ErrorCode::kInvalidData,
                     {"Capture.txt:4:", "range must be 0 (none) or positive"});
  expectCaptureError(handCapture("bad_lighting", kHeader + "L:0:0:0:1:1:1:0:0:0:0:0:0\n"), ErrorCode::kInvalidData,
                     {"Capture.txt:3:", "a sun needs a direction"});
  expectCaptureError(handCapture("bad_lighting_fields", kHeader + "L:0:1:0:1:1:1\n"), ErrorCode::kParse, {"Capture.txt:3:", "needs 12 fields"});
}

// A mesh's material beyond its maps (ModelMesh version 3): what the SDK takes comes back from the
// reader; values out of range are refused by the SDK (nothing written) and by the reader (file:line).
TEST(Capture, MaterialRecordsAndVertexColoursRoundTrip) {
  const fs::path dir = freshDir("capture_materials");
  dbc_session* s = nullptr;
  ASSERT_EQ(dbc_open(dir.c_str(), "test", &s), DBC_OK) << dbc_last_error();
  const float positions[] = {0, 0, 0, 1, 0, 0, 1, 0, 1}, uvs[] = {0, 0, 1, 0, 1, 1};
  const float colors[] = {1, 1, 1, 1, 0.5f, 0.25f, 0, 0.5f, 0, 0, 0, 0};
  const float base[] = {0.2f, 0.4f, 0.6f, 1}, mr[] = {0, 0.05f}, emission[] = {1.5f, 0.75f, 0};
  const uint32_t tri[] = {0, 1, 2};
  ASSERT_EQ(dbc_model_begin(s, "map"), DBC_OK);
  dbc_mesh lava{};
  lava.name = "lava";
  lava.texture = lava.emission_texture = "lava.png";
  lava.vertex_count = 3;
  lava.positions = positions;
  lava.uvs = uvs;
  lava.triangle_count = 1;
  lava.indices = tri;
  lava.base_color = base;
  lava.metallic_roughness = mr;
  lava.emission = emission;
  lava.colors = colors;
  // Refused before anything is kept: a colour above 1, a negative emission, roughness above 1.
  const float tooBright[] = {1.5f, 1, 1, 1}, negative[] = {-1, 0, 0}, rough[] = {0, 2};
  for (int bad = 0; bad < 3; ++bad) {
    dbc_mesh b = lava;
    if (bad == 0) b.base_color = tooBright;
    if (bad == 1) b.emission = negative;
    if (bad == 2) b.metallic_roughness = rough;
    EXPECT_EQ(dbc_model_mesh(s, &b), DBC_ERROR_ARGUMENT) << bad;
  }
  dbc_mesh badVertex = lava;
  const float badColors[] = {1, 1, 1, 1, 1, 1, 1, -0.5f, 1, 1, 1, 1};
  badVertex.colors = badColors;
  EXPECT_EQ(dbc_model_mesh(s, &badVertex), DBC_ERROR_ARGUMENT);
  EXPECT_NE(std::string(dbc_last_error()).find("vertex 1"), std::string::npos) << dbc_last_error();
  ASSERT_EQ(dbc_model_mesh(s, &lava), DBC_OK) << dbc_last_error();
  ASSERT_EQ(dbc_model_end(s), DBC_OK);
  const uint64_t camera = dbc_new_id(s);
  for (int f = 0; f < 2; ++f) {
    ASSERT_EQ(dbc_frame_begin(s, static_cast<uint64_t>(f), f / 60.0), DBC_OK);
    ASSERT_EQ(dbc_camera(s, camera, positions, 0, 0, 0), DBC_OK);
    ASSERT_EQ(dbc_frame_end(s), DBC_OK);
  }
  ASSERT_EQ(dbc_close(s), DBC_OK);
  auto reader = CaptureReader::open(dir);
  ASSERT_TRUE(reader) << reader.error().message;
  ASSERT_EQ((*reader)->models().size(), 1u);
  const CapturedMesh& m = (*reader)->models()[0].meshes.at(0);
  EXPECT_EQ(m.texture, "lava.png");
  EXPECT_EQ(m.emissionTexture, "lava.png");
  EXPECT_EQ(m.baseColor, glm::vec4(0.2f, 0.4f, 0.6f, 1));
  ASSERT_TRUE(m.metallicRoughness);
  EXPECT_EQ(*m.metallicRoughness, glm::vec2(0, 0.05f));
  EXPECT_EQ(m.emission, glm::vec3(1.5f, 0.75f, 0));
  ASSERT_EQ(m.colors.size(), 3u);
  EXPECT_EQ(m.colors[1], glm::vec4(0.5f, 0.25f, 0, 0.5f));

  // The reader names the line of a value out of range, and of a missing vertex colour.
  fs::path file;
  for (const auto& e : fs::directory_iterator(dir / "models")) file = e.path();
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  auto rewrite = [&](const std::string& from, const std::string& to) {
    std::string changed = text;
    const auto at = changed.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    changed.replace(at, from.size(), to);
    std::ofstream(file, std::ios::trunc) << changed;
  };
  rewrite("e:0:1.5:", "e:0:-1.5:");
  expectCaptureError(dir, ErrorCode::kInvalidData, {file.filename().string() + ":", "emission must not be negative"});
  rewrite("c:0:0.5:0.25:0:0.5\n", "");
  expectCaptureError(dir, ErrorCode::kInvalidData, {file.filename().string(), "'c' records"});
  rewrite("f:0:0.2", "f:0:1.2");
  expectCaptureError(dir, ErrorCode::kInvalidData, {file.filename().string() + ":", "[0, 1]"});
}

TEST(BadCapture, BrokenModelMeshFile) {
  const auto dir = writeCapture("bad_modelmesh");
  fs::path file;
  for (const auto& e : fs::directory_iterator(dir / "models")) file = e.path();
  std::ofstream(file, std::ios::app) << "i:0:0:1:7\n";
  expectCaptureError(dir, ErrorCode::kInvalidData, {file.filename().string(), "triangles"});
}

// A model file checked against its own declarations at its end (checkModel): each broken one names
// the file, its last line and what disagrees.
TEST(BadCapture, ModelMeshDeclarationsAreChecked) {
  const std::vector<std::pair<std::string, std::string>> edits = {
      {"i:0:0:1:2\n", "i:0:0:1:7\n"},  // a vertex beyond the three declared
      {"p:0:1:0:0\n", ""},              // two positions for three vertices
      {"o:mapmodel/crate%3A1\n", ""},    // no name
  };
  const std::vector<std::string> expected = {"mesh 0 has a triangle using vertex 7 of 3", "mesh 0 declares 3 vertices but has 2 'p' records",
                                             "no 'o' record naming the model"};
  for (std::size_t k = 0; k < edits.size(); ++k) {
    const auto dir = writeCapture(fmt::format("bad_modelmesh_{}", k));
    fs::path file;
    for (const auto& e : fs::directory_iterator(dir / "models"))
      if (test::slurp(e.path()).find("o:mapmodel/crate%3A1\n") != std::string::npos) file = e.path();
    ASSERT_FALSE(file.empty()) << "the crate's model file";
    std::string text = test::slurp(file);
    const auto at = text.find(edits[k].first);
    ASSERT_NE(at, std::string::npos) << edits[k].first;
    text.replace(at, edits[k].first.size(), edits[k].second);
    std::ofstream(file, std::ios::trunc) << text;
    expectCaptureError(dir, ErrorCode::kInvalidData, {file.filename().string() + ":", expected[k]});
  }
}

}  // namespace
}  // namespace dynbench::capture
