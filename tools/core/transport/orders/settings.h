// The resolved settings of `orders`: table sizes, the quality presets (a table indexed by
// Quality), and the typed expert overrides of SkyMethodOptions::table_size (docs/sky-methods.md,
// "orders" and "Expert overrides").
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "transport/sky_method.h"

namespace skybake::orders {

struct OrdersSettings {
  int nr = 16;               // radius nodes (+ the observer's), at least
  // > 0: every interval of the nr nodes holding more than this vertical optical depth (at the
  // grid's middle wavelength) split into equal optical-depth pieces, up to radius_max nodes in all
  // (RadiusNodeAltitudes in nodes.h; docs/sky-methods.md "Radius nodes under a cloud"). 0: nr.
  double radius_dtau = 0.0;
  int radius_max = 64;
  int nup = 16, ndn = 8;     // view nodes above / below each altitude's horizon
  int nphi = 8;              // azimuth nodes on [0, pi]
  int nt = 40;               // steps along a table ray
  // Steps along an output view ray (single scattering): 64 keep the sky within 0.016 % RMS,
  // max 0.055 %, of 96 (hazed, clear, cloudy4; sun 30-95 deg).
  int nss = 64;
  int fine = 256;            // pieces for optical depths along a ray
  // Truncation cone per scattering component, between truncation_min_deg and truncation_deg
  // (chosen in PrepareMedium; "Truncation cone per component" in docs/sky-methods.md).
  double truncation_deg = 5.0;
  double truncation_min_deg = 0.0;  // 0: the same as truncation_deg (one cone for all)
  // The cone rule's largest fall of the phase over one azimuth interval outside the cone, and the
  // same for a component whose phase peaks above 30 sr^-1 (cloud droplets; medium.cpp ChooseCones).
  double cone_ratio = 10.0;
  double cone_peaked_ratio = 10.0;
  double tau_cap = 12.0;     // optical depth beyond which a table ray's steps follow distance only
  double rho_cap = 0.98;     // largest ratio of successive orders the geometric tail extrapolates
  // The sun transmittance tables: radius nodes, and the sun-zenith node spacing from 80 to 110 deg.
  // log T is blended linearly between radius nodes and is convex there, so too few nodes make a
  // low sun's transmittance low: the hazed sky's single scattering at sun 85 deg is 0.36 % dark
  // with 48 nodes, 0.09 % with 96, 0.03 % with 200, against the path tracer's first order (0.2 %
  // references), while 0.05 and 0.1 deg zenith steps differ by <= 0.03 % even in twilight
  // ("Sun transmittance" in docs/sky-methods.md).
  int sun_nr = 96;
  double sun_low_step_deg = 0.1;
  // Sun-node intervals from here on: J blended log-linearly in the sun angle (> 180: never); the
  // sun nodes from 80 to 90 deg are 1 deg apart ("The sun on the horizon" in docs/sky-methods.md).
  double loglin_from_deg = 85.0;
  double view_power = 2.0;   // view nodes: power of the node spacing in angle from the horizon
  bool normalise = true;     // kernel rows scaled to conserve energy
  bool azimuth_even = true;  // azimuth blends even about the sun's plane (phi^2 near 0 and pi)
  bool early_tail = true;    // stop with the geometric tail once it is accurate to `tolerance`
  // Diffusion synthetic acceleration of the orders (acceleration.h; docs/sky-methods.md
  // "Accelerated orders") where the column's delta-scaled vertical optical depth at the reference
  // wavelength is at least this; 0: never.
  double dsa_from_tau = 0.0;
  // Scattering kernel: 0 = the phase sampled at the direction nodes (each node standing for its
  // cell); n > 0 = integrated against the interpolation's own basis (the "hat" of each node, linear
  // in the view-node index and in the azimuth blend) with n sub-intervals per view interval and
  // 2n per azimuth interval ("Scattering kernel" in docs/sky-methods.md).
  int kernel_sub = 0;
  // The kernel applied in azimuthal cosine modes (the phase depends on the azimuth difference
  // only: a circulant in the azimuth, plus the even blend's two end intervals as explicit
  // columns); false: the (nd x nd) matrix, the slow and plain form the modal one is tested
  // against ("Scattering kernel" in docs/sky-methods.md).
  bool kernel_modal = true;
  // The modal kernels stored as IEEE binary16 (Imath's half, round to nearest even) per unit
  // sigma_s*: half the memory and half the bytes each order's scatter reads; each value within
  // 2^-12 of the float one, the sky within 0.003 % of the float kernels' at high ("Scattering
  // kernel" in docs/sky-methods.md); false: floats.
  bool kernel_half = true;
  // The transport's gather by families (radius/view corners blended once per step for all sun and
  // azimuth nodes); false: cell by cell, 16 corners each (the plain form).
  bool gather_split = true;
  // The output's exact single scattering (full phase) attenuated on the sun's path by the
  // delta-scaled medium (Nakajima & Tanaka 1988's TMS correction: L = L1[P, T*] + L*_ms; the view's
  // path: ss_scaled_view), in the sky and in view segments, when there are multiple-scattering
  // orders; false, or max_orders 1: by the unscaled medium (the true first order). With the
  // unscaled attenuation the light scattered into the truncation cone on the way - not scattered,
  // in the delta-scaled problem - is counted by neither term: under a thin water cloud (cloudy1,
  // tau 1, the droplets' 5 deg cone holding 45 % of their scattering) the sky comes out 17-53 %
  // dark against the path tracer (docs/sky-methods.md "TMS attenuation").
  bool ss_scaled = true;
  // The view path's part of it: 1 = scaled for the components whose cone holds at least
  // kViewScaledFraction of their scattering (cloud droplets), unscaled for the rest; 2 = scaled
  // for all; 0 = unscaled for all (docs/sky-methods.md "TMS attenuation").
  int ss_scaled_view = 1;
  // Largest share of the total the geometric tail may have when taken early (StopRule in solve.cpp).
  double tail_share_max = 0.1;
  // Memory for the step positions stored between orders (TransportContext::sun_az, MiB): the
  // radius nodes whose positions fit are stored, the others' computed per lookup, with the same
  // bytes ("Peak memory" in docs/sky-methods.md). 288: all 65 of a thick sky's radius nodes at
  // high (4.35 MiB each, 283 MiB), whose computed positions would cost ~28 ms per node and order.
  int step_positions_mib = 288;
  // Memory for the solve's per-wavelength tables (the fields, the ratio codes, the kernels, J_ms;
  // MiB): above it the wavelengths are solved in batches that fit, with the same bytes
  // (PlanWavelengthBatches in solve.h; "Peak memory" in docs/sky-methods.md). 600: a thick sky's
  // 25 wavelengths at high (~635 MiB) are two batches, whose first one's tables and every step
  // position peak at 824 MiB; as one solve with every position stored they would peak at 1040
  // MiB, over the 1 GB target, and with the positions cut to fit it cost as much as two batches.
  int solve_tables_mib = 600;
  int max_orders = 40;
  double tolerance = 1e-3;
  // The sun zenith nodes' spacing (SunNodes in settings.cpp): every sun_step_deg up to 80 deg,
  // low_sun_step_deg to 90, twilight_step_deg through the low sun and twilight to 110.
  int sun_step_deg = 10;
  double low_sun_step_deg = 1.0;
  double twilight_step_deg = 1.0;
  // The sun nodes' range: SunNodes cut to [sun_min_deg, sun_max_deg] (a solve of part of the sun
  // range: the two parts of the twilight split, split.h).
  double sun_min_deg = 0.0;
  double sun_max_deg = 180.0;
  // The twilight split (split.h; docs/sky-methods.md "The twilight split"): 0 = one solve over
  // every sun node; > 0 = two solves, the daylight one at these settings with its sun nodes up to
  // split_day_to_deg, the twilight one with split_azimuths azimuths and medium's kernel and cones
  // with its sun nodes from split_twilight_from_deg, the answers blended from the daylight to the
  // twilight part over sun zenith split_from_deg to split_from_deg + split_width_deg.
  double split_from_deg = 0.0;
  double split_width_deg = 1.0;
  double split_day_to_deg = 0.0;
  double split_twilight_from_deg = 0.0;
  int split_azimuths = 16;
  std::vector<double> sun_deg = {};  // sun zenith nodes (SettingsFor)
};

// The sun zenith nodes of s (deg): the spacing of sun_step_deg, low_sun_step_deg and
// twilight_step_deg, cut to [sun_min_deg, sun_max_deg].
std::vector<double> SunNodes(const OrdersSettings& s);

// The presets: low, medium (the defaults above) and high.
const QualityTable<OrdersSettings>& OrdersPresets();

// One expert override: a key of SkyMethodOptions::table_size (an int) and the setting it sets.
//   kCount   the integer setting itself, from min to max
//   kFlag    a switch: 0 off, 1 on
//   kScaled  a real setting given as an integer from min to max, divided by `divisor`
//            (sun_low_step_x100 = 5 is 0.05 deg)
struct OrdersOverride {
  enum class Kind { kCount, kFlag, kScaled };
  const char* key;
  Kind kind;
  int min, max;
  double divisor;
  std::variant<int OrdersSettings::*, bool OrdersSettings::*, double OrdersSettings::*> field;
};
// Every override orders reads, defined once (settings.cpp); the known keys derive from it.
const std::vector<OrdersOverride>& OrdersOverrides();
const std::vector<std::string>& OverrideKeys();

// The preset of options.quality with options' overrides; UsageError for an unknown override key,
// a value out of its range, or table sizes too small.
OrdersSettings SettingsFor(const SkyMethodOptions& options);

}  // namespace skybake::orders
