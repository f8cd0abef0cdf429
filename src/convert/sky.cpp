#include "convert/sky.h"

#include <algorithm>
#include <cmath>

#include "core/math.h"

namespace dynbench::convert {
namespace {

struct Perez {
  double A, B, C, D, E;
  double operator()(double theta, double gamma) const {
    return (1.0 + A * std::exp(B / std::max(std::cos(theta), 0.01))) *
           (1.0 + C * std::exp(D * gamma) + E * std::cos(gamma) * std::cos(gamma));
  }
};

// Preetham 1999, Appendix A.2: the distribution coefficients as linear functions of turbidity.
Perez luminanceCoefficients(double T) { return {0.1787 * T - 1.4630, -0.3554 * T + 0.4275, -0.0227 * T + 5.3251, 0.1206 * T - 2.5771, -0.0670 * T + 0.3703}; }
Perez xCoefficients(double T) { return {-0.0193 * T - 0.2592, -0.0665 * T + 0.0008, -0.0004 * T + 0.2125, -0.0641 * T - 0.8989, -0.0033 * T + 0.0452}; }
Perez yCoefficients(double T) { return {-0.0167 * T - 0.2608, -0.0950 * T + 0.0092, -0.0079 * T + 0.2102, -0.0441 * T - 1.6537, -0.0109 * T + 0.0529}; }

// Zenith chromaticity: a cubic in the sun's zenith angle, quadratic in turbidity (Appendix A.2).
double zenithChromaticity(const double m[3][4], double T, double thetaS) {
  const double t[4] = {thetaS * thetaS * thetaS, thetaS * thetaS, thetaS, 1.0};
  const double w[3] = {T * T, T, 1.0};
  double sum = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) sum += w[i] * m[i][j] * t[j];
  return sum;
}

glm::dvec3 xyYToLinearRgb(double x, double y, double Y) {
  const double X = x * Y / y, Z = (1.0 - x - y) * Y / y;
  // CIE XYZ to linear Rec.709 / sRGB primaries, D65 white.
  return {3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z, -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z,
          0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z};
}

}  // namespace

