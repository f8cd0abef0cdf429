// Temporal methods and the evaluate harness (evaluate/method.h, evaluate/evaluate.h) on synthetic
// frames with known noise: a static camera looking at a plane.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "evaluate/evaluate.h"
#include "evaluate/method.h"
#include "frames/frame_io.h"

namespace dynbench::evaluate {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 64, kH = 48;
constexpr double kSigma = 0.2;  // the input's noise, per pixel and channel

// The true radiance of a pixel: a smooth pattern around 1.
glm::dvec3 truth(int x, int y) { return glm::dvec3(1.0 + 0.3 * std::sin(0.2 * x), 0.8 + 0.2 * std::cos(0.15 * y), 0.6); }

// Frame `index` of a static camera at the origin looking down -Z at the plane z = -5; the direct
// radiance is the truth plus Gaussian noise of standard deviation `sigma` (0: the reference).
// Frame `index` (at 24 fps) of w x h pixels, zero-filled, seen by a static camera at the origin
// looking down -Z (60 degrees vertical field of view).
frames::FeatureFrame staticCameraFrame(long index, int w, int h) {
  frames::FeatureFrame f;
  f.frame = index;
  f.time = index / 24.0;
  f.resize(w, h);
  frames::FrameCamera& c = f.camera;
  c.view = glm::lookAt(glm::dvec3(0.0), glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0));
  c.world = glm::inverse(c.view);
  c.projection = glm::perspective(glm::radians(60.0), static_cast<double>(w) / h, 0.1, 100.0);
  c.yfov = glm::radians(60.0), c.znear = 0.1, c.zfar = 100.0, c.width = w, c.height = h;
  return f;
}

frames::FeatureFrame planeFrame(long index, double sigma, std::uint32_t seed) {
  frames::FeatureFrame f = staticCameraFrame(index, kW, kH);
  const frames::FrameCamera& c = f.camera;
  std::mt19937 rng(seed * 7919u + static_cast<std::uint32_t>(index));
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * kW + x;
      const glm::dvec3 d = reprojection::pixelDirection(c, x + 0.5, y + 0.5);
      const glm::dvec3 p = d * (5.0 / -d.z);
      for (int k = 0; k < 3; ++k) {
        f.position[3 * i + k] = static_cast<float>(p[k]);
        f.normal[3 * i + k] = k == 2 ? 1.0f : 0.0f;
        f.albedo[3 * i + k] = 0.5f;
        f.direct[3 * i + k] = static_cast<float>(truth(x, y)[k] + (sigma > 0 ? noise(rng) * sigma : 0.0));
      }
      f.depth[i] = 5.0f, f.id[i] = 0.0f, f.hit[i] = 1.0f;
    }
  return f;
}

double mseAgainstTruth(const RgbImage& image) {
  double sum = 0.0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int k = 0; k < 3; ++k) {
        const double d = image.rgb[3 * (static_cast<std::size_t>(y) * kW + x) + k] - truth(x, y)[k];
        sum += d * d;
      }
  return sum / (3.0 * kW * kH);
}

// The registry is the one list of built-in methods: every entry makes the method of its name,
// the defaults are its names in order, and an unknown name's error lists them all.
TEST(Methods, TheRegistryMakesEachMethodAndListsThemAll) {
  const auto& methods = builtInMethods();
  ASSERT_EQ(methods.size(), 4u);
  std::vector<std::string> names;
  for (const auto& m : methods) {
    auto made = createMethod(std::string(m.name), MethodContext{});
    ASSERT_TRUE(made) << m.name;
    EXPECT_EQ((*made)->name(), m.name);
    EXPECT_FALSE(m.description.empty());
    names.emplace_back(m.name);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"none", "accumulate", "taa", "svgf"}));
  EXPECT_EQ(EvaluateOptions{}.methods, names);
  const auto unknown = createMethod("bogus", MethodContext{});
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().code, ErrorCode::kUsage);
  EXPECT_NE(unknown.error().message.find("none, accumulate, taa, svgf, external:DIR"), std::string::npos) << unknown.error().message;
}

