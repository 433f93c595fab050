// Wavelength grids: samples, bins (the quadrature cells) and located errors.
#include <gtest/gtest.h>

#include "spectrum/grid.h"

using namespace skybake;

// 360-830 nm at 5 nm: 95 samples, bins [λ-2.5, λ+2.5] that tile [357.5, 832.5] without gaps.
TEST(WavelengthGrid, UniformSamplesAndBins) {
  WavelengthGrid g = WavelengthGrid::Uniform(360, 830, 5);
  ASSERT_EQ(g.size(), 95u);
  EXPECT_EQ(g[0], 360.0);
  EXPECT_EQ(g[94], 830.0);
  EXPECT_DOUBLE_EQ(g[47], 595.0);
  EXPECT_DOUBLE_EQ(g.bin_lo_nm(0), 357.5);
  EXPECT_DOUBLE_EQ(g.bin_hi_nm(94), 832.5);
  double total = 0.0;
  for (size_t i = 0; i < g.size(); ++i) {
    EXPECT_NEAR(g.bin_width_nm(i), 5.0, 1e-12) << i;
    if (i > 0) {
      EXPECT_EQ(g.bin_lo_nm(i), g.bin_hi_nm(i - 1)) << "bins must tile: " << i;
    }
    total += g.bin_width_nm(i);
  }
  EXPECT_NEAR(total, 475.0, 1e-9);  // 95 bins of 5 nm
  EXPECT_EQ(g.step_nm(), 5.0);
  EXPECT_TRUE(g.is_spectral());
}

// A fractional step still ends exactly on max (samples computed from the index, not accumulated).
TEST(WavelengthGrid, UniformFractionalStepEndsOnMax) {
  WavelengthGrid g = WavelengthGrid::Uniform(400, 700, 0.1);
  ASSERT_EQ(g.size(), 3001u);
  EXPECT_EQ(g[3000], 700.0);
  EXPECT_NEAR(g[1234], 523.4, 1e-12);
  WavelengthGrid one = WavelengthGrid::Uniform(550, 550, 10);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one.bin_lo_nm(0), 545.0);
  EXPECT_EQ(one.bin_hi_nm(0), 555.0);
}

// An explicit list: bins between midpoints, end bins mirrored.
TEST(WavelengthGrid, ListBinsAreMidpointCells) {
  WavelengthGrid g = WavelengthGrid::List({400, 450, 550, 700});
  EXPECT_DOUBLE_EQ(g.bin_lo_nm(0), 375.0);
  EXPECT_DOUBLE_EQ(g.bin_hi_nm(0), 425.0);
  EXPECT_DOUBLE_EQ(g.bin_lo_nm(2), 500.0);
  EXPECT_DOUBLE_EQ(g.bin_hi_nm(2), 625.0);
  EXPECT_DOUBLE_EQ(g.bin_hi_nm(3), 775.0);
  EXPECT_EQ(g.kind(), WavelengthGrid::Kind::kList);
}

// The RGB grid keeps R, G, B order and 10 nm bins; it is not a quadrature grid.
TEST(WavelengthGrid, RgbGrid) {
  WavelengthGrid g = WavelengthGrid::Rgb();
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(g[0], 680.0);
  EXPECT_EQ(g[1], 550.0);
  EXPECT_EQ(g[2], 440.0);
  EXPECT_EQ(g.bin_lo_nm(2), 435.0);
  EXPECT_EQ(g.bin_hi_nm(0), 685.0);
  EXPECT_FALSE(g.is_spectral());
  EXPECT_EQ(g.covered_lo_nm(), 435.0);
  EXPECT_EQ(g.covered_hi_nm(), 685.0);
}

TEST(WavelengthGrid, BadInputIsLocated) {
  const FileLoc where{"pipeline.yaml", 7};
  auto message = [&](auto fn) {
    try {
      fn();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([&] { WavelengthGrid::Uniform(360, 830, 7, where); }),
            "pipeline.yaml:7: wavelength grid: max_nm - min_nm (470) must be a whole number of steps of 7 nm");
  EXPECT_EQ(message([&] { WavelengthGrid::Uniform(0, 830, 5, where); }),
            "pipeline.yaml:7: wavelength grid: min_nm must be > 0, got 0");
  EXPECT_EQ(message([&] { WavelengthGrid::Uniform(500, 400, 5, where); }),
            "pipeline.yaml:7: wavelength grid: max_nm (400) must be >= min_nm (500)");
  EXPECT_EQ(message([&] { WavelengthGrid::Uniform(400, 500, -1, where); }),
            "pipeline.yaml:7: wavelength grid: step_nm must be > 0, got -1");
  EXPECT_EQ(message([&] { WavelengthGrid::List({400, 400, 500}, where); }),
            "pipeline.yaml:7: wavelength list: must be strictly increasing, but entry 2 (400) follows 400");
  EXPECT_EQ(message([&] { WavelengthGrid::List({400}, where); }),
            "pipeline.yaml:7: wavelength list: needs at least 2 wavelengths, got 1");
}

TEST(WavelengthGrid, Describe) {
  EXPECT_EQ(WavelengthGrid::Uniform(360, 830, 5).Describe(),
            "uniform 360-830 nm, step 5 nm (95 samples; bin i = [lambda_i - step/2, lambda_i + step/2])");
  EXPECT_EQ(WavelengthGrid::List({440, 550.5}).Describe(), "list of 2 wavelengths 440, 550.5 nm (bins between midpoints)");
}
