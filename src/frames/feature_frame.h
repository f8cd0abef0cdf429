#pragma once
// The feature-buffer contract (ARCHITECTURE §3, docs/feature-buffers.md), in one place: the
// channels, the frame_NNNNN naming, the camera sidecar, reading and writing a frame, and the
// preview tone mapping. Every renderer writes through it and every consumer (discard, report,
// evaluation) reads through it, so the contract cannot drift between them.
#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace dynbench::frames {

// The camera a frame was rendered with, as its sidecar records it. Matrices map as glTF/OpenGL:
// clip = projection * view * world_point; `world` is the camera's rigid transform (view's inverse).
struct FrameCamera {
  glm::dmat4 world{1.0}, view{1.0}, projection{1.0};
  glm::dvec3 position{0.0};
  double yfov = 0.0;   // radians
  double znear = 0.0, zfar = 0.0;  // dataset length units
  int width = 0, height = 0;       // pixels
  // Sub-pixel offset of every pixel's sample from its centre (render --jitter), in pixels (+x
  // right, +y down); `projection` is the unjittered one. {0, 0} without jitter.
  glm::dvec2 jitter{0.0};
};

// render --jitter's offset for a frame: the Halton (2, 3) sequence at index 1 + (frame mod 8),
// minus 0.5, so that eight consecutive frames cover the pixel evenly (the sequence real-time TAA
// uses, e.g. Unreal Engine 4; Karis 2014). In pixels, in [-0.5, 0.5).
glm::dvec2 jitterOffset(long frame);

// How a frame's radiance was sampled (the sidecar's `sampling` object; docs/feature-buffers.md).
struct SamplingSummary {
  bool adaptive = false;              // render --converge
  double tolerance = 0.0;             // --tolerance: a fraction of the discard threshold
  double directTarget = 0.0, indirectTarget = 0.0;  // standard-error targets (luminance, cd/m2)
  int minSamples = 0, maxSamples = 0;  // samples per pixel, smallest and largest in the frame
  double meanSamples = 0.0;
  long cappedPixels = 0;               // pixels that reached --max-spp before their target
  int lightsPerPoint = 0;              // point and spot lights evaluated per shading point at most (0: all)
  // Radiance-change pairs (render --pairs; 0 when the frame has none): the cap on a pixel's pairs,
  // the mean and largest count, and the pixels still undecided at the cap for direct or indirect
  // (at the thresholds the render estimated; discard decides again at its own).
  int pairCap = 0, maxPairs = 0;
  double meanPairs = 0.0;
  long undecidedPixels = 0;
};

// One frame's buffers: row 0 at the top, channels of a buffer interleaved per pixel. A buffer the
// renderer did not produce is empty (Cycles writes no id, motion or variance).
struct FeatureFrame {
  long frame = 0;
  double time = 0.0;  // seconds, dataset clock
  FrameCamera camera;
  int width = 0, height = 0;
  std::vector<float> position, normal, direct, indirect, albedo;  // 3 per pixel
  std::vector<float> depth, id, hit;                              // 1 per pixel
  std::vector<float> motion;                                      // 2 per pixel
  std::vector<float> directVariance, indirectVariance;            // 1 per pixel
  std::vector<float> spp;                                         // 1 per pixel: samples taken
  // Radiance change from the previous frame by correlated re-shading (frames/radiance_change.h,
  // docs/feature-buffers.md), where the renderer made pairs: per pixel, for the luminance of each
  // of direct and indirect, the pairs' mean difference Y_t - Y_{t-1}, its standard error and the
  // mean |Y_t| + |Y_{t-1}| the halves' paths gathered (3 per pixel, in that order); and how many
  // pairs (1 per pixel).
  std::vector<float> directChange, indirectChange;
  std::vector<float> changePairs;
  std::optional<SamplingSummary> sampling;                        // the sidecar's `sampling`
  // The sidecar's `cut`: the camera jumped between the previous frame and this one (a respawn or
  // a switch of the followed player), so temporal methods start their history again here.
  bool cut = false;

  std::size_t pixelCount() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  bool hasVariance() const { return !directVariance.empty() && !indirectVariance.empty(); }
  bool hasChanges() const { return !directChange.empty() && !indirectChange.empty() && !changePairs.empty(); }
  // Sizes every buffer of the contract for width x height, zero-filled (those made on request, the
  // radiance-change pairs, stay empty: a frame without them must not look as if it had them).
  void resize(int width, int height);
};

// How a buffer is stored on disk (docs/feature-buffers.md, "Precision on disk"). Readers need not
// know: EXR channels carry their type and every reader gets floats.
enum class Storage {
  kFloat32,          // always 32-bit (world position, depth, motion)
  kFloat16,          // 16-bit half: relative error <= 2^-11; 32-bit in a frame where a finite value
                     // exceeds the buffer's halfLimit, so nothing overflows and the absolute error
                     // stays <= halfLimit x 2^-12
  kFloat16WhenExact  // 16-bit when every value of the frame is exact in half (0/1 flags, small
                     // integers such as node ids below 2048), else 32-bit: lossless either way
};

// A buffer of the contract: its EXR channel names and where it lives in FeatureFrame.
struct BufferSpec {
  const char* name;                 // "direct"
  std::vector<std::string> channels;  // {"direct.R", "direct.G", "direct.B"}
  std::vector<float> FeatureFrame::*member;
  bool required;                    // every frames folder has it
  Storage storage;
  float halfLimit = 65504.0f;       // kFloat16: the largest magnitude stored as half (65504: half's largest)
  bool onRequest = false;           // made only when asked for (FeatureFrame::resize leaves it empty)
};

// The contract's buffers in the order dynbench writes them (P N direct indirect albedo Z id
// motion direct.var indirect.var hit spp change.direct change.indirect change.pairs).
const std::vector<BufferSpec>& contractBuffers();
// Every channel name of the contract, in that order.
std::vector<std::string> contractChannelNames();

// frame_NNNNN.exr and frame_NNNNN.json in `dir` (NNNNN: at least five digits, zero-padded).
std::filesystem::path frameImagePath(const std::filesystem::path& dir, long frame);
std::filesystem::path frameSidecarPath(const std::filesystem::path& dir, long frame);

}  // namespace dynbench::frames
