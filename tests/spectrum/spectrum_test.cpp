// Tabulated spectra and the resampling rule (bin averages of the linear interpolant, or values
// at the samples): closed forms, conservation of the integral, located errors.
#include <gtest/gtest.h>

#include <cmath>

#include "io/csv.h"
#include "spectrum/spectrum.h"

using namespace skybake;

namespace {
TabulatedSpectrum Table(std::vector<double> x, std::vector<double> y, bool zero_outside = false) {
  TabulatedSpectrum t;
  t.display_name = "t.csv";
  t.quantity = "value_W_m2_nm";
  t.wavelength_nm = std::move(x);
  t.values = std::move(y);
  t.zero_outside = zero_outside;
  return t;
}
}  // namespace

// The integral of the piecewise-linear interpolant is exact for a linear function: ∫_a^b (2λ + 1)
// dλ = (b² - a²) + (b - a), also over sub-intervals that cut table cells.
TEST(TabulatedSpectrum, IntegralIsExactForLinearFunctions) {
  std::vector<double> x, y;
  for (double w = 300; w <= 900; w += 7) {
    x.push_back(w);
    y.push_back(2 * w + 1);
  }
  TabulatedSpectrum t = Table(x, y);
  for (auto [a, b] : {std::pair{300.0, 895.0}, {401.3, 402.9}, {555.5, 812.25}, {420.0, 420.0}}) {
    const double exact = (b * b - a * a) + (b - a);
    EXPECT_NEAR(t.Integral(a, b), exact, 1e-9 * std::max(1.0, exact)) << a << " " << b;
  }
}

// Zero outside: a constant 1 on [400, 500] integrates to 100 over any range that contains it.
TEST(TabulatedSpectrum, ZeroOutsideTheTable) {
  TabulatedSpectrum t = Table({400, 450, 500}, {1, 1, 1}, /*zero_outside=*/true);
  EXPECT_DOUBLE_EQ(t.Integral(100, 1000), 100.0);
  EXPECT_DOUBLE_EQ(t.Integral(480, 520), 20.0);
  EXPECT_EQ(t.Eval(399.9), 0.0);
  EXPECT_EQ(t.Eval(450.0), 1.0);
}

// Bin averages of a linear function equal its value at the bin centre; the sum of
// f_i Δλ_i over the grid equals the table's integral over the covered range (conservation).
TEST(Resample, BinAverageOfLinearFunctionAndConservation) {
  std::vector<double> x, y;
  for (double w = 350; w <= 850; w += 0.5) {
    x.push_back(w);
    y.push_back(0.01 * w - 2.0 + std::sin(w / 3.0));  // wiggly: conservation must not depend on smoothness
  }
  TabulatedSpectrum t = Table(x, y);
  WavelengthGrid g = WavelengthGrid::Uniform(360, 830, 5);
  ASSERT_EQ(ChooseResampling(t, g), Resampling::kBinAverage);
  Spectrum s = Resample(t, g);
  double sum = 0.0;
  for (size_t i = 0; i < g.size(); ++i) sum += s.values[i] * g.bin_width_nm(i);
  const double integral = t.Integral(357.5, 832.5);
  EXPECT_NEAR(sum, integral, 1e-12 * std::abs(integral) + 1e-12);

  TabulatedSpectrum lin = Table({300, 900}, {1.0, 7.0});  // f = 1 + (λ - 300)/100
  Spectrum avg = Resample(lin, g, Resampling::kBinAverage);
  for (size_t i = 0; i < g.size(); ++i) EXPECT_NEAR(avg.values[i], 1.0 + (g[i] - 300.0) / 100.0, 1e-12) << g[i];
}

