// Model simplifications of sky-render part 2 that act on the vertical profiles
// (docs/sky-methods.md, "Simplifications"): the analytic profiles of the real-time models
// (Bruneton 2017 and Hillaire 2020: exponential air and aerosol, a tent of ozone) fitted to the
// measured profiles, so that the cost of the simplification can be measured on the same
// atmosphere.
//
// Each fit keeps the column the renderer sees (the trapezoid integral on the level grid, which is
// what linear interpolation between levels integrates to), so zenith optical depths are unchanged
// and only the vertical distribution differs:
//   air, aerosol layers   n(z) = n_0 exp(-z/H) with n_0 the measured value at the ground and H
//                         solving trapz(n_0 exp(-z_i/H)) = the measured column (monotone in H,
//                         bisection). A layer whose ground value is below half its peak (an
//                         elevated layer, which no exponential represents) takes H from its
//                         first moment instead (<z> = H for an exponential) and n_0 from the
//                         column. clear.yaml: air H = 8454 m, the continental aerosol H = 2414 m,
//                         the ozone tent centre 22.5 km, half-width 21.8 km
//                         (tests/atmosphere/simplify_test.cpp).
//   ozone                 Bruneton 2017's tent (demo.cc: 0 below c - w, linear up to c, down to
//                         0 at c + w) with the measured profile's mean altitude c and the same
//                         variance (w^2/6 for the symmetric triangle), scaled to the column.
// Temperature and pressure are kept (the ozone cross-section depends on the local temperature).
#pragma once

#include <string>
#include <vector>

#include "atmosphere/vertical_profiles.h"

namespace skybake {

struct ProfileFit {
  std::string constituent;  // "air", "ozone", "aerosol.<name>"
  std::string shape;        // "exponential", "exponential (first moment)", "tent"
  double scale_height_m = 0.0;  // exponential
  double ground_value = 0.0;    // exponential: n_0 (m^-3 for air, m^-1 for aerosol unit shapes)
  double centre_m = 0.0, half_width_m = 0.0;  // tent
  double column = 0.0;          // the conserved column (m^-2, or 1 for aerosol shapes)
};

// The profiles with analytic shapes; `fits` (optional) receives what was fitted.
VerticalProfiles AnalyticProfiles(const VerticalProfiles& measured, std::vector<ProfileFit>* fits = nullptr);

// The trapezoid integral of values on the altitude levels (the column a renderer sees).
double TrapezoidColumn(const std::vector<double>& altitude_m, const std::vector<double>& values);

}  // namespace skybake
