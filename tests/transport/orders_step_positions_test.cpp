// The packed step positions of `orders` (transport/orders/transport.h): the sun and azimuth nodes
// round-trip through the 32-bit form (kNoSun included), the weights come back as the 10-bit
// quantization QuantizeSunAzimuth gives the computed positions (so that stored and computed
// lookups read the same weights), within half a step (0.5 / 1023) of the float weight, with 0
// and 1 exact, and no field spills into another.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "transport/orders/transport.h"

namespace skybake::orders {
namespace {

TEST(OrdersStepPositions, NodesRoundTripIncludingNoSun) {
  for (uint16_t si = 0; si < 63; ++si) {
    for (uint16_t q0 = 0; q0 < 64; ++q0) {
      const SunAzimuth p = UnpackSunAzimuth(PackSunAzimuth({si, q0, 1.0f, 1.0f}));
      ASSERT_EQ(p.si, si);
      ASSERT_EQ(p.q0, q0);
      ASSERT_EQ(p.ts, 1.0f);  // the weights' bits beside the nodes' all set: nothing spills
      ASSERT_EQ(p.tq, 1.0f);
    }
  }
  const SunAzimuth none = UnpackSunAzimuth(PackSunAzimuth({kNoSun, 63, 0.0f, 0.0f}));
  EXPECT_EQ(none.si, kNoSun);
  EXPECT_EQ(none.q0, 63);
  EXPECT_TRUE(PositionsPackable(64, 64));  // sun nodes 0..63 (si <= 62), azimuths q0 <= 62
  EXPECT_FALSE(PositionsPackable(65, 36));
  EXPECT_FALSE(PositionsPackable(22, 65));
}

TEST(OrdersStepPositions, WeightsAreTheQuantizedOnesWithinHalfAStep) {
  const double half_step = 0.5 / 1023.0;
  double worst = 0.0;
  for (int i = 0; i <= 100000; ++i) {
    const float t = static_cast<float>(i) / 100000.0f, u = 1.0f - t;
    const SunAzimuth p{5, 7, t, u};
    const SunAzimuth packed = UnpackSunAzimuth(PackSunAzimuth(p)), quantized = QuantizeSunAzimuth(p);
    ASSERT_EQ(packed.ts, quantized.ts) << t;  // stored and computed lookups read the same weights
    ASSERT_EQ(packed.tq, quantized.tq) << u;
    ASSERT_EQ(packed.si, 5);
    ASSERT_EQ(packed.q0, 7);
    worst = std::max({worst, std::abs(packed.ts - static_cast<double>(t)), std::abs(packed.tq - static_cast<double>(u))});
  }
  EXPECT_LE(worst, half_step * (1.0 + 1e-6));
  EXPECT_GT(worst, 0.9 * half_step);  // the sweep reaches the rounding's worst case
  for (float t : {0.0f, 1.0f}) {
    const SunAzimuth p = UnpackSunAzimuth(PackSunAzimuth({0, 0, t, t}));
    EXPECT_EQ(p.ts, t);
    EXPECT_EQ(p.tq, t);
  }
  const SunAzimuth clamped = UnpackSunAzimuth(PackSunAzimuth({0, 0, -0.25f, 1.5f}));
  EXPECT_EQ(clamped.ts, 0.0f);
  EXPECT_EQ(clamped.tq, 1.0f);
}

}  // namespace
}  // namespace skybake::orders