// Bin-averaging a finely tabulated parabola f = λ² onto 10 nm bins: the exact bin mean is
// (b³ - a³)/(3(b - a)) = λ² + H²/12 (H = 10 nm), and the chords of the 0.5 nm table lie above the
// parabola by h²/6 on average (h = 0.5 nm: ∫ chord - ∫ λ² = h³/6 per cell), so the result must be
// λ² + H²/12 + h²/6 exactly (to rounding).
TEST(Resample, BinAverageOfParabolaMatchesClosedForm) {
  std::vector<double> x, y;
  for (double w = 300; w <= 900; w += 0.5) {
    x.push_back(w);
    y.push_back(w * w);
  }
  TabulatedSpectrum t = Table(x, y);
  WavelengthGrid g = WavelengthGrid::Uniform(400, 800, 10);
  Spectrum s = Resample(t, g);
  for (size_t i = 0; i < g.size(); ++i) {
    const double exact = g[i] * g[i] + 100.0 / 12.0;
    EXPECT_NEAR(s.values[i], exact + 0.25 / 6.0, 1e-6) << g[i];
  }
}

// kAuto copies a table onto its own grid (values at the samples), and linear interpolation is
// used when the table is coarser than the grid.
TEST(Resample, AutoChoosesLinearForCoarseOrEqualTables) {
  TabulatedSpectrum t = Table({400, 401, 402, 403}, {1, 5, 2, 8});
  WavelengthGrid same = WavelengthGrid::Uniform(400, 403, 1);
  EXPECT_EQ(ChooseResampling(t, same), Resampling::kLinear);
  Spectrum s = Resample(t, same);
  EXPECT_EQ(s.values, (std::vector<double>{1, 5, 2, 8}));
  WavelengthGrid fine = WavelengthGrid::Uniform(400, 403, 0.5);
  Spectrum f = Resample(t, fine);
  EXPECT_DOUBLE_EQ(f.values[1], 3.0);  // midway between 1 and 5
  EXPECT_DOUBLE_EQ(f.values[5], 5.0);  // midway between 2 and 8
}

// The grid needs the table to cover its bins (bin averages) or samples (linear).
TEST(Resample, CoverageErrorsNameTheMissingRange) {
  TabulatedSpectrum t = Table({380, 390, 400, 780}, {1, 1, 1, 1});
  try {
    Resample(t, WavelengthGrid::Uniform(380, 780, 40), Resampling::kBinAverage);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "t.csv: column 'value_W_m2_nm' covers 380-780 nm, but the wavelength grid (uniform 380-780 nm, "
                 "step 40 nm (11 samples; bin i = [lambda_i - step/2, lambda_i + step/2])) needs 360-800 nm (its "
                 "bins, bin-averaged)");
  }
  EXPECT_NO_THROW(Resample(t, WavelengthGrid::Uniform(380, 780, 40), Resampling::kLinear));
}

// Loading: wavelength column with a unit (µm converted to nm), located errors for bad rows.
TEST(LoadSpectrum, ParsesAndReportsEveryBadRow) {
  CsvTable ok = CsvTable::Parse("# source: test\nwavelength_um,e_W_m2_nm\n0.4,1.5\n0.5,2.5\n", "s.csv");
  TabulatedSpectrum s = SpectrumColumn(ok, "e_W_m2_nm");
  EXPECT_DOUBLE_EQ(s.wavelength_nm[1], 500.0);
  EXPECT_EQ(s.source, "test");
  CsvTable bad = CsvTable::Parse("# source: test\nwavelength_nm,e_W_m2_nm\n400,1\n410,-2\n405,3\n", "s.csv");
  try {
    SpectrumColumn(bad, "e_W_m2_nm");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "s.csv:4: column 'e_W_m2_nm': expected a value >= 0, got -2\n"
                 "s.csv:5: column 'wavelength_nm': wavelengths must strictly increase, but 405 follows 410");
  }
  try {
    SpectrumColumn(ok, "missing_W_m2_nm");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "s.csv:2: no column 'missing_W_m2_nm' (columns: wavelength_um, e_W_m2_nm)");
  }
}