SkyImage preethamSky(const SkyParameters& p) {
  SkyImage sky;
  sky.width = std::max(8, p.width);
  sky.height = sky.width / 2;
  sky.rgb.assign(static_cast<std::size_t>(sky.width) * sky.height * 3, 0.0f);
  const double T = p.turbidity;
  const double elevation = radians(std::clamp(p.sunElevationDegrees, 0.0, 90.0));
  const double thetaS = kPi / 2 - elevation;
  const double azimuth = radians(p.sunAzimuthDegrees);
  sky.sunDirection = {std::cos(elevation) * std::sin(azimuth), std::sin(elevation), -std::cos(elevation) * std::cos(azimuth)};

  // Zenith values (Preetham eq. in A.2); Y_z in kcd/m².
  const double chi = (4.0 / 9.0 - T / 120.0) * (kPi - 2.0 * thetaS);
  sky.zenithLuminance = 1000.0 * ((4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192);
  static const double mx[3][4] = {{0.00166, -0.00375, 0.00209, 0.0}, {-0.02903, 0.06377, -0.03202, 0.00394}, {0.11693, -0.21196, 0.06052, 0.25886}};
  static const double my[3][4] = {{0.00275, -0.00610, 0.00317, 0.0}, {-0.04214, 0.08970, -0.04153, 0.00516}, {0.15346, -0.26756, 0.06670, 0.26688}};
  const double xz = zenithChromaticity(mx, T, thetaS), yz = zenithChromaticity(my, T, thetaS);
  const Perez fY = luminanceCoefficients(T), fx = xCoefficients(T), fy = yCoefficients(T);
  const double nY = fY(0.0, thetaS), nx = fx(0.0, thetaS), ny = fy(0.0, thetaS);

  // The ground below the horizon: grey, albedo 0.2, lit like the horizon above it.
  constexpr double kGroundAlbedo = 0.2;
  for (int row = 0; row < (p.dome ? sky.height : 0); ++row) {
    for (int col = 0; col < sky.width; ++col) {
      const glm::dvec3 d = equirectDirection((col + 0.5) / sky.width, (row + 0.5) / sky.height);
      const bool ground = d.y < 0.0;
      const glm::dvec3 view = ground ? glm::normalize(glm::dvec3(d.x, 0.001, d.z)) : d;
      const double theta = std::acos(std::clamp(view.y, -1.0, 1.0));
      const double gamma = std::acos(std::clamp(glm::dot(view, sky.sunDirection), -1.0, 1.0));
      const double Y = sky.zenithLuminance * fY(theta, gamma) / nY;
      const double x = xz * fx(theta, gamma) / nx, y = yz * fy(theta, gamma) / ny;
      glm::dvec3 rgb = glm::max(xyYToLinearRgb(x, y, Y), glm::dvec3(0.0));
      if (ground) rgb = glm::dvec3(kGroundAlbedo * Y * 0.5);  // grey: albedo x horizon luminance x ~1/2 sky seen
      float* px = &sky.rgb[(static_cast<std::size_t>(row) * sky.width + col) * 3];
      px[0] = static_cast<float>(rgb.r);
      px[1] = static_cast<float>(rgb.g);
      px[2] = static_cast<float>(rgb.b);
    }
  }

  // The sun: direct normal illuminance (ESRA), over a disc of the sun's angular radius (0.2665°),
  // widened to 1.5 pixels so that the image resolves it; radiance = illuminance / disc solid angle.
  const double zenithDegrees = degrees(thetaS);
  const double airMass = 1.0 / (std::cos(thetaS) + 0.50572 * std::pow(96.07995 - zenithDegrees, -1.6364));
  const double rayleigh = 1.0 / (6.6296 + 1.7513 * airMass - 0.1202 * airMass * airMass + 0.0065 * std::pow(airMass, 3) -
                                 0.00013 * std::pow(airMass, 4));
  const double directNormal = 1361.0 * std::exp(-0.8662 * T * airMass * rayleigh);  // W/m²
  sky.sunIlluminanceLux = p.sunDisc ? directNormal * 93.0 : 0.0;
  if (!p.sunDisc) return sky;
  const double pixelAngle = kPi / sky.height;
  const double radius = std::max(radians(0.2665), 1.5 * pixelAngle);
  double solidAngle = 0.0;
  std::vector<std::size_t> disc;
  for (int row = 0; row < sky.height; ++row)
    for (int col = 0; col < sky.width; ++col) {
      const glm::dvec3 d = equirectDirection((col + 0.5) / sky.width, (row + 0.5) / sky.height);
      if (std::acos(std::clamp(glm::dot(d, sky.sunDirection), -1.0, 1.0)) > radius) continue;
      disc.push_back(static_cast<std::size_t>(row) * sky.width + col);
      solidAngle += equirectPixelSolidAngle(row, sky.width, sky.height);
    }
  if (solidAngle > 0) {
    // Sun colour: the sky's chromaticity towards the sun would be too blue; use D65 white (1,1,1)
    // scaled to the luminance, a documented simplification.
    const float radiance = static_cast<float>(sky.sunIlluminanceLux / solidAngle);
    for (std::size_t i : disc)
      for (int c = 0; c < 3; ++c) sky.rgb[i * 3 + static_cast<std::size_t>(c)] += radiance;
  }
  return sky;
}

double horizontalIlluminance(const std::vector<float>& rgb, int width, int height, glm::dvec3 excludeDirection, double excludeRadians) {
  double e = 0.0;
  const double cosExclude = std::cos(excludeRadians);
  const bool exclude = glm::length(excludeDirection) > 0;
  for (int row = 0; row < height; ++row) {
    const double solidAngle = equirectPixelSolidAngle(row, width, height);
    for (int col = 0; col < width; ++col) {
      const glm::dvec3 d = equirectDirection((col + 0.5) / width, (row + 0.5) / height);
      if (d.y <= 0) continue;
      if (exclude && glm::dot(d, glm::normalize(excludeDirection)) >= cosExclude) continue;
      const std::size_t i = (static_cast<std::size_t>(row) * width + col) * 3;
      e += luminance(glm::dvec3(rgb[i], rgb[i + 1], rgb[i + 2])) * d.y * solidAngle;
    }
  }
  return e;
}

std::pair<double, double> sunAngles(const glm::dvec3& towardsSun) {
  const glm::dvec3 d = glm::normalize(towardsSun);
  // d = (cos e sin a, sin e, -cos e cos a): the inverse of preethamSky's sun direction.
  return {degrees(std::asin(std::clamp(d.y, -1.0, 1.0))), degrees(std::atan2(d.x, -d.z))};
}

}  // namespace dynbench::convert
