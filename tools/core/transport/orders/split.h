// The twilight split of `orders` (OrdersSettings::split_from_deg > 0; docs/sky-methods.md "The
// twilight split"): `high` is needed in daylight only (the target there: RMS <= 0.5 %, max <= 2 %
// against the path tracer), while in twilight (sun zenith 90-110 deg) the target is 3 % RMS; yet
// 24 of the 42 sun nodes are twilight ones. So the method solves twice: the daylight part at the
// preset's settings with its sun nodes up to split_day_to_deg, the twilight part with
// split_azimuths azimuths and medium's kernel and cone settings (the preset's otherwise, its view
// nodes among them: medium's blur the ground's dark band 1-2 deg below the horizon) with its sun
// nodes from split_twilight_from_deg. Each answer comes from the
// daylight part up to split_from_deg, from the twilight part beyond split_from_deg +
// split_width_deg, and from both in between, blended with a weight smooth in the sun zenith, so
// that a LUT's sun slices have no jump where the parts meet.
#pragma once

#include <vector>

#include "transport/orders/settings.h"

namespace skybake::orders {

struct SplitSettings {
  OrdersSettings day, twilight;  // each a one-solve setting (split_from_deg 0) with its sun nodes
};

// The two parts of a split setting s (s.split_from_deg > 0).
SplitSettings SplitParts(const OrdersSettings& s);

// The twilight part's weight at sun zenith sun_zenith_rad: 0 up to split_from_deg, 1 from
// split_from_deg + split_width_deg, smoothstep 3u^2 - 2u^3 in between (u the position in the
// zone: the blend and its derivative in the sun angle continuous at both ends).
double TwilightWeight(const OrdersSettings& s, double sun_zenith_rad);

// day[i] = (1 - w) day[i] + w twilight[i].
void Blend(double w, const std::vector<double>& twilight, std::vector<double>* day);

}  // namespace skybake::orders
