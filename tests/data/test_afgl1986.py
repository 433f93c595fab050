"""The six AFGL 1986 standard atmospheres in atmospheres/data/afgl1986_*.csv (Anderson et al. 1986,
AFGL-TR-86-0110, Tables 1a-1f; sources in atmospheres/data/SOURCES.md).

Checks, per table:
- the `# source:` first line and the header (the format of afgl1986_us_standard.csv);
- altitudes 0 to 120 km, strictly increasing, the 50 AFGL levels;
- every value a positive finite number;
- the ideal-gas law p = n k T to within the tables' rounding: p, T and n carry 3 to 4
  significant digits, so a half unit in the third digit bounds the relative error at 0.5 %;
  the one known exception (Tropical, 120 km: n k T / p = 0.985 in the transcription) is listed
  and checked to stay what it is;
- o3_number_density_cm3 = o3_ppmv * 1e-6 * air_number_density_cm3 (written with 5 significant
  digits: 5e-5 relative);
- the total ozone column (trapezoid over altitude of the number density, 1 DU = 2.6867e20 m^-2)
  against the column of each model listed below, within 0.5 DU;
- the U.S. Standard table is the file clear.yaml has always used (its rows are those of
  joseki's Table 1f transcription, with o3_number_density_cm3 computed as here).

Ozone columns: no published per-model column of the AFGL 1986 tables was found in the sources
reachable from this project (the report's text and the MODTRAN/libRadtran manuals were not
available), so EXPECTED_DU holds the columns computed here from the tables themselves
(trapezoid, 0-120 km). They guard the data against edits; the U.S. Standard value agrees with
the "~345 DU" clear.yaml has always quoted, and all six lie inside the range of measured
climatological means (about 250-450 DU).

Runs with the standard library only: `python3 tests/data/test_afgl1986.py` or through ctest
(label `data`).
"""
import csv
import hashlib
import math
import os
import unittest

ROOT = os.environ.get("SKYBAKE_SOURCE_DIR") or os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))
DATA = os.path.join(ROOT, "atmospheres", "data")

BOLTZMANN_J_K = 1.380649e-23      # CODATA 2018 (exact)
DOBSON_M2 = 2.6867e20             # molecules m^-2 per DU (docs/atmosphere.md)
HEADER = ["altitude_km", "pressure_mb", "temperature_K", "air_number_density_cm3", "o3_ppmv",
          "o3_number_density_cm3"]
LEVELS_KM = [float(z) for z in range(0, 25)] + [25.0 + 2.5 * i for i in range(11)] + \
    [55.0 + 5.0 * i for i in range(14)]

# model: (table, ozone column in DU computed here, see the docstring)
MODELS = {
    "tropical": ("1a", 283.75),
    "midlatitude_summer": ("1b", 335.73),
    "midlatitude_winter": ("1c", 379.78),
    "subarctic_summer": ("1d", 349.15),
    "subarctic_winter": ("1e", 377.09),
    "us_standard": ("1f", 345.79),
}
COLUMN_TOLERANCE_DU = 0.5
IDEAL_GAS_TOLERANCE = 5e-3
# (model, altitude_km): n k T / p as transcribed, kept because it is above the rendered atmosphere
IDEAL_GAS_EXCEPTIONS = {("tropical", 120.0): 0.985}

# The US Standard table as clear.yaml has used it: the first and last data rows, and the row count.
US_STANDARD_FIRST = "0.00,1.013e+03,288.2,2.548e+19,2.66e-02,6.7777e+11"
US_STANDARD_LAST = "120.00,2.540e-05,360.0,5.114e+11,5.00e-04,2.5570e+02"
# sha256 of atmospheres/data/afgl1986_us_standard.csv, the table clear.yaml uses
US_STANDARD_SHA256 = "c671e8bd54c7669494e00e41d61d6c6dc51b230438f2b219f87200f2c7e8f316"


def read_table(model):
    path = os.path.join(DATA, "afgl1986_%s.csv" % model)
    with open(path, newline="") as f:
        lines = f.read().splitlines()
    return path, lines