TEST(Methods, AccumulateErrorFallsAsOneOverSqrtNOnAStaticScene) {
  // With alpha = max(1/n, 0.1) and every history kept, the output after n <= 10 frames is the mean
  // of n independent frames: variance sigma^2 / n. After that each frame gives
  // v' = (1 - 0.1)^2 v + 0.1^2 sigma^2, which tends to sigma^2 x 0.01 / 0.19 (= 0.0526 sigma^2).
  // The measured MSE averages P = 3 x 64 x 48 independent squared Gaussians, so its relative
  // standard deviation is sqrt(2 / P) = 1.47 %; 4 of those (5.9 %) bound each frame's ratio.
  MethodContext context;
  context.sceneSize = discard::sceneSize(planeFrame(0, 0.0, 1));
  auto method = createMethod("accumulate", context);
  ASSERT_TRUE(method.has_value());
  (*method)->reset();
  const double bound = 4.0 * std::sqrt(2.0 / (3.0 * kW * kH));
  double expected = kSigma * kSigma;
  for (int n = 1; n <= 30; ++n) {
    if (n > 1) expected = n <= 10 ? kSigma * kSigma / n : 0.81 * expected + 0.01 * kSigma * kSigma;
    auto out = (*method)->process(planeFrame(n, kSigma, 1));
    ASSERT_TRUE(out.has_value());
    EXPECT_NEAR(out->historyUse.value_or(-1), n == 1 ? 0.0 : 1.0, 1e-12) << "frame " << n;
    const double ratio = mseAgainstTruth(out->image) / expected;
    EXPECT_NEAR(ratio, 1.0, bound) << "frame " << n << ": MSE " << mseAgainstTruth(out->image) << ", expected " << expected;
  }
}

TEST(Methods, TaaAndSvgfReduceNoiseOnAStaticScene) {
  // Not a bound, a sanity floor: after 16 frames both must be well below the input's noise.
  for (const char* name : {"taa", "svgf"}) {
    auto method = createMethod(name, MethodContext{});
    ASSERT_TRUE(method.has_value());
    double mse = 0.0;
    for (int n = 1; n <= 16; ++n) {
      auto out = (*method)->process(planeFrame(n, kSigma, 2));
      ASSERT_TRUE(out.has_value());
      mse = mseAgainstTruth(out->image);
    }
    EXPECT_LT(mse, 0.5 * kSigma * kSigma) << name;
  }
  EXPECT_FALSE(createMethod("bogus", MethodContext{}).has_value());
  EXPECT_FALSE(createMethod("external:/no/such/dir", MethodContext{}).has_value());
}

TEST(Methods, SvgfReturnsAConstantIlluminationUnderAnyAlbedoAtAnyWidth) {
  // Known answer: radiance = demodulating albedo (0.96 base + 0.04) x a constant illumination, so
  // the demodulated image is constant, every filter's weighted mean of it is that constant, and the
  // remodulated output is the input radiance. A width of 37 (not a multiple of any SIMD width)
  // exercises the row's last partial vector; pixels that hit nothing pass their radiance through.
  constexpr int w = 37, h = 11;
  const glm::vec3 illumination(1.3f, 0.9f, 0.4f);
  auto frame = [&](long index) {
    frames::FeatureFrame f = staticCameraFrame(index, w, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        const bool sky = x == w - 1 && y % 3 == 0;
        for (int k = 0; k < 3; ++k) {
          const float base = 0.2f + 0.7f * static_cast<float>((x * 7 + y * 3 + k * 5) % 11) / 10.0f;
          f.albedo[3 * i + k] = base;
          f.normal[3 * i + k] = k == 2 && !sky ? 1.0f : 0.0f;
          f.direct[3 * i + k] = sky ? 2.0f + k : (0.96f * base + 0.04f) * illumination[k];
        }
        f.depth[i] = sky ? 0.0f : 5.0f, f.hit[i] = sky ? 0.0f : 1.0f;
      }
    return f;
  };
  auto method = createMethod("svgf", MethodContext{});
  ASSERT_TRUE(method.has_value());
  for (long n = 1; n <= 3; ++n) {  // the first frame (no history) and two with history
    const frames::FeatureFrame f = frame(n);
    auto out = (*method)->process(f);
    ASSERT_TRUE(out.has_value());
    double worst = 0.0;
    for (std::size_t j = 0; j < f.direct.size(); ++j) worst = std::max(worst, std::abs(out->image.rgb[j] / f.direct[j] - 1.0));
    EXPECT_LT(worst, 1e-5) << "frame " << n;
  }
}

// Stripes with sharp edges across the image, 1.65 pixels wide: finer than a pixel can resolve, so
// a sample at a pixel's centre aliases and the pixel's integral is a blend.
double stripes(double x, double y) {
  const double u = (x + 0.6 * y) / 3.3;
  return u - std::floor(u) < 0.5 ? 1.5 : 0.5;
}

