#pragma once
// Rates every stage defaults to, in one home.
namespace dynbench {

// Frames per second at which a dataset is sampled (stats, render, discard, the cameras' checks) unless
// told otherwise: the thesis's 24 (its Tables 6.4-6.7 are per frame at 24 fps).
inline constexpr double kDefaultFrameRate = 24.0;

// Key frames per second of an OBJ sequence, whose files carry no times: one file a frame at 24 fps.
inline constexpr double kDefaultSequenceRate = 24.0;

}  // namespace dynbench
