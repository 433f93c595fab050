// sky-render points' geometry CSV (transport/points.h ParsePointGeometries) on arbitrary bytes:
// the CSV reader, then the validation of every row. A row it accepts must be inside the ranges
// it states (SKYBAKE_CHECK: an accepted row out of range is a crash of the target).
#include "fuzz_common.h"
#include "io/csv.h"
#include "transport/points.h"

using namespace skybake;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // 100 km: the top of the shipped atmospheres (atmospheres/*.yaml, planet.top_km).
  constexpr double kTopM = 100e3;
  fuzz::Guarded([&] {
    const CsvTable csv = CsvTable::Parse(fuzz::Text(data, size), "fuzz.csv");
    const PointsInput in = ParsePointGeometries(csv, 0.0, kTopM);
    SKYBAKE_CHECK(in.rows.size() == csv.rows());
    for (const PointGeometry& g : in.rows) {
      SKYBAKE_CHECK(g.sun_zenith_deg >= 0 && g.sun_zenith_deg <= 180);
      SKYBAKE_CHECK(g.view_zenith_deg >= 0 && g.view_zenith_deg <= 180);
      SKYBAKE_CHECK(g.relative_azimuth_deg >= -360 && g.relative_azimuth_deg <= 360);
      SKYBAKE_CHECK(g.observer_altitude_m >= 0 && g.observer_altitude_m < kTopM);
      (void)PointStreamKey(g);
    }
  });
  return 0;
}