TEST(Methods, CatmullRomHistoryInterpolatesAndKeepsConstants) {
  RgbImage image{5, 4, std::vector<float>(3 * 5 * 4)};
  for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = static_cast<float>((i * 7919) % 13) / 13.0f;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) {
      const glm::dvec3 at = sampleCatmullRom(image, x + 0.5, y + 0.5);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(at[k], image.rgb[3 * (static_cast<std::size_t>(y) * 5 + x) + k], 1e-12) << x << "," << y;
    }
  RgbImage flat{5, 4, std::vector<float>(3 * 5 * 4, 0.25f)};
  EXPECT_NEAR(sampleCatmullRom(flat, 2.3, 1.7).x, 0.25, 1e-12);
  // A linear ramp is reproduced between the centres (Catmull-Rom is exact on linear data).
  RgbImage ramp{8, 1, std::vector<float>(3 * 8)};
  for (int x = 0; x < 8; ++x)
    for (int k = 0; k < 3; ++k) ramp.rgb[3 * static_cast<std::size_t>(x) + k] = static_cast<float>(x);
  EXPECT_NEAR(sampleCatmullRom(ramp, 3.8, 0.5).x, 3.3, 1e-6);
}

TEST(Methods, TaaTurnsJitteredSamplesIntoThePixelsIntegral) {
  // A static camera over a static scene of sharp stripes, with jittered input (render --jitter:
  // frame n samples each pixel at its centre + the Halton (2, 3) offset of n) and no noise: `none`
  // shows the aliased point samples, while TAA's exponential history averages the jitter
  // positions towards the pixel's integral (the reference: a 16 x 16 box average over the pixel).
  // The bound: with blend a = 0.1, frame n's output weighs frame n - k by a (1 - a)^k and the
  // first frame by (1 - a)^(n-1). Were the samples' errors against the integral independent with
  // variance v, the output's mean squared error would be v S(n),
  //   S(n) = (1 - a)^(2(n-1)) + a^2 (1 - (1 - a)^(2(n-1))) / (1 - (1 - a)^2),
  // falling from 1 to a / (2 - a) = 0.053 (S(3) = 0.67, S(8) = 0.27). Halton offsets are
  // stratified, which only helps an average; the variance clip adds a bias where a pixel's 3 x 3
  // samples all lie on one side of an edge its area crosses (the box then excludes the blend),
  // bounded here by 0.1 v. v is none's error averaged over the 8 jitter phases (a single
  // frame's error depends on its phase).
  auto frameAt = [](long n, bool reference) {
    frames::FeatureFrame f = planeFrame(n, 0.0, 1);
    f.camera.jitter = reference ? glm::dvec2(0.0) : frames::jitterOffset(n);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        double value = 0.0;
        if (reference) {
          for (int sy = 0; sy < 16; ++sy)
            for (int sx = 0; sx < 16; ++sx) value += stripes(x + (sx + 0.5) / 16, y + (sy + 0.5) / 16) / 256.0;
        } else {
          value = stripes(x + 0.5 + f.camera.jitter.x, y + 0.5 + f.camera.jitter.y);
        }
        const std::size_t i = static_cast<std::size_t>(y) * kW + x;
        for (int k = 0; k < 3; ++k) f.direct[3 * i + k] = static_cast<float>(value);
      }
    return f;
  };
  const RgbImage reference = frameRadiance(frameAt(0, true));
  auto mse = [&](const RgbImage& image) {
    double sum = 0.0;
    for (std::size_t i = 0; i < image.rgb.size(); ++i) sum += std::pow(image.rgb[i] - reference.rgb[i], 2);
    return sum / static_cast<double>(image.rgb.size());
  };
  auto none = createMethod("none", MethodContext{}), taa = createMethod("taa", MethodContext{});
  ASSERT_TRUE(none && taa);
  constexpr int kFrames = 10;
  double errorNone[kFrames + 1] = {}, errorTaa[kFrames + 1] = {}, v = 0.0;
  for (int n = 1; n <= kFrames; ++n) {
    const frames::FeatureFrame input = frameAt(n, false);
    auto a = (*none)->process(input), b = (*taa)->process(input);
    ASSERT_TRUE(a && b);
    errorNone[n] = mse(a->image), errorTaa[n] = mse(b->image);
    if (n <= 8) v += errorNone[n] / 8.0;
  }
  const double a = 0.1;
  auto S = [a](int n) {
    const double decay = std::pow(1.0 - a, 2.0 * (n - 1));
    return decay + a * a * (1.0 - decay) / (1.0 - (1.0 - a) * (1.0 - a));
  };
  for (int n = 1; n <= kFrames; ++n) {
    const double bound = v * (S(n) + 0.1);
    std::printf("frame %d: MSE none %.5f, taa %.5f (bound %.5f)\n", n, errorNone[n], errorTaa[n], bound);
    if (n >= 2) EXPECT_LT(errorTaa[n], errorNone[n]) << "frame " << n;
    EXPECT_LT(errorTaa[n], bound) << "frame " << n;
  }
  // And it keeps falling through the 8 jitter phases: around frame 8 (frames 7-9) at most
  // (S(8) + 0.1) / S(3) of its error around frame 2 (frames 2-3), what the bound allows.
  EXPECT_LT((errorTaa[7] + errorTaa[8] + errorTaa[9]) / 3.0, (S(8) + 0.1) / S(3) * (errorTaa[2] + errorTaa[3]) / 2.0);
}

