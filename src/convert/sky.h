#pragma once
// The default environment of a dataset: an analytic clear daylight sky with a sun, as an
// equirectangular HDR image (docs/dataset.md, "Environment").
//
// Sky: Preetham, Shirley and Smits, "A Practical Analytic Model for Daylight", SIGGRAPH 1999:
// luminance and chromaticity from the Perez distribution F(θ, γ) = (1 + A e^{B / cos θ})
// (1 + C e^{D γ} + E cos² γ), scaled to the zenith values, as functions of turbidity T.
// Sun: direct normal illuminance from the ESRA clear-sky model (Rigollier, Bauer and Wald 2000),
// B_n = I_0 exp(-0.8662 T m δ_R(m)), with Kasten-Young air mass m, turned to lux with a luminous
// efficacy of 93 lm/W, spread evenly over the pixels of the sun's disc.
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "core/math.h"

namespace dynbench::convert {

// The turbidity convert accepts: 1.7 (very clear) to 10 (hazy).
inline constexpr std::pair<double, double> kTurbidityRange{1.7, 10.0};

struct SkyParameters {
  double turbidity = 3.0;             // kTurbidityRange: very clear to hazy
  double sunElevationDegrees = 45.0;  // above the horizon
  double sunAzimuthDegrees = 135.0;   // from -Z (the image centre) towards +X
  int width = 1024;                   // equirectangular: height = width / 2
  bool sunDisc = true;                // false: the sky dome alone (a map the engine lights without a sun)
  bool dome = true;                   // false: no sky dome, black but the sun disc (an engine whose sky gives no light but its sun)
};

struct SkyImage {
  int width = 0, height = 0;
  std::vector<float> rgb;            // linear Rec.709 RGB, luminance in cd/m², top row = up (+Y)
  glm::dvec3 sunDirection{0.0};      // towards the sun
  double sunIlluminanceLux = 0.0;    // direct normal illuminance of the sun disc
  double zenithLuminance = 0.0;      // cd/m², Preetham's Y_z
};

SkyImage preethamSky(const SkyParameters& parameters);

// Illuminance (lux) of a horizontal surface open to the whole upper hemisphere of an
// equirectangular image (luminance x cos(theta) x solid angle, summed over the pixels above the
// horizon), with the pixels within `excludeRadians` of `excludeDirection` left out (a sun disc).
double horizontalIlluminance(const std::vector<float>& rgb, int width, int height, glm::dvec3 excludeDirection = glm::dvec3(0.0),
                             double excludeRadians = 0.0);

// Elevation and azimuth (degrees, SkyParameters' convention) of a direction towards the sun.
std::pair<double, double> sunAngles(const glm::dvec3& towardsSun);

// The equirectangular mapping (equirectDirection, equirectPixelSolidAngle) is in core/math.h:
// the renderer reads the same images.
using dynbench::equirectDirection;
using dynbench::equirectPixelSolidAngle;

}  // namespace dynbench::convert
