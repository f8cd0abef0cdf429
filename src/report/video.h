#pragma once
// A run's motion as a video for the report: each frame's radiance (direct + indirect, tone-mapped
// with one exposure for the whole clip) beside the discard mask of the pair that ends at it,
// encoded as VP9 WebM (Chromium plays it) by Debian's ffmpeg. This is the only place that runs
// ffmpeg.
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "frames/frame_io.h"
#include "frames/preview.h"

namespace dynbench::report {

// One exposure for a set of frames: the median of the frames' own preview exposures (their mean
// luminance to middle grey, frames/preview.h), over at most `sampleFrames` evenly spaced frames.
Expected<frames::PreviewToneMap> clipToneMap(const std::vector<frames::FrameEntry>& frames, int sampleFrames = 16);

// How the frames' radiance was sampled, from their sidecars: "converged (render --converge, tolerance
// 0.5): 16-512 spp per pixel, mean 495" over adaptive renders (smallest, largest, mean of the
// frames' means), "8 spp" for a fixed count.
Expected<std::string> samplingNote(const std::vector<frames::FrameEntry>& frames);

struct VideoOptions {
  int maxFrames = 240;          // the first this many frames of the folder (10 s at 24 fps)
  int maxWidth = 1280;          // wider videos (frame and mask side by side) are scaled down to this; smaller
                                // ones keep their pixels (the page enlarges them, which costs no bytes)
  int crf = 32;                 // VP9 constant quality (0-63, lower is better)
};

struct Video {
  std::filesystem::path file;   // .webm
  long firstFrame = 0, lastFrame = 0;
  int frames = 0;               // encoded frames
  int width = 0, height = 0;    // the video's size in pixels
  double fps = 0.0;             // from the sidecars' times (24 when there is one frame)
  bool masks = false;           // the right half shows discard masks
};

// The size ffmpeg gives a video of frames `width` x `height` (doubled in width with masks): reduced
// to options.maxWidth when wider.
void videoSize(int width, int height, bool masks, const VideoOptions& options, int& outWidth, int& outHeight);

// Writes `out` (through a temporary name). `masksDir` holds discard_NNNNN.png (discard --masks);
// empty or absent: the video is the frames alone. A frame without a mask (the first, a camera cut)
// shows a grey panel. Needs `ffmpeg` on PATH (Debian package ffmpeg; scripts/setup.sh).
Expected<Video> writeRunVideo(const std::vector<frames::FrameEntry>& frames, const std::filesystem::path& masksDir,
                              const frames::PreviewToneMap& toneMap, const std::filesystem::path& out, const VideoOptions& options = {});

}  // namespace dynbench::report
