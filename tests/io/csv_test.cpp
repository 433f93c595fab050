// CSV tables: the "# source:" convention, unit-bearing columns converted to SI, located errors.
#include <gtest/gtest.h>

#include <cmath>

#include "io/csv.h"
#include "io/interp.h"

using namespace skybake;

TEST(Csv, ParsesAndConvertsUnits) {
  CsvTable t = CsvTable::Parse(
      "# source: test\n# comment\naltitude_km,number_density_cm3,name\n0,2.5e19,a\n1.5,2.0e19,b\n", "t.csv");
  EXPECT_EQ(t.source(), "test");
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.row_line(1), 5);
  Diagnostics d;
  auto z = t.ColumnIn("altitude", Quantity::kLength, d);
  auto n = t.ColumnIn("number_density", Quantity::kNumberDensity, d);
  ASSERT_TRUE(d.empty());
  EXPECT_DOUBLE_EQ(z->values[1], 1500.0);   // km -> m
  EXPECT_DOUBLE_EQ(n->values[0], 2.5e25);   // cm^-3 -> m^-3
}

TEST(Csv, RequiresSourceLine) {
  try {
    CsvTable::Parse("altitude_km,x\n0,1\n", "t.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "t.csv:1: the first line must be '# source: <where the data come from>'");
  }
}

TEST(Csv, RowWidthErrorsAreLocated) {
  try {
    CsvTable::Parse("# source: x\na_km,b_m\n1,2\n3\n4,5,6\n", "t.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "t.csv:4: expected 2 cells (as in the header on line 2), got 1\n"
                 "t.csv:5: expected 2 cells (as in the header on line 2), got 3");
  }
}

TEST(Csv, BadNumbersAndGapsAreLocated) {
  CsvTable t = CsvTable::Parse("# source: x\nz_km,v_m3\n0,1\n1,abc\n2,\n", "t.csv");
  Diagnostics d;
  t.Numbers("v_m3", d);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.items()[0].ToString(), "t.csv:4: column 'v_m3': expected a number, got \"abc\"");
  EXPECT_EQ(d.items()[1].ToString(), "t.csv:5: column 'v_m3': missing value");
  Diagnostics d2;
  t.ColumnIn("pressure", Quantity::kPressure, d2);
  EXPECT_EQ(d2.items().at(0).ToString(),
            "t.csv:2: no column 'pressure_<unit>' with a unit of _Pa, _hPa, _mb (columns: z_km, v_m3)");
}

TEST(Interp, LinearAndLogLinear) {
  Interpolant1D lin({0.0, 10.0}, {1.0, 3.0}, Interpolation::kLinear);
  EXPECT_DOUBLE_EQ(lin(5.0), 2.0);
  // Log-linear is exact for an exponential: y = exp(-z/8).
  Interpolant1D lg({0.0, 8.0}, {1.0, std::exp(-1.0)}, Interpolation::kLogLinear);
  EXPECT_NEAR(lg(4.0), std::exp(-0.5), 1e-15);
  // A zero end falls back to linear.
  Interpolant1D lz({0.0, 1.0}, {2.0, 0.0}, Interpolation::kLogLinear);
  EXPECT_DOUBLE_EQ(lz(0.5), 1.0);
  EXPECT_TRUE(lin.Covers(0.0, 10.0));
  EXPECT_FALSE(lin.Covers(-1.0, 10.0));
  EXPECT_THROW(lin(11.0), InternalError);
}

TEST(Interp, Trapezoid) {
  std::vector<double> x{0, 1, 2, 3}, y{0, 1, 2, 3};
  EXPECT_DOUBLE_EQ(Trapezoid(x, y), 4.5);  // integral of x from 0 to 3
}

// IntervalLocator must give FindInterval's answer everywhere, nodes and just-off-node values
// included, on grids as the sky uses them (piecewise uniform with accumulated rounding,
// quadratic, irregular).
TEST(Interp, IntervalLocatorMatchesFindInterval) {
  std::vector<std::vector<double>> grids;
  std::vector<double> g;
  for (double a = 0; a < 80; a += 1.0) g.push_back(a);
  for (double a = 80; a < 110; a += 0.05) g.push_back(a);  // accumulated rounding, as sun_theta_deg_
  for (double a = 110; a <= 125 + 1e-9; a += 1.0) g.push_back(a);
  grids.push_back(g);
  g.clear();
  for (int i = 0; i < 48; ++i) g.push_back(6.36e6 + 1e5 * std::pow(i / 47.0, 2.0));
  grids.push_back(g);
  grids.push_back({-3.0, -2.999, 0.0, 1e-9, 5.0, 5.5, 100.0});
  for (const std::vector<double>& x : grids) {
    IntervalLocator loc(x);
    const double lo = x.front() - 1.0, hi = x.back() + 1.0;
    for (int i = 0; i <= 20000; ++i) {
      const double v = lo + (hi - lo) * i / 20000.0;
      ASSERT_EQ(loc.Find(v), FindInterval(x, v)) << v;
    }
    for (double node : x) {
      for (double v : {node, std::nextafter(node, -1e300), std::nextafter(node, 1e300)}) {
        ASSERT_EQ(loc.Find(v), FindInterval(x, v)) << v;
      }
    }
  }
}