def parse(lines):
    reader = csv.reader(lines[1:])
    header = next(reader)
    rows = [[float(x) for x in row] for row in reader if row]
    return header, rows


def ozone_column_du(rows):
    col = 0.0
    for a, b in zip(rows, rows[1:]):
        dz_m = (b[0] - a[0]) * 1e3
        col += 0.5 * (a[5] + b[5]) * 1e6 * dz_m   # cm^-3 -> m^-3
    return col / DOBSON_M2


class Afgl1986Tables(unittest.TestCase):
    def test_source_line_and_header(self):
        for model, (table, _) in MODELS.items():
            with self.subTest(model=model):
                path, lines = read_table(model)
                self.assertTrue(lines[0].startswith("# source: "), path)
                self.assertIn("AFGL-TR-86-0110", lines[0])
                self.assertIn("Table %s" % table, lines[0])
                self.assertEqual(lines[1].split(","), HEADER, path)

    def test_altitudes(self):
        for model in MODELS:
            with self.subTest(model=model):
                _, rows = parse(read_table(model)[1])
                z = [r[0] for r in rows]
                self.assertEqual(z, LEVELS_KM)
                self.assertTrue(all(b > a for a, b in zip(z, z[1:])))
                self.assertEqual((z[0], z[-1]), (0.0, 120.0))

    def test_values_positive_and_finite(self):
        for model in MODELS:
            with self.subTest(model=model):
                _, rows = parse(read_table(model)[1])
                for r in rows:
                    for v in r[1:]:
                        self.assertTrue(math.isfinite(v) and v > 0.0, (model, r))

    def test_ideal_gas_law(self):
        for model in MODELS:
            _, rows = parse(read_table(model)[1])
            for z, p_mb, t_k, n_cm3, _, _ in rows:
                with self.subTest(model=model, altitude_km=z):
                    ratio = n_cm3 * 1e6 * BOLTZMANN_J_K * t_k / (p_mb * 100.0)
                    expected = IDEAL_GAS_EXCEPTIONS.get((model, z), 1.0)
                    self.assertAlmostEqual(ratio, expected, delta=IDEAL_GAS_TOLERANCE * expected,
                                           msg="%s %g km: n k T / p = %.4f" % (model, z, ratio))

    def test_ozone_number_density_is_mixing_ratio_times_air(self):
        for model in MODELS:
            _, rows = parse(read_table(model)[1])
            for r in rows:
                with self.subTest(model=model, altitude_km=r[0]):
                    self.assertAlmostEqual(r[5], r[4] * 1e-6 * r[3], delta=5e-5 * r[5])

    def test_ozone_column(self):
        for model, (_, expected_du) in MODELS.items():
            with self.subTest(model=model):
                _, rows = parse(read_table(model)[1])
                du = ozone_column_du(rows)
                self.assertAlmostEqual(du, expected_du, delta=COLUMN_TOLERANCE_DU,
                                       msg="%s: %.2f DU" % (model, du))
                self.assertTrue(250.0 < du < 450.0)

    def test_us_standard_is_the_existing_table(self):
        _, lines = read_table("us_standard")
        self.assertIn("Table 1f 'U.S. Standard' (model 6)", lines[0])
        self.assertEqual(lines[2], US_STANDARD_FIRST)
        self.assertEqual(lines[-1], US_STANDARD_LAST)
        self.assertEqual(len(lines), 52)
        with open(os.path.join(DATA, "afgl1986_us_standard.csv"), "rb") as f:
            self.assertEqual(hashlib.sha256(f.read()).hexdigest(), US_STANDARD_SHA256)

    def test_same_levels_in_every_model(self):
        ref = [r[0] for r in parse(read_table("us_standard")[1])[1]]
        for model in MODELS:
            with self.subTest(model=model):
                self.assertEqual([r[0] for r in parse(read_table(model)[1])[1]], ref)


if __name__ == "__main__":
    unittest.main()