fs::path writeSequence(const std::string& name, double sigma, long cutAt, int count) {
  const fs::path dir = fs::temp_directory_path() / ("dynbench_evaluate_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (int n = 0; n < count; ++n) {
    frames::FeatureFrame f = planeFrame(100 + n, sigma, 3);
    f.cut = (100 + n) == cutAt;
    EXPECT_TRUE(frames::writeFrame(dir, f, nlohmann::json{{"engine", "test"}}, frames::WriteOptions{.float32 = true}).has_value());
  }
  return dir;
}

TEST(Evaluate, HistoryUseIsZeroAtCutsAndScoresAreDeterministic) {
  const fs::path noisy = writeSequence("noisy", kSigma, 104, 8), reference = writeSequence("reference", 0.0, -1, 8);
  EvaluateOptions o;
  o.frames = noisy, o.reference = reference;
  o.methods = {"none", "accumulate", "taa", "svgf"};
  o.json = noisy / "eval.json", o.outDir = noisy / "out";
  auto run = runEvaluate(o);
  ASSERT_TRUE(run.has_value()) << run.error().message;
  ASSERT_EQ(run->methods.size(), 4u);
  for (const MethodScores& m : run->methods) {
    ASSERT_EQ(m.frames.size(), 8u);
    for (const FrameScores& s : m.frames) {
      const bool cut = s.frame == 100 || s.frame == 104;
      EXPECT_EQ(s.cut, cut) << m.name << " frame " << s.frame;
      ASSERT_TRUE(s.historyUse.has_value());
      if (cut || m.name == "none") {
        EXPECT_EQ(*s.historyUse, 0.0) << m.name << " frame " << s.frame;
        EXPECT_FALSE(s.tPsnr.has_value() && cut);
      } else {
        EXPECT_GT(*s.historyUse, 0.9) << m.name << " frame " << s.frame;
      }
    }
    if (m.name != "none") EXPECT_LT(m.flip.mean, run->methods[0].flip.mean) << m.name << " is no better than the input";
  }
  // Deterministic: a second run writes the same JSON.
  const std::string first = nlohmann::json::parse(std::ifstream(o.json)).dump();
  auto again = runEvaluate(o);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(o.json)).dump(), first);
  // The outputs under --out follow the external contract: scored again as external:DIR they give
  // the built-in method's scores.
  EvaluateOptions external = o;
  external.methods = {"external:" + (o.outDir / "svgf").string()};
  external.json.clear(), external.outDir.clear();
  auto rescored = runEvaluate(external);
  ASSERT_TRUE(rescored.has_value()) << rescored.error().message;
  EXPECT_NEAR(rescored->methods[0].flip.mean, run->methods[3].flip.mean, 1e-6);
  EXPECT_NEAR(rescored->methods[0].relMse.mean, run->methods[3].relMse.mean, 1e-6);
  EXPECT_FALSE(rescored->methods[0].frames[1].historyUse.has_value());
  EXPECT_TRUE(fs::exists(o.outDir / "svgf" / "flip_worst.png"));
  // The JSON reads back.
  auto read = readEvaluateJson(o.json);
  ASSERT_TRUE(read.has_value()) << read.error().message;
  EXPECT_EQ(read->methods[2].name, "taa");
  EXPECT_NEAR(read->methods[2].flip.mean, run->methods[2].flip.mean, 1e-12);
}

TEST(Evaluate, BadInputsGiveClearErrors) {
  const fs::path noisy = writeSequence("bad_noisy", kSigma, -1, 3), reference = writeSequence("bad_reference", 0.0, -1, 2);
  EvaluateOptions o;
  o.frames = noisy, o.reference = reference, o.methods = {"none"};
  auto run = runEvaluate(o);
  ASSERT_FALSE(run.has_value());
  EXPECT_NE(run.error().message.find("no reference for frame 102"), std::string::npos) << run.error().message;
  o.reference = noisy, o.methods = {"median"};
  run = runEvaluate(o);
  ASSERT_FALSE(run.has_value());
  EXPECT_NE(run.error().message.find("unknown method 'median'"), std::string::npos) << run.error().message;
  const fs::path bad = noisy / "bad.json";
  std::ofstream(bad) << R"({"format": "dynbench-evaluate", "methods": [{"name": "none", "mean": {"flip": {"mean": "x"}}}]})";
  auto read = readEvaluateJson(bad);
  ASSERT_FALSE(read.has_value());
  EXPECT_NE(read.error().message.find("/methods/0/mean/flip/mean: expected a number"), std::string::npos) << read.error().message;
}

}  // namespace
}  // namespace dynbench::evaluate
