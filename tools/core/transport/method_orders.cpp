#include "transport/method_orders.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>

#include <fmt/format.h>

#include "io/error.h"
#include "io/fast_exp.h"
#include "io/interp.h"

namespace skybake {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// out[w] = sum_{k in [k0, k1)} wv[k] v[k][w], summed in k order: the transport's gather of J at a
// table ray's step. Eight wavelengths at a time in a GCC vector (one register with AVX2, two with
// SSE2), the sum kept in it across the corners; each lane rounds exactly as the scalar loop
// (contraction is off: CMakeLists.txt), so the bytes are those of the plain form. The plain form,
// one corner at a time into out[], stored and reloaded the sum for each corner.
void Gather16(const float* const* v, const float* wv, int k0, int k1, size_t nw, float* out) {
  using V8 = float __attribute__((vector_size(32)));
  size_t w = 0;
  for (; w + 8 <= nw; w += 8) {
    V8 sum = {};
    for (int k = k0; k < k1; ++k) {
      V8 x;
      std::memcpy(&x, v[k] + w, sizeof x);
      sum += wv[k] * x;
    }
    std::memcpy(out + w, &sum, sizeof sum);
  }
  for (; w < nw; ++w) {
    float sum = 0.0f;
    for (int k = k0; k < k1; ++k) sum += wv[k] * v[k][w];
    out[w] = sum;
  }
}

// The modal scatter's three products (SolveMultipleScattering), 8 wavelengths at a time in GCC
// vectors with the sums kept in registers; every sum in the order of the plain loop it replaces
// (contraction is off), so the same bytes. V8 as in Gather16.
using ModalV8 = float __attribute__((vector_size(32)));
inline ModalV8 LoadV8(const float* p) {
  ModalV8 x;
  std::memcpy(&x, p, sizeof x);
  return x;
}
inline void StoreV8(float* p, ModalV8 x) { std::memcpy(p, &x, sizeof x); }

// out[m * out_stride + w] = sum_{q ascending} cos_mq[m * nq + q] l[q * nw + w], m < nm.
void ModalAnalysis(const float* l, const float* cos_mq, size_t nm, size_t nq, size_t nw, float* out, size_t out_stride) {
  size_t m = 0;
  for (; m + 4 <= nm; m += 4) {
    size_t w = 0;
    for (; w + 8 <= nw; w += 8) {
      ModalV8 a0 = {}, a1 = {}, a2 = {}, a3 = {};
      for (size_t q = 0; q < nq; ++q) {
        const ModalV8 x = LoadV8(l + q * nw + w);
        a0 += cos_mq[m * nq + q] * x;
        a1 += cos_mq[(m + 1) * nq + q] * x;
        a2 += cos_mq[(m + 2) * nq + q] * x;
        a3 += cos_mq[(m + 3) * nq + q] * x;
      }
      StoreV8(out + m * out_stride + w, a0);
      StoreV8(out + (m + 1) * out_stride + w, a1);
      StoreV8(out + (m + 2) * out_stride + w, a2);
      StoreV8(out + (m + 3) * out_stride + w, a3);
    }
    for (; w < nw; ++w) {
      for (size_t i = 0; i < 4; ++i) {
        float a = 0.0f;
        for (size_t q = 0; q < nq; ++q) a += cos_mq[(m + i) * nq + q] * l[q * nw + w];
        out[(m + i) * out_stride + w] = a;
      }
    }
  }
  for (; m < nm; ++m) {
    for (size_t w = 0; w < nw; ++w) {
      float a = 0.0f;
      for (size_t q = 0; q < nq; ++q) a += cos_mq[m * nq + q] * l[q * nw + w];
      out[m * out_stride + w] = a;
    }
  }
}

// acc[b * nw + w] (+)= sum_{j ascending < n} g_j x[b * b_stride + j * x_stride + w] for the 4 b of a
// sun block, g_j = g[j * g_stride + w] (kScalar false: a row per j, loaded once for the 4 b) or
// g[j * g_stride] (kScalar true: one weight per j).
template <bool kAdd, bool kScalar>
void ModalBlock4Impl(const float* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw,
                     float* acc) {
  size_t w = 0;
  for (; w + 8 <= nw; w += 8) {
    ModalV8 a0 = {}, a1 = {}, a2 = {}, a3 = {};
    if (kAdd) {
      a0 = LoadV8(acc + w), a1 = LoadV8(acc + nw + w), a2 = LoadV8(acc + 2 * nw + w), a3 = LoadV8(acc + 3 * nw + w);
    }
    for (size_t j = 0; j < n; ++j) {
      ModalV8 gv;
      if (kScalar) {
        gv = ModalV8{} + g[j * g_stride];  // the weight in every lane
      } else {
        gv = LoadV8(g + j * g_stride + w);
      }
      const float* xj = x + j * x_stride + w;
      a0 += gv * LoadV8(xj);
      a1 += gv * LoadV8(xj + b_stride);
      a2 += gv * LoadV8(xj + 2 * b_stride);
      a3 += gv * LoadV8(xj + 3 * b_stride);
    }
    StoreV8(acc + w, a0);
    StoreV8(acc + nw + w, a1);
    StoreV8(acc + 2 * nw + w, a2);
    StoreV8(acc + 3 * nw + w, a3);
  }
  for (; w < nw; ++w) {
    for (size_t b = 0; b < 4; ++b) {
      float a = kAdd ? acc[b * nw + w] : 0.0f;
      for (size_t j = 0; j < n; ++j) a += g[j * g_stride + (kScalar ? 0 : w)] * x[b * b_stride + j * x_stride + w];
      acc[b * nw + w] = a;
    }
  }
}
void ModalBlock4(const float* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw, float* acc) {
  ModalBlock4Impl<false, false>(g, g_stride, x, x_stride, b_stride, n, nw, acc);
}
void ModalBlock4Add(const float* g, size_t g_stride, const float* x, size_t x_stride, size_t b_stride, size_t n, size_t nw,
                    float* acc) {
  ModalBlock4Impl<true, false>(g, g_stride, x, x_stride, b_stride, n, nw, acc);
}
// acc[b * nw + w] = sum_{m ascending < nm} c[m * c_stride] t[b * b_stride + m * nw + w], 4 b.
void ModalSynthesis4(const float* c, size_t c_stride, const float* t, size_t b_stride, size_t nm, size_t nw, float* acc) {
  ModalBlock4Impl<false, true>(c, c_stride, t, nw, b_stride, nm, nw, acc);
}

// The solve's tables (a field over every cell and wavelength: 178 MB for high) in vectors whose
// elements start uninitialised, zeroed in parallel by ZeroTable: a std::vector<float> of that
// size is zeroed on one thread, and the kernel's zeroing of the fresh pages on first touch with
// it (~1.8 GB for high, ~2.5 s of system time: most of high's shortfall from 2x at 2 threads).
// The same values, the same bytes. 2026-11-24, sixth stop.
template <class T>
struct UninitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitAllocator<U>;
  };
  UninitAllocator() = default;
  template <class U>
  UninitAllocator(const UninitAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... A>
  void construct(U* p, A&&... a) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
  }
};
using Table = std::vector<float, UninitAllocator<float>>;

// v = n zeros, written in parallel blocks (the first touch of fresh pages spread over the threads).
void ZeroTable(Table* v, size_t n) {
  Table().swap(*v);
  v->resize(n);
  constexpr size_t kBlock = size_t{1} << 18;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, (n + kBlock - 1) / kBlock, 1), [&](const tbb::blocked_range<size_t>& rg) {
    for (size_t b = rg.begin(); b != rg.end(); ++b) std::fill(v->begin() + b * kBlock, v->begin() + std::min(n, (b + 1) * kBlock), 0.0f);
  });
}

// ---------------------------------------------------------------------------- settings

struct OrdersSettings {
  int nr = 16;               // radius nodes (+ the observer's)
  int nup = 16, ndn = 8;     // view nodes above / below each altitude's horizon
  int nphi = 8;              // azimuth nodes on [0, pi]
  int nt = 40;               // steps along a table ray
  // Steps along an output view ray (single scattering). 64 since 2026-11-24 (96 before): against
  // 96 the sky moves by <= 0.016 % RMS, max 0.055 % (hazed, clear, cloudy4; sun 30-95 deg; 48
  // steps: max 0.18 %), and the render - two thirds of a clear or hazed LUT - is a third shorter.
  int nss = 64;
  int fine = 256;            // pieces for optical depths along a ray
  // Truncation cone per scattering component, between truncation_min_deg and truncation_deg
  // (chosen in PrepareMedium; "Truncation cone per component" in docs/sky-methods.md).
  double truncation_deg = 5.0;
  double truncation_min_deg = 0.0;  // 0: the same as truncation_deg (one cone for all)
  double tau_cap = 12.0;     // optical depth beyond which a table ray's steps follow distance only
  double rho_cap = 0.98;     // largest ratio of successive orders the geometric tail extrapolates
  // The sun transmittance tables: radius nodes, and the sun-zenith node spacing from 80 to 110 deg.
  // log T is blended linearly between radius nodes and is convex there, so too few nodes make a
  // low sun's transmittance low: the hazed sky's single scattering at sun 85 deg came out 0.36 %
  // dark with 48 nodes (0.09 % with 96, 0.03 % with 200) against the path tracer's first order
  // (0.2 % references), while 0.05 and 0.1 deg zenith steps differ by <= 0.03 % even in twilight
  // ("Sun transmittance" in docs/sky-methods.md). Until 2026-11-24: 48 nodes and 0.05 deg, the
  // same table size and cost as 96 and 0.1 deg.
  int sun_nr = 96;
  double sun_low_step_deg = 0.1;
  // Sun-node intervals from here on: J blended log-linearly in the sun angle (> 180: never). 85
  // since 2026-11-24 (90 before), with the sun nodes from 80 to 90 deg 1 deg apart (2.5 before):
  // the sun on the horizon, "The sun on the horizon" in docs/sky-methods.md.
  double loglin_from_deg = 85.0;
  double view_power = 2.0;   // view nodes: power of the node spacing in angle from the horizon
  bool normalise = true;     // kernel rows scaled to conserve energy
  bool azimuth_even = true;  // azimuth blends even about the sun's plane (phi^2 near 0 and pi)
  bool early_tail = true;    // stop with the geometric tail once it is accurate to `tolerance`
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
  // The transport's gather by families (radius/view corners blended once per step for all sun and
  // azimuth nodes); false: cell by cell, 16 corners each (the plain form).
  bool gather_split = true;
  // A table ray's step weights J by the exact int T* sigma_t* dt = T*(t0) (1 - e^-dtau) times the
  // single-scattering albedo at the step's point (conserves energy: the weights of a lossless
  // medium sum to 1 - T*(end)); false: int T* dt exactly times sigma_s* at the point, which
  // overweights a step whose point is denser than its mean (a thick cloud's orders then never
  // converged: cloudy5, docs/sky-methods.md "Step weights").
  bool step_albedo = true;
  // The scaled sun table (the sources of the multiple-scattering tables) with the unscaled one's
  // nodes and logarithmic blend; false: nodes quadratic in altitude and a linear blend, which
  // overestimates the sun inside a thick layer and at a low sun's horizon (docs/sky-methods.md
  // "Sun transmittance"). Together with tau_centroid since 2026-11-23 (fifth stop): each alone
  // is worse, the old table's error having held up the thick layers' sources.
  bool scaled_sun_exact = true;
  // A table ray's step takes its sources at the point of its centroid in optical depth, tau0 +
  // g dtau, whatever the medium's shape within the step; false: at t0 + g dt, the centroid of a
  // uniform medium, which for a step straddling a cloud's edge fell in the clear air and lost the
  // step's sources (docs/sky-methods.md "Step weights").
  bool tau_centroid = true;
  // The output's exact single scattering (full phase) attenuated on the sun's path by the
  // delta-scaled medium (Nakajima & Tanaka 1988's TMS correction: L = L1[P, T*] + L*_ms; the view's
  // path: ss_scaled_view), in the sky and in view segments, when there are multiple-scattering
  // orders; false, or max_orders 1: by the unscaled medium (the true first order). With the
  // unscaled attenuation the light scattered into the truncation cone on the way - not scattered,
  // in the delta-scaled problem - was counted by neither term: under a thin water cloud (cloudy1,
  // tau 1, the droplets' 5 deg cone holding 45 % of their scattering) the sky came out 17-53 %
  // dark against the path tracer (docs/sky-methods.md "TMS attenuation").
  bool ss_scaled = true;
  // The view path's part of it: 1 = scaled for the components whose cone holds at least
  // kViewScaledFraction of their scattering (cloud droplets), unscaled for the rest; 2 = scaled
  // for all; 0 = unscaled for all (docs/sky-methods.md "TMS attenuation").
  int ss_scaled_view = 1;
  // Largest share of the total the geometric tail may have when taken early (see the stopping
  // rule in SolveMultipleScattering).
  double tail_share_max = 0.1;
  int max_orders = 40;
  double tolerance = 1e-3;
  std::vector<double> sun_deg;  // sun zenith nodes
};

OrdersSettings SettingsFor(const SkyMethodOptions& o) {
  OrdersSettings s;
  if (o.quality == "low") {
    s.nr = 10, s.nup = 10, s.ndn = 6, s.nphi = 6, s.nt = 24, s.nss = 48, s.fine = 128, s.tolerance = 3e-3;
    s.sun_nr = 48;
  } else if (o.quality == "medium") {
    // defaults above
  } else if (o.quality == "high") {
    // Measured on the hazed sky (docs/sky-methods.md, "Scattering kernel"): the azimuth count and
    // a kernel that resolves the aerosol lobe matter; more radius nodes or ray steps do not. 36
    // azimuths since 2026-11-24 (24 before): with the 1 deg aerosol cone the multiple-scattering
    // aureole of a low sun needs them (hazed, sun 85 deg: 0.53 -> 0.45 % RMS, max 2.11 -> 1.19 %;
    // the build 14 -> 21 s at 48 wavelengths on 2 threads). 96 view steps (160 until 2026-11-24:
    // the same sky within 0.005 % RMS, max 0.023 %, hazed, sun 30-85 deg) and medium's 1 deg
    // twilight nodes (0.5 deg until then: 62 sun nodes instead of 42, a third of the build; the
    // sky at sun 92 / 95 / 98 deg moves by 0.16 / 0.18 / 0.12 % RMS, daylight not at all, sun 90
    // deg by 0.11 %; the twilight target is 3 %).
    s.nup = 24, s.ndn = 12, s.nphi = 36, s.nss = 96, s.fine = 512, s.tolerance = 3e-4;
    s.kernel_sub = 4, s.truncation_deg = 3.0, s.truncation_min_deg = 1.0;
    s.sun_nr = 192;
  } else {
    throw UsageError("--quality: expected low, medium or high, got '" + o.quality + "'");
  }
  auto get = [&](const char* key, int* v) {
    auto it = o.table_size.find(key);
    if (it != o.table_size.end()) *v = it->second;
  };
  // A switch: 0 off, anything else on.
  auto get_flag = [&](const char* key, bool* v) {
    auto it = o.table_size.find(key);
    if (it != o.table_size.end()) *v = it->second != 0;
  };
  get("radius", &s.nr);
  get("view_up", &s.nup);
  get("view_down", &s.ndn);
  get("azimuth", &s.nphi);
  get("ray_steps", &s.nt);
  get("view_steps", &s.nss);
  int trunc = 0;
  get("truncation_deg", &trunc);
  if (trunc > 0) s.truncation_deg = trunc;
  int trunc_min = 0;
  get("truncation_min_deg", &trunc_min);
  if (trunc_min > 0) s.truncation_min_deg = trunc_min;
  if (s.truncation_min_deg <= 0.0 || s.truncation_min_deg > s.truncation_deg) s.truncation_min_deg = s.truncation_deg;
  get_flag("normalise", &s.normalise);
  int cap = 0;
  get("tau_cap", &cap);
  if (cap > 0) s.tau_cap = cap;
  get("sun_radius_nodes", &s.sun_nr);
  int sun_low_step_x100 = 0;
  get("sun_low_step_x100", &sun_low_step_x100);
  if (sun_low_step_x100 > 0) s.sun_low_step_deg = sun_low_step_x100 / 100.0;
  int ksub = -1;
  get("kernel_sub", &ksub);
  if (ksub >= 0) s.kernel_sub = ksub;
  int tsp = 0;
  get("tail_share_pct", &tsp);
  if (tsp > 0) s.tail_share_max = tsp / 100.0;
  get_flag("step_albedo", &s.step_albedo);
  get_flag("scaled_sun_exact", &s.scaled_sun_exact);
  get_flag("tau_centroid", &s.tau_centroid);
  get_flag("ss_scaled", &s.ss_scaled);
  get("ss_scaled_view", &s.ss_scaled_view);
  get_flag("kernel_modal", &s.kernel_modal);
  get_flag("gather_split", &s.gather_split);

  int loglin = 0;
  get("loglin_from_deg", &loglin);
  if (loglin > 0) s.loglin_from_deg = loglin;
  int vp10 = 0;
  get("view_power_x10", &vp10);
  if (vp10 > 0) s.view_power = vp10 / 10.0;
  int rho_pct = 0;
  get("rho_cap_pct", &rho_pct);
  if (rho_pct > 0) s.rho_cap = rho_pct / 100.0;
  get_flag("azimuth_even", &s.azimuth_even);
  get_flag("early_tail", &s.early_tail);
  if (o.view_steps > 0) s.nss = o.view_steps;
  if (o.orders > 0) s.max_orders = o.orders;
  if (o.order_tolerance > 0) s.tolerance = o.order_tolerance;
  // Sun zenith nodes: every 10 deg up to 80, then 1 deg through the low sun and twilight to
  // 110, then 112, 115, 120 (beyond: no sunlight reaches the atmosphere's sunlit part that
  // matters; J is taken as 0); "high" halved the twilight step until 2026-11-24. From 80 to 90 deg the step was
  // 2.5 deg until 2026-11-24: a table ray's sources were blended linearly between 87.5 and 90
  // deg, where they fall steeply and convexly, and with the sun on the horizon the clear sky
  // 0.5 deg above the horizon, 40 deg from the sun's azimuth, came out +4.7 % (high; path
  // tracer 387.1 cd/m2 +- 0.37 %); 1 deg with the log-linear blend from 85 deg: +0.1 %.
  int sun_step = 10;
  get("sun_step_deg", &sun_step);
  for (double a = 0; a < 80; a += sun_step) s.sun_deg.push_back(a);
  int low10 = 10;
  get("low_sun_step_x10", &low10);
  for (double a = 80; a < 90 - 1e-9; a += low10 / 10.0) s.sun_deg.push_back(a);
  double tw = 1.0;
  int tw10 = 0;
  get("twilight_step_x10", &tw10);
  if (tw10 > 0) tw = tw10 / 10.0;
  for (double a = 90; a <= 110 + 1e-9; a += tw) s.sun_deg.push_back(a);
  for (double a : {112.0, 115.0, 120.0}) s.sun_deg.push_back(a);
  if (s.nr < 3 || s.nup < 2 || s.ndn < 2 || s.nphi < 2 || s.nt < 4 || s.nss < 4) {
    throw UsageError("orders: table sizes are too small");
  }
  return s;
}

// n altitudes in [0, H] uniform in a monotone s(h) with s(0) = 0 and s(H) = 1 (bisection to 1 mm;
// the ends exactly 0 and H): the node placements that follow both altitude and optical depth.
template <class S>
std::vector<double> AltitudesUniformIn(const S& s_of, int n, double H) {
  std::vector<double> h;
  for (int i = 0; i < n; ++i) {
    const double u = static_cast<double>(i) / (n - 1);
    double lo = 0.0, hi = H;
    if (i == 0) hi = 0.0;
    if (i == n - 1) lo = H;
    for (int it = 0; it < 60 && hi - lo > 1e-3; ++it) {
      const double mid = 0.5 * (lo + hi);
      (s_of(mid) < u ? lo : hi) = mid;
    }
    h.push_back(0.5 * (lo + hi));
  }
  return h;
}

// Linear interpolation position on a sorted grid: index of the lower node and weight of the upper.
struct Lerp {
  size_t i = 0;
  double t = 0.0;
};
[[gnu::always_inline]] inline Lerp Locate(const IntervalLocator& loc, double v) {
  const std::vector<double>& x = loc.x();
  if (v <= x.front()) return {0, 0.0};
  if (v >= x.back()) return {x.size() - 2, 1.0};
  const size_t i = loc.Find(v);
  return {i, (v - x[i]) / (x[i + 1] - x[i])};
}
Lerp Locate(const std::vector<double>& x, double v) {
  if (v <= x.front()) return {0, 0.0};
  if (v >= x.back()) return {x.size() - 2, 1.0};
  size_t i = static_cast<size_t>(std::upper_bound(x.begin(), x.end(), v) - x.begin()) - 1;
  return {i, (v - x[i]) / (x[i + 1] - x[i])};
}

// ---------------------------------------------------------------------------- the method

class OrdersMethod : public SkyMethod {
 public:
  OrdersMethod(const AtmosphereModel& model, const SkyMethodOptions& options, const ProgressFn& progress)
      : m_(model), s_(SettingsFor(options)), nw_(model.wavelengths()) {
    observer_altitude_m_ = options.observer_altitude_m;
    ss_scaled_ = s_.ss_scaled && s_.max_orders >= 2;
    ss_scaled_view_ = ss_scaled_ && s_.ss_scaled_view > 0;
    PrepareMedium();
    BuildSunTables();
    BuildRadiusNodes();
    SolveMultipleScattering(progress);
  }

  std::string Name() const override { return "orders"; }

  std::string Describe() const override {
    return fmt::format(
        "method: orders\nradius_nodes: {}\nview_nodes: {} up + {} down per altitude\nazimuth_nodes: {}\n"
        "sun_nodes: {}\nray_steps: {}\nview_steps: {}\ntruncation_deg: {}\nkernel: {}\norders_computed: {}\n"
        "tail_extrapolated: {}\nlast_order_fraction: {:.3g}\ntolerance: {}\nsingle_scattering_attenuation: {}\n",
        radius_.size(), s_.nup, s_.ndn, s_.nphi, s_.sun_deg.size(), s_.nt, s_.nss, ConesText(),
        s_.kernel_sub > 0 ? fmt::format("basis-integrated, {} sub-intervals", s_.kernel_sub) : std::string("phase at the nodes"), orders_done_,
        tail_ ? "true" : "false", last_fraction_, s_.tolerance, ss_scaled_ ? "delta-scaled" : "unscaled");
  }

  // "1 (rayleigh, truncated fraction 0.000 at 570 nm), ...": each scattering component's truncation
  // cone (deg) and the share of its scattering inside it at the grid's middle wavelength.
  std::string ConesText() const {
    std::string text;
    size_t c = 0;
    for (const MediumComponent& mc : m_.components) {
      if (!mc.phase) continue;
      text += fmt::format("{}{:g} ({}, truncated fraction {:.3f} at {:g} nm)", text.empty() ? "" : ", ", cone_deg_[c], mc.name,
                          f_[c * nw_ + nw_ / 2], m_.wavelength_nm[nw_ / 2]);
      ++c;
    }
    return text;
  }

  void Radiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                std::vector<double>* out) const override {
    Render(observer_altitude_m, sun_zenith_rad, dirs, nullptr, out);
  }
  // L_1 of the split L = L_1 + L_ms (the exact march of the output ray), computed beside L.
  bool SingleScatteringRadiance(double observer_altitude_m, double sun_zenith_rad,
                                const std::vector<std::array<double, 3>>& dirs, std::vector<double>* out) const override {
    std::vector<double> total;
    Render(observer_altitude_m, sun_zenith_rad, dirs, nullptr, &total, out);
    return true;
  }
  bool SupportsSegments() const override { return true; }
  void SegmentRadiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                       const ViewSegment& segment, std::vector<double>* out) const override {
    Render(observer_altitude_m, sun_zenith_rad, dirs, &segment, out);
  }

 private:
  // --- medium: per model level, wavelength innermost (float)
  void PrepareMedium();
  // Coefficients at altitude z into per-wavelength buffers.
  void SigmaT(double z, bool scaled, float* out) const { SigmaT(m_.Locate(z), scaled, out); }
  void SigmaS(size_t c, double z, bool scaled, float* out) const { SigmaS(c, m_.Locate(z), scaled, out); }
  void SigmaT(const AtmosphereModel::Cell& cell, bool scaled, float* out) const;
  // The output view ray's extinction: sigma_t_view_ (the unscaled one unless ss_scaled_view_).
  void SigmaTView(const AtmosphereModel::Cell& cell, float* out) const;
  // A per-level table [l * nw + w] interpolated to a cell.
  void LevelLerp(const std::vector<float>& s, const AtmosphereModel::Cell& cell, float* out) const;
  void SigmaS(size_t c, const AtmosphereModel::Cell& cell, bool scaled, float* out) const;
  // sigma_t at one wavelength (the step placement's reference).
  float SigmaTAt(double z, bool scaled, size_t w) const;

  // --- sun transmittance averaged over the solar disk, T(r, theta_s) per wavelength
  void BuildSunTables();
  // Disk-averaged sun transmittance at radius r and sun zenith cosine mu_s into out[w].
  void SunTransmittance(double r, double mu_s, bool scaled, float* out) const {
    SunTransmittanceAt(SunRadius(r, scaled), mu_s, scaled, out);
  }
  // The same with the radius part of the lookup done once (a view ray's point, every direction).
  Lerp SunRadius(double r, bool scaled) const { return Locate((scaled ? sun_star_ : sun_).loc, r); }
  void SunTransmittanceAt(const Lerp& lr, double mu_s, bool scaled, float* out) const;
  // Optical depths (unscaled, truncated part) along a ray from r with cosine mu to the top;
  // false if it hits the ground.
  bool RayDepth(double r, double mu, std::vector<double>* tau, std::vector<double>* tau_f) const;

  // --- multiple-scattering tables
  void BuildRadiusNodes();
  double HorizonMu(double r) const {
    const double q = m_.bottom_radius_m / r;
    return -std::sqrt(std::max(0.0, 1.0 - q * q));
  }
  // View node k (0..nu-1, ascending mu) at radius r, its solid-angle width in mu.
  double ViewMu(size_t k, double r) const;
  // The same placement at a fractional node index f within the set below (down) or above the horizon.
  double ViewMuAt(bool down, double f, double r) const;
  double ViewWidth(size_t k, double r) const;
  // Fractional view index of mu at radius r (up and down parts are not interpolated across).
  void ViewIndex(double mu, double r, size_t* k0, size_t* k1, double* t) const;
  void SolveMultipleScattering(const ProgressFn& progress);

  // Azimuth blend position of phi (0..pi, from the sun's plane): the lower node and the weight
  // of the next one. The sky is even in the azimuth about the sun's vertical plane, so near
  // phi = 0 and pi it goes as a + b phi^2 (a + b (pi - phi)^2): with `even`, the first and last
  // intervals, and beyond the outer nodes (within pi / 2n of those planes), blend linearly in
  // phi^2 ((pi - phi)^2), not in phi. Clamping there took the value of the node 11.25 deg from
  // the sun for the sun's plane itself, under the forward lobe (hazed, sun 70 deg: -6 % at the
  // horizon towards the sun; the output's blend is what matters: inside the table build the
  // sources are smooth in azimuth and the change there is <= 0.01 %).
  double AzimuthBlend(double phi, bool even, size_t* q0) const {
    double fq = phi / kPi * s_.nphi - 0.5;
    fq = std::clamp(fq, 0.0, static_cast<double>(s_.nphi - 1));
    *q0 = std::min(static_cast<size_t>(fq), static_cast<size_t>(s_.nphi - 2));
    double tq = fq - static_cast<double>(*q0);
    if (even) {
      auto sq = [](double x) { return x * x; };
      const double p0 = (*q0 + 0.5) * kPi / s_.nphi, p1 = (*q0 + 1.5) * kPi / s_.nphi;
      if (*q0 == 0) tq = (sq(phi) - sq(p0)) / (sq(p1) - sq(p0));
      else if (*q0 + 2 == static_cast<size_t>(s_.nphi)) tq = 1.0 - (sq(kPi - phi) - sq(kPi - p1)) / (sq(kPi - p0) - sq(kPi - p1));
    }
    return tq;
  }
  size_t Cell(size_t ri, size_t si, size_t k, size_t q) const {
    return ((ri * ns_ + si) * nu_ + k) * static_cast<size_t>(s_.nphi) + q;
  }

  // Sky radiance (segment == nullptr) or a view segment's in-scattered radiance.
  // With `single`, also L_1 alone (sky radiance only).
  void Render(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
              const ViewSegment* segment, std::vector<double>* out, std::vector<double>* single = nullptr) const;

  // The radius and view-node part of an interpolation: it depends on the point's radius and view
  // cosine only, so the table rays compute it once, not once per order, sun node and azimuth.
  struct RadialView {
    size_t ri = 0;             // lower radius node
    double wr[2] = {0, 0};     // weights of the radius nodes ri, ri + 1
    size_t k0[2] = {0, 0}, k1[2] = {0, 0};  // bracketing view nodes at each radius node
    double tk[2] = {0, 0};     // weight of k1
  };
  RadialView RadialViewAt(double r, double mu) const;
  // The sun-angle and azimuth part of an interpolation (fixed for a table-ray step across all
  // orders, so computed once).
  struct SunAzimuth {
    uint16_t si = 0;  // lower sun node; kNoSun beyond the last node (no light)
    uint16_t q0 = 0;  // lower azimuth node
    float ts = 0.0f;  // weight of si + 1
    float tq = 0.0f;  // weight of q0 + 1
  };
  static constexpr uint16_t kNoSun = 0xFFFF;
  SunAzimuth SunAzimuthAt(double theta_s, double cos_phi) const;
  // Interpolates table `tab` (cells x nw) at a point, accumulating weight * value into acc.
  void Interpolate(const Table& tab, const RadialView& rv, const SunAzimuth& sa, double weight,
                   float* acc) const;

  const AtmosphereModel& m_;
  OrdersSettings s_;
  bool ss_scaled_ = false;  // s_.ss_scaled with multiple-scattering orders (max_orders >= 2)
  bool ss_scaled_view_ = false;  // the view ray's attenuation from sigma_t_view_
  const size_t nw_;
  double observer_altitude_m_ = 0.0;
  size_t nc_ = 0;  // scattering components

  // Medium per model level l: sigma_t[l*nw+w], sigma_t*[..], sigma_s_c[(c*nl+l)*nw+w], sigma_s*_c.
  std::vector<float> sigma_t_, sigma_t_star_, sigma_s_, sigma_s_star_;
  std::vector<float> sigma_t_view_;  // the view ray's extinction (OrdersSettings::ss_scaled_view)
  std::vector<std::shared_ptr<const PhaseModel>> phase_;  // per component
  std::vector<double> f_;                                   // truncated fraction [c*nw+w]
  std::vector<double> cone_deg_;                            // truncation cone per component, deg
  std::vector<float> phase_star_;                           // [(c*ng+g)*nw+w] on cos grid
  static constexpr int kPhaseGrid = 2048;
  std::vector<double> albedo_, sun_e_;

  // Sun transmittance tables (unscaled and scaled): radius nodes x theta nodes x nw, averaged
  // over the solar disk; their logarithms (0 where the transmittance is 0) and a per-node flag
  // "every wavelength lit".
  struct SunTable {
    std::vector<double> r;
    IntervalLocator loc;
    std::vector<float> t, lt;
    std::vector<uint8_t> pos;
    bool log_blend = false;
  };
  SunTable sun_, sun_star_;
  std::vector<double> sun_theta_deg_;
  IntervalLocator sun_theta_loc_;

  // MS tables.
  std::vector<double> radius_;  // radius nodes (m); obs_index_ is the observer's
  size_t obs_index_ = 0;
  size_t ns_ = 0, nu_ = 0;
  std::vector<double> sun_theta_rad_;
  std::vector<float> ms_;  // accumulated orders >= 2 at the observer radius: [(si*nu+k)*nphi+q]*nw
  // Accumulated multiple-scattering source J_ms* = sum_{n>=2} J_n at every node (cells x nw),
  // for view segments: L_seg,ms = int_0^t_end T* J_ms* dt.
  Table jms_;
  int orders_done_ = 0;
  bool tail_ = false;
  double last_fraction_ = 0.0;

  // A view ray's sun-independent part (Render).
  struct ViewPoint {
    double t = 0.0, rr = 0.0, mu2 = 0.0;
    Lerp sun_r;  // the sun transmittance table's radius position
  };
  struct ViewRay {
    double mu = 2.0;  // none yet
    double length = 0.0;
    bool ground = false;
    std::vector<ViewPoint> pts;
    std::vector<float> e;      // [(p * nc + c) * nw + w]: half-step x T(0, t_p) x sigma_s,c (single scattering weight)
    std::vector<float> seg;    // [p * nw + w]: half-step x T*(0, t_p) x sigma_s* (segments' multiple scattering)
    std::vector<float> t_end;  // [w] transmittance to the ray's end (the ground)
  };
  // The whole view ray (no segment) from the observer altitude along mu: built by `build` on the
  // first request and kept, up to kMaxCachedRays rays (then built anew each time). A ray depends
  // on (altitude, mu) only, so a cached one is the same bytes as a new one, whichever thread
  // built it first. The LUT render's 16 ambient rings are the same in each of its 64 sun slices
  // (its rows are not: the GT7 mapping's view zenith follows the sun); keeping them saves
  // 0.2-0.4 s of a 32x128 LUT at 48 wavelengths (docs/benchmarks.md).
  template <class Build>
  std::shared_ptr<const ViewRay> CachedViewRay(double altitude_m, double mu, Build&& build) const {
    const std::pair<double, double> key{altitude_m, mu};
    {
      std::lock_guard<std::mutex> lock(ray_mutex_);
      auto it = rays_.find(key);
      if (it != rays_.end()) return it->second;
    }
    auto ray = std::make_shared<ViewRay>();
    build(ray.get());
    std::lock_guard<std::mutex> lock(ray_mutex_);
    if (rays_.size() >= kMaxCachedRays) return ray;
    return rays_.emplace(key, std::move(ray)).first->second;
  }
  static constexpr size_t kMaxCachedRays = 64;  // ~0.15 MB each at 48 wavelengths and 4 components
  mutable std::mutex ray_mutex_;
  mutable std::map<std::pair<double, double>, std::shared_ptr<const ViewRay>> rays_;
};

// ---------------------------------------------------------------------------- medium

void OrdersMethod::PrepareMedium() {
  const size_t nl = m_.levels();
  for (const MediumComponent& c : m_.components) {
    if (c.phase) phase_.push_back(c.phase);
  }
  nc_ = phase_.size();
  albedo_ = m_.ground_albedo;
  sun_e_ = m_.sun.irradiance;

  // Each component's truncation cone (OrdersSettings::truncation_min_deg): the smallest angle in
  // 0.5 deg steps from the minimum up to truncation_deg at which, for every wavelength, the phase
  // function one azimuth interval further out is no more than kPeakRatioPerInterval times lower.
  // So what the kernel must integrate is no sharper than its grid resolves. At 550 nm and high's
  // azimuth interval (7.5 deg with the 24 azimuths this was measured with, 5 deg with 36) the
  // continental aerosol falls 3-4.5x from 1 deg (1 deg cone), a 10 um water droplet over 100x from
  // 1 deg and 5-7x from 3 deg (3 deg cone; docs/sky-methods.md "Truncation cone per component").
  constexpr double kPeakRatioPerInterval = 10.0;
  const double interval_deg = 180.0 / s_.nphi;  // azimuth nodes at cell centres, pi / nphi apart
  cone_deg_.assign(nc_, s_.truncation_deg);
  for (size_t c = 0; c < nc_; ++c) {
    for (double th = s_.truncation_min_deg; th < s_.truncation_deg - 1e-9; th += 0.5) {
      bool smooth = true;
      for (size_t w = 0; w < nw_ && smooth; ++w) {
        const double p0 = phase_[c]->Eval(w, std::cos(th * kDeg));
        const double p1 = phase_[c]->Eval(w, std::cos(std::min(180.0, th + interval_deg) * kDeg));
        smooth = p0 <= kPeakRatioPerInterval * p1;
      }
      if (smooth) {
        cone_deg_[c] = th;
        break;
      }
    }
  }

  // Truncated fractions and truncated phase functions on a uniform grid in cos(theta).
  f_.assign(nc_ * nw_, 0.0);
  phase_star_.assign(nc_ * kPhaseGrid * nw_, 0.0f);
  for (size_t c = 0; c < nc_; ++c) {
    const double cos_c = std::cos(cone_deg_[c] * kDeg);
    for (size_t w = 0; w < nw_; ++w) {
      // f = 2 pi int_{cos_c}^{1} (P(mu) - P(cos_c)) dmu, integrated in theta on a log grid
      // (the forward peak of large particles is ~1/x rad wide).
      const double p_c = phase_[c]->Eval(w, cos_c);
      const int n = 4000;
      const double th_min = 1e-5, th_max = cone_deg_[c] * kDeg;
      double f = 0.0, prev_th = 0.0, prev_v = 2 * kPi * std::max(0.0, phase_[c]->Eval(w, 1.0) - p_c) * 0.0;
      for (int i = 0; i <= n; ++i) {
        const double th = th_min * std::pow(th_max / th_min, static_cast<double>(i) / n);
        const double v = 2 * kPi * std::max(0.0, phase_[c]->Eval(w, std::cos(th)) - p_c) * std::sin(th);
        f += 0.5 * (v + prev_v) * (th - prev_th);
        prev_th = th;
        prev_v = v;
      }
      f = std::clamp(f, 0.0, 0.999);
      f_[c * nw_ + w] = f;
      for (int g = 0; g < kPhaseGrid; ++g) {
        const double mu = -1.0 + 2.0 * g / (kPhaseGrid - 1);
        const double p = mu > cos_c ? p_c : phase_[c]->Eval(w, mu);
        phase_star_[(c * kPhaseGrid + g) * nw_ + w] = static_cast<float>(p / (1.0 - f));
      }
    }
  }

  // The components whose view-ray attenuation is delta-scaled (OrdersSettings::ss_scaled_view):
  // all (2), none (0), or (1) those whose cone holds at least a quarter of their scattering at the
  // grid's middle wavelength - cloud droplets (10 um: ~0.5 in a 3-5 deg cone), not the aerosols
  // (continental 0.015-0.025 in 5 deg), whose long horizontal view rays near the horizon the scaled
  // attenuation made up to 1 % bright (docs/sky-methods.md "TMS attenuation").
  constexpr double kViewScaledFraction = 0.25;
  std::vector<bool> view_scaled(nc_, false);
  for (size_t c = 0; c < nc_; ++c) {
    view_scaled[c] = ss_scaled_view_ && (s_.ss_scaled_view == 2 || f_[c * nw_ + nw_ / 2] >= kViewScaledFraction);
  }
  sigma_t_.assign(nl * nw_, 0.0f);
  sigma_t_star_.assign(nl * nw_, 0.0f);
  sigma_t_view_.assign(nl * nw_, 0.0f);
  sigma_s_.assign(nc_ * nl * nw_, 0.0f);
  sigma_s_star_.assign(nc_ * nl * nw_, 0.0f);
  for (size_t l = 0; l < nl; ++l) {
    const AtmosphereModel::Cell cell{std::min(l, nl - 2), l == nl - 1 ? 1.0 : 0.0};
    size_t c = 0;
    for (size_t comp = 0; comp < m_.components.size(); ++comp) {
      const MediumComponent& mc = m_.components[comp];
      for (size_t w = 0; w < nw_; ++w) {
        const double ss = mc.scattering[l * nw_ + w], sa = mc.absorption[l * nw_ + w];
        sigma_t_[l * nw_ + w] += static_cast<float>(ss + sa);
        double trunc = 0.0;
        if (mc.phase) {
          trunc = f_[c * nw_ + w] * ss;
          sigma_s_[(c * nl + l) * nw_ + w] = static_cast<float>(ss);
          sigma_s_star_[(c * nl + l) * nw_ + w] = static_cast<float>(ss - trunc);
        }
        sigma_t_star_[l * nw_ + w] += static_cast<float>(ss + sa - trunc);
        sigma_t_view_[l * nw_ + w] += static_cast<float>(ss + sa - (mc.phase && view_scaled[c] ? trunc : 0.0));
      }
      (void)cell;
      if (mc.phase) ++c;
    }
  }
}

float OrdersMethod::SigmaTAt(double z, bool scaled, size_t w) const {
  const AtmosphereModel::Cell c = m_.Locate(z);
  const std::vector<float>& s = scaled ? sigma_t_star_ : sigma_t_;
  const float a = s[c.i * nw_ + w], b = s[(c.i + 1) * nw_ + w];
  return a + (b - a) * static_cast<float>(c.t);
}

void OrdersMethod::LevelLerp(const std::vector<float>& s, const AtmosphereModel::Cell& c, float* out) const {
  const float* a = &s[c.i * nw_];
  const float* b = &s[(c.i + 1) * nw_];
  const float t = static_cast<float>(c.t);
  for (size_t w = 0; w < nw_; ++w) out[w] = a[w] + (b[w] - a[w]) * t;
}

void OrdersMethod::SigmaT(const AtmosphereModel::Cell& c, bool scaled, float* out) const {
  LevelLerp(scaled ? sigma_t_star_ : sigma_t_, c, out);
}

void OrdersMethod::SigmaTView(const AtmosphereModel::Cell& c, float* out) const { LevelLerp(sigma_t_view_, c, out); }

void OrdersMethod::SigmaS(size_t comp, const AtmosphereModel::Cell& c, bool scaled, float* out) const {
  const size_t nl = m_.levels();
  const std::vector<float>& s = scaled ? sigma_s_star_ : sigma_s_;
  const float* a = &s[(comp * nl + c.i) * nw_];
  const float* b = &s[(comp * nl + c.i + 1) * nw_];
  const float t = static_cast<float>(c.t);
  for (size_t w = 0; w < nw_; ++w) out[w] = a[w] + (b[w] - a[w]) * t;
}

// ---------------------------------------------------------------------------- sun tables

bool OrdersMethod::RayDepth(double r, double mu, std::vector<double>* tau, std::vector<double>* tau_f) const {
  const double R = m_.bottom_radius_m, top = m_.top_radius_m;
  tau->assign(nw_, 0.0);
  tau_f->assign(nw_, 0.0);
  const double disc_g = r * r * (mu * mu - 1.0) + R * R;
  if (mu < 0.0 && disc_g >= 0.0) return false;  // hits the ground
  const double length = -r * mu + std::sqrt(std::max(0.0, r * r * (mu * mu - 1.0) + top * top));
  const int pieces = s_.fine;
  const double h = length / pieces;
  static const double kG = 0.5773502691896257;
  std::vector<float> st(nw_), sts(nw_);
  for (int p = 0; p < pieces; ++p) {
    for (double g : {-kG, kG}) {
      const double t = (p + 0.5 + 0.5 * g) * h;
      const double rr = std::sqrt(r * r + 2.0 * r * mu * t + t * t);
      const AtmosphereModel::Cell cell = m_.Locate(rr - R);  // one lookup for both media
      SigmaT(cell, false, st.data());
      SigmaT(cell, true, sts.data());
      for (size_t w = 0; w < nw_; ++w) {
        (*tau)[w] += 0.5 * h * st[w];
        (*tau_f)[w] += 0.5 * h * (st[w] - sts[w]);
      }
    }
  }
  return true;
}

void OrdersMethod::BuildSunTables() {
  const double R = m_.bottom_radius_m, H = m_.top_radius_m - R;
  const int nr = s_.sun_nr;
  // Radius nodes of the unscaled table (the exact single scattering and the ground's direct sun
  // at the output): uniform in s(h) = (tau(0,h)/tau(0,H) + (h/H)^0.5) / 2, tau the vertical
  // optical depth at the grid's shortest wavelength - half the nodes quadratic in altitude (dense
  // near the ground), half where the extinction is. The scaled table (the sources of the
  // multiple-scattering tables) has the same nodes and blend (scaled_sun_exact; before the fifth
  // stop of 2026-11-23 quadratic in altitude and linear: "Sun transmittance" in
  // docs/sky-methods.md).
  const double tau_top = std::max(m_.VerticalOpticalDepth(0.0, H, 0), 1e-12);
  auto s_of = [&](double h) { return 0.5 * (m_.VerticalOpticalDepth(0.0, h, 0) / tau_top + std::sqrt(h / H)); };
  for (double h : AltitudesUniformIn(s_of, nr, H)) sun_.r.push_back(R + h);
  if (s_.scaled_sun_exact) {
    sun_star_.r = sun_.r;
  } else {
    for (int i = 0; i < nr; ++i) {
      const double u = static_cast<double>(i) / (nr - 1);
      sun_star_.r.push_back(R + H * u * u);
    }
  }
  sun_.log_blend = true;
  sun_star_.log_blend = s_.scaled_sun_exact;
  // Sun zenith nodes (deg): 1 deg to 80, sun_low_step_deg (0.1) to 110 (the horizon and the Earth's
  // shadow), 1 deg to 125.
  for (double a = 0; a < 80; a += 1.0) sun_theta_deg_.push_back(a);
  const int n_low = static_cast<int>(std::lround(30.0 / s_.sun_low_step_deg));
  for (int k = 0; k < n_low; ++k) sun_theta_deg_.push_back(80.0 + k * s_.sun_low_step_deg);
  for (double a = 110; a <= 125 + 1e-9; a += 1.0) sun_theta_deg_.push_back(a);
  const size_t nt = sun_theta_deg_.size();
  sun_theta_loc_ = IntervalLocator(sun_theta_deg_);
  // Average over the solar disk in elevation: offsets delta_i across the disk with weights =
  // chord length x limb darkening (mean over the wavelengths' coefficients, a stated
  // simplification: the limb darkening shapes the penumbra only), 16-point midpoint rule.
  const double alpha = m_.sun.angular_radius_rad;
  constexpr int kDisk = 16;
  std::vector<double> delta(kDisk), weight(kDisk);
  double wsum = 0.0;
  for (int i = 0; i < kDisk; ++i) {
    const double y = -1.0 + (i + 0.5) * 2.0 / kDisk;  // vertical position on the disk / radius
    delta[i] = y * alpha;
    // Integrate the limb-darkened radiance along the chord at height y (32 points).
    double chord = 0.0;
    const double half = std::sqrt(1.0 - y * y);
    for (int q = 0; q < 32; ++q) {
      const double x = -half + (q + 0.5) * 2.0 * half / 32;
      const double rr = std::min(1.0, std::sqrt(x * x + y * y));
      const double mu = std::sqrt(1.0 - rr * rr);
      double ld = 1.0;
      if (!m_.sun.limb_coefficients.empty()) {
        ld = 0.0;
        double p = 1.0;
        const std::array<double, 6>& a = m_.sun.limb_coefficients[m_.sun.limb_coefficients.size() / 2];
        for (int c = 0; c < 6; ++c) {
          ld += a[static_cast<size_t>(c)] * p;
          p *= mu;
        }
      }
      chord += ld * 2.0 * half / 32;
    }
    weight[i] = chord;
    wsum += chord;
  }
  for (double& v : weight) v /= wsum;
  // The optical depths: one ray per (radius, sun node) gives both tables' where they share
  // their radii (scaled_sun_exact; each table had its own rays before, a tenth of a hazed
  // build), each table's own rays where not. The values are the same either way.
  const size_t nrt = static_cast<size_t>(nr) * nt;
  std::vector<float> base_plain(nrt * nw_), base_star(nrt * nw_);
  auto depths = [&](const std::vector<double>& radii, bool plain, bool star) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nrt, 8), [&](const tbb::blocked_range<size_t>& rg) {
      std::vector<double> tau, tau_f;
      for (size_t k = rg.begin(); k != rg.end(); ++k) {
        const size_t i = k / nt, j = k % nt;
        const bool clear = RayDepth(radii[i], std::cos(sun_theta_deg_[j] * kDeg), &tau, &tau_f);
        for (size_t w = 0; w < nw_; ++w) {
          if (plain) base_plain[k * nw_ + w] = clear ? static_cast<float>(std::exp(-tau[w])) : 0.0f;
          if (star) base_star[k * nw_ + w] = clear ? static_cast<float>(std::exp(-(tau[w] - tau_f[w]))) : 0.0f;
        }
      }
    });
  };
  if (sun_.r == sun_star_.r) {
    depths(sun_.r, true, true);
  } else {
    depths(sun_.r, true, false);
    depths(sun_star_.r, false, true);
  }
  // The disk's elevation offsets located once per (sun node, disk point), for every radius.
  std::vector<Lerp> disk_at(nt * kDisk);
  for (size_t j = 0; j < nt; ++j) {
    for (int d = 0; d < kDisk; ++d) disk_at[j * kDisk + static_cast<size_t>(d)] = Locate(sun_theta_deg_, sun_theta_deg_[j] - delta[d] / kDeg);
  }
  for (SunTable* tb : {&sun_, &sun_star_}) {
    tb->loc = IntervalLocator(tb->r);
    const std::vector<float>& base = tb == &sun_star_ ? base_star : base_plain;
    tb->t.assign(nrt * nw_, 0.0f);
    // Each node sums its disk points in the same order whichever thread takes its radius.
    tbb::parallel_for(size_t{0}, static_cast<size_t>(nr), [&](size_t i) {
      for (size_t j = 0; j < nt; ++j) {
        for (int d = 0; d < kDisk; ++d) {
          const Lerp& l = disk_at[j * kDisk + static_cast<size_t>(d)];
          const float* a = &base[(i * nt + l.i) * nw_];
          const float* b = &base[(i * nt + l.i + 1) * nw_];
          const float t = static_cast<float>(l.t), wt = static_cast<float>(weight[d]);
          float* o = &tb->t[(i * nt + j) * nw_];
          for (size_t w = 0; w < nw_; ++w) o[w] += wt * (a[w] + (b[w] - a[w]) * t);
        }
      }
    });
    if (!tb->log_blend) continue;
    tb->lt.assign(tb->t.size(), 0.0f);
    tb->pos.assign(tb->t.size() / nw_, 1);
    tbb::parallel_for(size_t{0}, tb->pos.size(), [&](size_t n) {
      for (size_t w = 0; w < nw_; ++w) {
        const float v = tb->t[n * nw_ + w];
        if (v > 0.0f) tb->lt[n * nw_ + w] = std::log(v);
        else tb->pos[n] = 0;
      }
    });
  }
}

// Bilinear in (radius, sun zenith). The unscaled table blends the logarithm where the four nodes
// differ by more than 2 % and are all lit: the transmittance is exponential in both (e^-tau, tau
// growing by ~4 per km of descent through the hazed sky's aerosol with the sun 5 deg high), and a
// linear blend of e^-tau between nodes a few hundred metres apart overestimated it - the exact
// single scattering at 87 deg view zenith, sun 85 deg, came out +7.6 % and +4.7 % against the
// path tracer's first order (+1.4 / -1.5 % with the logarithm and the nodes that follow the
// optical depth; docs/sky-methods.md "Sun transmittance"). Where the nodes agree within 2 % the
// linear blend is within 3e-5 of the logarithmic one and costs no exp; where one node is in the
// Earth's full shadow (0) the blend stays linear.
void OrdersMethod::SunTransmittanceAt(const Lerp& lr, double mu_s, bool scaled, float* out) const {
  const SunTable& tb = scaled ? sun_star_ : sun_;
  const Lerp lt = Locate(sun_theta_loc_, std::acos(std::clamp(mu_s, -1.0, 1.0)) / kDeg);
  const size_t nt = sun_theta_deg_.size();
  const size_t n00 = lr.i * nt + lt.i, n10 = (lr.i + 1) * nt + lt.i;
  const float* p00 = &tb.t[n00 * nw_];
  const float* p01 = &tb.t[(n00 + 1) * nw_];
  const float* p10 = &tb.t[n10 * nw_];
  const float* p11 = &tb.t[(n10 + 1) * nw_];
  const float a = static_cast<float>(lr.t), b = static_cast<float>(lt.t);
  const float w00 = (1 - a) * (1 - b), w01 = (1 - a) * b, w10 = a * (1 - b), w11 = a * b;
  if (tb.log_blend && tb.pos[n00] && tb.pos[n00 + 1] && tb.pos[n10] && tb.pos[n10 + 1]) {
    // The shortest wavelength varies most (Rayleigh): it decides.
    const float lo = std::min(std::min(p00[0], p01[0]), std::min(p10[0], p11[0]));
    const float hi = std::max(std::max(p00[0], p01[0]), std::max(p10[0], p11[0]));
    if (hi > 1.02f * lo) {
      const float* l00 = &tb.lt[n00 * nw_];
      const float* l01 = &tb.lt[(n00 + 1) * nw_];
      const float* l10 = &tb.lt[n10 * nw_];
      const float* l11 = &tb.lt[(n10 + 1) * nw_];
      for (size_t w = 0; w < nw_; ++w) out[w] = ExpF(w00 * l00[w] + w01 * l01[w] + w10 * l10[w] + w11 * l11[w]);
      return;
    }
  }
  for (size_t w = 0; w < nw_; ++w) out[w] = w00 * p00[w] + w01 * p01[w] + w10 * p10[w] + w11 * p11[w];
}

// ---------------------------------------------------------------------------- MS tables

void OrdersMethod::BuildRadiusNodes() {
  const double R = m_.bottom_radius_m, H = m_.top_radius_m - R;
  // Nodes uniform in s(h) = (tau(0,h)/tau(0,H) + (h/H)^0.4) / 2, tau the vertical optical depth
  // at the grid's middle wavelength: the altitude part alone is h_i = H (i/(n-1))^2.5 (0, 0.12,
  // 0.65, 1.8, 3.7, 6.4, 10 ... 100 km for n = 16), the optical-depth part puts half the nodes
  // where the extinction is. Without it a 2 km thick water cloud at 3.5-5.5 km (cloudy4) fell
  // between the nodes 3.7 and 6.4 km, its sources were interpolated from outside the cloud, and
  // the sky under it came out 3-5x too dark.
  const size_t wref = m_.wavelengths() / 2;
  const double tau_total = std::max(m_.VerticalOpticalDepth(0.0, H, wref), 1e-12);
  auto s_of = [&](double h) { return 0.5 * (m_.VerticalOpticalDepth(0.0, h, wref) / tau_total + std::pow(h / H, 0.4)); };
  for (double h : AltitudesUniformIn(s_of, s_.nr, H)) radius_.push_back(R + h);
  const double r_obs = R + std::clamp(observer_altitude_m_, 0.0, H * 0.999);
  auto it = std::lower_bound(radius_.begin(), radius_.end(), r_obs);
  if (it != radius_.end() && std::abs(*it - r_obs) < 1e-6) {
    obs_index_ = static_cast<size_t>(it - radius_.begin());
  } else {
    obs_index_ = static_cast<size_t>(it - radius_.begin());
    radius_.insert(it, r_obs);
  }
  for (double d : s_.sun_deg) sun_theta_rad_.push_back(d * kDeg);
  ns_ = sun_theta_rad_.size();
  nu_ = static_cast<size_t>(s_.nup + s_.ndn);
}

// View nodes, in ascending mu, placed in the view zenith angle theta (theta_h the horizon's,
// > 90 deg): k < ndn below the horizon, theta = theta_h + (pi - theta_h)(1 - s)^p, s = k/(ndn-1),
// from the nadir to the horizon's lower side; k >= ndn above it, theta = theta_h (1 - s^p),
// s = (k-ndn)/(nup-1), from the horizon's upper side to the zenith. Both sets include their ends
// (the horizon on each side of the discontinuity, the zenith, the nadir) and are dense next to
// the horizon (p = 2: 0.4 deg from it with 16 up nodes); integrals use the trapezoid rule in mu
// on each set. Until 2026-11-23 the nodes were placed in mu (mu = mu_h + (1 - mu_h) s^2): as
// dense at the horizon, but the last up node was 29.5 deg from the zenith and the first down node
// 43 deg from the nadir; under a tau-8 cloud the sky at 85 deg came out 22 % dark.
double OrdersMethod::ViewMu(size_t k, double r) const {
  const bool down = k < static_cast<size_t>(s_.ndn);
  return ViewMuAt(down, static_cast<double>(down ? k : k - static_cast<size_t>(s_.ndn)), r);
}

double OrdersMethod::ViewMuAt(bool down, double f, double r) const {
  const double th = std::acos(HorizonMu(r));
  const double p = s_.view_power;
  if (down) return std::cos(th + (kPi - th) * std::pow(1.0 - f / (s_.ndn - 1), p));
  return std::cos(th * (1.0 - std::pow(f / (s_.nup - 1), p)));
}

double OrdersMethod::ViewWidth(size_t k, double r) const {
  // Trapezoid weight: half the distance between the neighbours within the node's own set.
  const bool down = k < static_cast<size_t>(s_.ndn);
  const size_t lo = down ? 0 : static_cast<size_t>(s_.ndn);
  const size_t hi = down ? static_cast<size_t>(s_.ndn) - 1 : nu_ - 1;
  const double m = ViewMu(k, r);
  const double left = k > lo ? ViewMu(k - 1, r) : m;
  const double right = k < hi ? ViewMu(k + 1, r) : m;
  return 0.5 * (right - left);
}

void OrdersMethod::ViewIndex(double mu, double r, size_t* k0, size_t* k1, double* t) const {
  const double mh = HorizonMu(r);
  const double th = std::acos(mh), theta = std::acos(std::clamp(mu, -1.0, 1.0));
  const double ip = 1.0 / s_.view_power;
  double f;
  size_t base, n;
  if (mu >= mh) {
    const double s = std::pow(std::clamp(1.0 - theta / th, 0.0, 1.0), ip);
    f = s * (s_.nup - 1);
    base = static_cast<size_t>(s_.ndn);
    n = static_cast<size_t>(s_.nup);
  } else {
    const double s = 1.0 - std::pow(std::clamp((theta - th) / (kPi - th), 0.0, 1.0), ip);
    f = s * (s_.ndn - 1);
    base = 0;
    n = static_cast<size_t>(s_.ndn);
  }
  f = std::clamp(f, 0.0, static_cast<double>(n - 1));
  const size_t i = std::min(static_cast<size_t>(f), n - 2);
  *k0 = base + i;
  *k1 = base + i + 1;
  *t = f - static_cast<double>(i);
}

OrdersMethod::RadialView OrdersMethod::RadialViewAt(double r, double mu) const {
  RadialView v;
  const Lerp lr = Locate(radius_, r);
  v.ri = lr.i;
  v.wr[0] = 1.0 - lr.t;
  v.wr[1] = lr.t;
  for (int dr = 0; dr < 2; ++dr) {
    if (v.wr[dr] == 0.0) continue;
    ViewIndex(mu, radius_[lr.i + static_cast<size_t>(dr)], &v.k0[dr], &v.k1[dr], &v.tk[dr]);
  }
  return v;
}

OrdersMethod::SunAzimuth OrdersMethod::SunAzimuthAt(double theta_s, double cos_phi) const {
  SunAzimuth sa;
  if (theta_s > sun_theta_rad_.back()) {
    sa.si = kNoSun;
    return sa;
  }
  const Lerp ls = Locate(sun_theta_rad_, theta_s);
  size_t q0;
  const double tq = AzimuthBlend(std::acos(std::clamp(cos_phi, -1.0, 1.0)), s_.azimuth_even, &q0);
  sa.si = static_cast<uint16_t>(ls.i);
  sa.q0 = static_cast<uint16_t>(q0);
  sa.ts = static_cast<float>(ls.t);
  sa.tq = static_cast<float>(tq);
  return sa;
}

void OrdersMethod::Interpolate(const Table& tab, const RadialView& rv, const SunAzimuth& sa, double weight,
                               float* acc) const {
  if (sa.si == kNoSun) return;  // beyond the last sun node: no light
  const Lerp ls{sa.si, sa.ts};
  const size_t q0 = sa.q0;
  const double tq = sa.tq;
  for (int dr = 0; dr < 2; ++dr) {
    const size_t ri = rv.ri + static_cast<size_t>(dr);
    const double wr = rv.wr[dr];
    if (wr == 0.0) continue;
    const size_t k0 = rv.k0[dr], k1 = rv.k1[dr];
    const double tk = rv.tk[dr];
    for (int ds = 0; ds < 2; ++ds) {
      const size_t si = ls.i + static_cast<size_t>(ds);
      const double ws = wr * (ds ? ls.t : 1.0 - ls.t);
      if (ws == 0.0) continue;
      for (int dk = 0; dk < 2; ++dk) {
        const double wk = ws * (dk ? tk : 1.0 - tk);
        if (wk == 0.0) continue;
        const size_t k = dk ? k1 : k0;
        for (int dq = 0; dq < 2; ++dq) {
          const float wq = static_cast<float>(weight * wk * (dq ? tq : 1.0 - tq));
          if (wq == 0.0f) continue;
          const float* v = &tab[Cell(ri, si, k, q0 + static_cast<size_t>(dq)) * nw_];
          for (size_t w = 0; w < nw_; ++w) acc[w] += wq * v[w];
        }
      }
    }
  }
}

void OrdersMethod::SolveMultipleScattering(const ProgressFn& progress) {
  const double R = m_.bottom_radius_m, top = m_.top_radius_m;
  const size_t nr = radius_.size(), nphi = static_cast<size_t>(s_.nphi);
  const size_t cells = nr * ns_ * nu_ * nphi;
  const size_t nt = static_cast<size_t>(s_.nt);

  // Ray families: for each (radius node, view node) the table ray's steps (shared by every sun
  // node and azimuth): midpoints t, widths dt, their radius and local view cosine, the scaled
  // transmittance from the start, and the ground hit.
  struct Family {
    std::vector<double> t, r, mu;  // the step's representative point, its radius and view cosine
    // [step * nw + w]: the integral of the scaled transmittance over the step, int T* dt (m),
    // exact for a medium uniform within the step (the step may be optically thick).
    std::vector<float> wt;
    std::vector<float> ssc;    // [step * nw + w] scaled scattering coefficient sigma_s* at the step (m^-1)
    std::vector<RadialView> rv;  // the interpolation's radius/view part at each step
    // The same as table offsets: per step the 4 (radius, view) corners' cell offsets
    // Cell(ri, 0, k, 0) and weights (Cell() is a sum of a radius/view part and a sun/azimuth part).
    struct Corners {
      uint32_t off[4];
      float w[4];
    };
    std::vector<Corners> rc;
    std::vector<float> g;      // [step * nw + w] wt x ssc: the step's weight of J (m^-1 m)
    bool ground = false;
    double d = 0.0;
    std::vector<float> trans_end;  // at the ground
  };
  std::vector<Family> fam(nr * nu_);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * nu_, 1), [&](const tbb::blocked_range<size_t>& rg) {
    std::vector<float> st(nw_), sc(nw_);
    for (size_t idx = rg.begin(); idx != rg.end(); ++idx) {
      const size_t ri = idx / nu_, k = idx % nu_;
      const double r = radius_[ri], mu = ViewMu(k, r);
      Family& f = fam[idx];
      const double disc_g = r * r * (mu * mu - 1.0) + R * R;
      f.ground = mu < 0.0 && disc_g >= 0.0;
      f.d = f.ground ? -r * mu - std::sqrt(std::max(0.0, disc_g))
                     : -r * mu + std::sqrt(std::max(0.0, r * r * (mu * mu - 1.0) + top * top));
      if (f.d <= 0.0) {  // on the ground looking down: nothing but the ground
        f.d = 0.0;
        f.trans_end.assign(nw_, 1.0f);
        continue;
      }
      // Fine optical depth (reference wavelength: the middle of the grid) to place the steps
      // uniformly in (tau_ref/tau_total + t/d)/2: dense where the medium is.
      const int nf = s_.fine;
      std::vector<double> cum(static_cast<size_t>(nf) + 1, 0.0);
      std::vector<std::vector<float>> cum_w(static_cast<size_t>(nf) + 1, std::vector<float>(nw_, 0.0f));
      const size_t wref = nw_ / 2;
      for (int p = 0; p < nf; ++p) {
        const double tm = (p + 0.5) * f.d / nf;
        const double rr = std::sqrt(r * r + 2.0 * r * mu * tm + tm * tm);
        SigmaT(rr - R, true, st.data());
        cum[static_cast<size_t>(p) + 1] = cum[static_cast<size_t>(p)] + st[wref] * f.d / nf;
        for (size_t w = 0; w < nw_; ++w) cum_w[static_cast<size_t>(p) + 1][w] = cum_w[static_cast<size_t>(p)][w] + st[w] * static_cast<float>(f.d / nf);
      }
      // The optical-depth part of s saturates at tau_cap: light from deeper than that does not
      // reach the ray's start (e^-12 = 6e-6), and a ray along the inside of a thick layer (a
      // horizontal ray in a 1 km cloud of optical depth 8 runs through tau ~ 900) would
      // otherwise spread its steps over optical depths that contribute nothing.
      const double tau_cap = s_.tau_cap;
      const double tau_total = std::max(std::min(cum.back(), tau_cap), 1e-12);
      // Parameter s(t) at the fine nodes; invert for step edges.
      std::vector<double> s_at(static_cast<size_t>(nf) + 1);
      for (int p = 0; p <= nf; ++p) s_at[static_cast<size_t>(p)] = 0.5 * (std::min(cum[static_cast<size_t>(p)], tau_cap) / tau_total + static_cast<double>(p) / nf);
      auto t_of_s = [&](double sv) {
        const Lerp l = Locate(s_at, sv);
        return (static_cast<double>(l.i) + l.t) * f.d / nf;
      };
      f.wt.resize(nt * nw_);
      f.ssc.assign(nt * nw_, 0.0f);
      // Position of t on the fine sub-grid: the piece and the fraction into it.
      auto fine_at = [&](double tv) {
        const double pf = std::clamp(tv / f.d * nf, 0.0, static_cast<double>(nf));
        const size_t pi = std::min(static_cast<size_t>(pf), static_cast<size_t>(nf) - 1);
        return Lerp{pi, pf - static_cast<double>(pi)};
      };
      auto tau_at = [&](double tv, size_t w) {
        const Lerp l = fine_at(tv);
        return cum_w[l.i][w] + (cum_w[l.i + 1][w] - cum_w[l.i][w]) * l.t;
      };
      for (size_t m = 0; m < nt; ++m) {
        const double t0 = t_of_s(static_cast<double>(m) / nt), t1 = t_of_s(static_cast<double>(m + 1) / nt);
        // Exponential integration (the step's medium taken as uniform): int_t0^t1 T* dt =
        // T*(t0) dt (1 - e^-dtau)/dtau, and the sources are taken at the centroid of that
        // weight, t0 + dt (1/dtau - 1/(e^dtau - 1)) at the reference wavelength (the midpoint
        // for a thin step, near t0 for a thick one). The midpoint rule with T*(t_mid) lost
        // 0.7 % of a step of optical depth 0.4 and everything of a step of 45.
        const double h = t1 - t0;
        const double a = tau_at(t1, wref) - tau_at(t0, wref);
        const double g = a < 1e-3 ? 0.5 - a / 12.0 : 1.0 / a - 1.0 / std::expm1(a);
        double tm = t0 + h * g;
        if (s_.tau_centroid && a >= 1e-3) {
          // The centroid in optical depth, tau0 + g a, whatever the medium's shape within the
          // step (the weight is e^-tau dtau in optical depth): the point where that depth is
          // reached, inside the medium, never in the clear air of a step that straddles a
          // cloud's edge (that lost the step's sources: under a tau-8 layer the sky came out
          // 10-20 % dark once the scaled sun table no longer overestimated the sun there).
          const Lerp l0 = fine_at(t0);
          const double tau0 = cum[l0.i] + (cum[l0.i + 1] - cum[l0.i]) * l0.t;
          const Lerp l = Locate(cum, tau0 + g * a);
          tm = std::clamp((static_cast<double>(l.i) + l.t) * f.d / nf, t0, t1);
        }
        f.t.push_back(tm);
        const double rr = std::sqrt(r * r + 2.0 * r * mu * tm + tm * tm);
        f.r.push_back(rr);
        f.mu.push_back((r * mu + tm) / rr);
        f.rv.push_back(RadialViewAt(rr, f.mu.back()));
        const AtmosphereModel::Cell cell = m_.Locate(rr - R);  // one lookup for the step's media
        for (size_t c = 0; c < nc_; ++c) {
          SigmaS(c, cell, true, sc.data());
          for (size_t w = 0; w < nw_; ++w) f.ssc[m * nw_ + w] += sc[w];
        }
        // The step's weight of J: int T* sigma_s* dt taken as sigma_s*/sigma_t* at the point times
        // the exact int T* sigma_t* dt = T*(t0) (1 - e^-dtau) (step_albedo), or as sigma_s* at the
        // point times the exact int T* dt (before 2026-11-23): where the point's extinction
        // exceeds the step's mean (a dense cloud's steps) that weighted J by more than the light
        // the step can scatter, and cloudy5's orders grew without end (docs/sky-methods.md).
        SigmaT(cell, true, st.data());
        for (size_t w = 0; w < nw_; ++w) {
          const double tau0 = tau_at(t0, w), dtau = std::max(0.0, tau_at(t1, w) - tau0);
          if (s_.step_albedo && dtau > 1e-6 && st[w] > 0.0f) {
            f.wt[m * nw_ + w] = static_cast<float>(-std::exp(-tau0) * std::expm1(-dtau) / st[w]);
          } else {
            const double phi = dtau > 1e-6 ? -std::expm1(-dtau) / dtau : 1.0 - 0.5 * dtau;
            f.wt[m * nw_ + w] = static_cast<float>(std::exp(-tau0) * h * phi);
          }
        }
      }
      f.trans_end.resize(nw_);
      for (size_t w = 0; w < nw_; ++w) f.trans_end[w] = std::exp(-cum_w.back()[w]);
      f.g.resize(nt * nw_);
      for (size_t i = 0; i < nt * nw_; ++i) f.g[i] = f.wt[i] * f.ssc[i];
      for (const RadialView& v : f.rv) {
        Family::Corners c{};
        for (int dr = 0; dr < 2; ++dr) {
          const size_t rn = std::min(v.ri + static_cast<size_t>(dr), nr - 1);
          for (int dk = 0; dk < 2; ++dk) {
            const size_t kk = dk ? v.k1[dr] : v.k0[dr];
            c.off[2 * dr + dk] = static_cast<uint32_t>(Cell(rn, 0, kk, 0));
            c.w[2 * dr + dk] = static_cast<float>(v.wr[dr] * (dk ? v.tk[dr] : 1.0 - v.tk[dr]));
          }
        }
        f.rc.push_back(c);
      }
    }
  });

  // Per-cell geometry helpers.
  auto cell_geometry = [&](size_t ri, size_t si, size_t k, size_t q, double* mu, double* nu) {
    const double r = radius_[ri];
    *mu = ViewMu(k, r);
    const double phi = (q + 0.5) * kPi / s_.nphi;
    const double ts = sun_theta_rad_[si];
    *nu = std::sqrt(std::max(0.0, 1.0 - *mu * *mu)) * std::cos(phi) * std::sin(ts) + *mu * std::cos(ts);
  };

  // Irradiance at the ground from a table of radiance (upper view nodes at radius node 0):
  // E[si*nw + w] = sum over up nodes and both azimuth halves of L mu dOmega.
  auto ground_irradiance = [&](const Table& L, std::vector<float>* E) {
    E->assign(ns_ * nw_, 0.0f);
    for (size_t si = 0; si < ns_; ++si) {
      for (size_t k = static_cast<size_t>(s_.ndn); k < nu_; ++k) {
        const double mu = ViewMu(k, R), dmu = ViewWidth(k, R);
        for (size_t q = 0; q < nphi; ++q) {
          const float wgt = static_cast<float>(mu * dmu * 2.0 * kPi / s_.nphi);
          const float* v = &L[Cell(0, si, k, q) * nw_];
          for (size_t w = 0; w < nw_; ++w) (*E)[si * nw_ + w] += wgt * v[w];
        }
      }
    }
  };
  auto interp_E = [&](const std::vector<float>& E, double theta_s, float* out) {
    if (theta_s > sun_theta_rad_.back()) {
      std::fill(out, out + nw_, 0.0f);
      return;
    }
    const Lerp l = Locate(sun_theta_rad_, theta_s);
    for (size_t w = 0; w < nw_; ++w) {
      out[w] = static_cast<float>(E[l.i * nw_ + w] * (1.0 - l.t) + E[(l.i + 1) * nw_ + w] * l.t);
    }
  };

  // --- order 1 (scaled problem) at every node
  // L = L_{n-1} while order n is computed into Lnext; Lprev = L_{n-2} (for the ratio tests).
  Table L, J, Lnext, Lprev;
  for (Table* t : {&L, &J, &Lnext, &Lprev}) ZeroTable(t, cells * nw_);
  std::vector<float> E0(ns_ * nw_);  // direct sun at the ground (scaled transmittance)
  {
    std::vector<float> tr(nw_);
    for (size_t si = 0; si < ns_; ++si) {
      const double mus = std::cos(sun_theta_rad_[si]);
      SunTransmittance(R, mus, true, tr.data());
      for (size_t w = 0; w < nw_; ++w) E0[si * nw_ + w] = static_cast<float>(sun_e_[w] * std::max(0.0, mus)) * tr[w];
    }
  }
  auto phase_star = [&](size_t c, double mu, size_t w) {
    const double g = (mu + 1.0) * 0.5 * (kPhaseGrid - 1);
    const size_t gi = std::min(static_cast<size_t>(g), static_cast<size_t>(kPhaseGrid - 2));
    const float t = static_cast<float>(g - static_cast<double>(gi));
    const float a = phase_star_[(c * kPhaseGrid + gi) * nw_ + w], b = phase_star_[(c * kPhaseGrid + gi + 1) * nw_ + w];
    return a + (b - a) * t;
  };
  // The sun/azimuth interpolation position of every (cell, step), shared by all orders (saves
  // two acos and a node search per lookup and order; order 1 fills it); computed per lookup
  // instead if it would take more than 768 MiB.
  std::vector<SunAzimuth> sun_az;
  if (cells * nt * sizeof(SunAzimuth) <= (size_t{768} << 20)) sun_az.resize(cells * nt);
  auto step_sun_azimuth = [&](const Family& f, size_t m, double r, double ts, double nu) {
    const double mus = std::clamp((r * std::cos(ts) + f.t[m] * nu) / f.r[m], -1.0, 1.0);
    const double mu2 = f.mu[m];
    const double denom = std::sqrt(std::max(1e-12, (1.0 - mu2 * mu2) * (1.0 - mus * mus)));
    return SunAzimuthAt(std::acos(mus), (nu - mu2 * mus) / denom);
  };
  ReportProgress(progress, "orders: order 1", 0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * ns_ * nu_, 4), [&](const tbb::blocked_range<size_t>& rg) {
    std::vector<float> tsun(nw_), src(nw_), acc(nw_), pc(nc_ * nw_), eg(nw_), ssc;
    for (size_t idx = rg.begin(); idx != rg.end(); ++idx) {
      const size_t ri = idx / (ns_ * nu_), si = (idx / nu_) % ns_, k = idx % nu_;
      const Family& f = fam[ri * nu_ + k];
      const double r = radius_[ri], ts = sun_theta_rad_[si];
      // sigma_s* of every component at the family's steps, the same for all its azimuths (it was
      // located and interpolated once per azimuth node: 36 times over for high).
      ssc.resize(f.t.size() * nc_ * nw_);
      for (size_t m = 0; m < f.t.size(); ++m) {
        const AtmosphereModel::Cell cm = m_.Locate(f.r[m] - R);
        for (size_t c = 0; c < nc_; ++c) SigmaS(c, cm, true, &ssc[(m * nc_ + c) * nw_]);
      }
      for (size_t q = 0; q < nphi; ++q) {
        double mu, nu;
        cell_geometry(ri, si, k, q, &mu, &nu);
        for (size_t c = 0; c < nc_; ++c) {
          for (size_t w = 0; w < nw_; ++w) pc[c * nw_ + w] = phase_star(c, nu, w);
        }
        std::fill(acc.begin(), acc.end(), 0.0f);
        for (size_t m = 0; m < f.t.size(); ++m) {
          const double mus = (r * std::cos(ts) + f.t[m] * nu) / f.r[m];
          SunTransmittance(f.r[m], mus, true, tsun.data());
          std::fill(src.begin(), src.end(), 0.0f);
          for (size_t c = 0; c < nc_; ++c) {
            const float* sv = &ssc[(m * nc_ + c) * nw_];
            for (size_t w = 0; w < nw_; ++w) src[w] += sv[w] * pc[c * nw_ + w];
          }
          for (size_t w = 0; w < nw_; ++w) acc[w] += f.wt[m * nw_ + w] * src[w] * tsun[w] * static_cast<float>(sun_e_[w]);
          if (!sun_az.empty()) sun_az[Cell(ri, si, k, q) * nt + m] = step_sun_azimuth(f, m, r, ts, nu);
        }
        if (f.ground) {
          const double mus_g = (r * std::cos(ts) + f.d * nu) / R;
          interp_E(E0, std::acos(std::clamp(mus_g, -1.0, 1.0)), eg.data());
          for (size_t w = 0; w < nw_; ++w) acc[w] += f.trans_end[w] * static_cast<float>(albedo_[w] / kPi) * eg[w];
        }
        std::copy(acc.begin(), acc.end(), &L[Cell(ri, si, k, q) * nw_]);
      }
    }
  });

  // --- orders 2, 3, ...
  ms_.assign(ns_ * nu_ * nphi * nw_, 0.0f);
  ZeroTable(&jms_, cells * nw_);
  const size_t nd = nu_ * nphi;  // directions per (radius, sun)
  std::vector<float> E(ns_ * nw_);
  double prev_norm = 0.0, prev_ratio = -1.0, prev_prev_ratio = -1.0;
  bool last_order_tail = false;
  const size_t wref = nw_ / 2;
  // The scattering step: J = sum_c sigma_s*_c P*_c applied to a radiance table, per radius a
  // (nd x nd) kernel per wavelength, stored per unit sigma_s*. The kernel depends on the radius
  // only, so it is built once and kept for every order when all radii fit in 768 MiB (medium:
  // 17 x 192^2 x nw floats, 60 MiB at 24 wavelengths), else rebuilt per order and radius.
  std::vector<double> ssc_total(nr * nw_, 0.0);  // sigma_s* at each radius node (m^-1)
  for (size_t ri = 0; ri < nr; ++ri) {
    std::vector<float> ssc(nw_);
    for (size_t c = 0; c < nc_; ++c) {
      SigmaS(c, radius_[ri] - R, true, ssc.data());
      for (size_t w = 0; w < nw_; ++w) ssc_total[ri * nw_ + w] += ssc[w];
    }
  }
  const size_t kernel_floats = nd * nd * nw_;
  // The mixture phase x scattering coefficient sum_c sigma_s*_c P*_c on the cos grid at a radius.
  auto mixture = [&](size_t ri) {
    std::vector<float> mix(static_cast<size_t>(kPhaseGrid) * nw_, 0.0f), ssc(nw_);
    for (size_t c = 0; c < nc_; ++c) {
      SigmaS(c, radius_[ri] - R, true, ssc.data());
      for (int g = 0; g < kPhaseGrid; ++g) {
        for (size_t w = 0; w < nw_; ++w) mix[static_cast<size_t>(g) * nw_ + w] += ssc[w] * phase_star_[(c * kPhaseGrid + static_cast<size_t>(g)) * nw_ + w];
      }
    }
    return mix;
  };
  // scale x the mixture at cosine mu, accumulated into out[w].
  auto mixture_at = [&](const std::vector<float>& mix, double mu, float scale, float* out) {
    const double g = (std::clamp(mu, -1.0, 1.0) + 1.0) * 0.5 * (kPhaseGrid - 1);
    const size_t gi = std::min(static_cast<size_t>(g), static_cast<size_t>(kPhaseGrid - 2));
    const float t = static_cast<float>(g - static_cast<double>(gi));
    const float* a = &mix[gi * nw_];
    const float* b = &mix[(gi + 1) * nw_];
    for (size_t w = 0; w < nw_; ++w) out[w] += scale * (a[w] + (b[w] - a[w]) * t);
  };
  // The view nodes at a radius: cosine, sine and trapezoid width in mu (both kernel builders).
  struct ViewNodes {
    std::vector<double> mu, sn, width;
  };
  auto view_nodes = [&](double r) {
    ViewNodes v{std::vector<double>(nu_), std::vector<double>(nu_), std::vector<double>(nu_)};
    for (size_t k = 0; k < nu_; ++k) {
      v.mu[k] = ViewMu(k, r);
      v.sn[k] = std::sqrt(std::max(0.0, 1.0 - v.mu[k] * v.mu[k]));
      v.width[k] = ViewWidth(k, r);
    }
    return v;
  };
  // The basis kernel's quadrature (both forms, matrix and modal): for every view sub-interval
  // (kernel_sub per view interval, midpoint rule in the view-node index f) and every output view
  // node k, the mixture phase at the 2 na azimuth offsets (m + 1/2) u, u = pi / (2 sub nphi),
  // into pm[m * nw + w]; then fn(k, kn, wk, dmu, pm) with kn the sub-interval's two view nodes, wk
  // their hat weights at its midpoint and dmu its width in mu. The node azimuths are
  // (q + 1/2) pi / nphi = (2 sub q + sub + 1/2) u, so every phi_q -+ phi_a is a half-integer
  // multiple of u and the phase is evaluated once per multiple.
  auto for_each_view_subsample = [&](double r, const std::vector<float>& mix, const std::vector<double>& vmu,
                                     const std::vector<double>& vsn, const auto& fn) {
    const int sub = s_.kernel_sub;
    const size_t na = nphi * 2 * static_cast<size_t>(sub);
    const double u = kPi / static_cast<double>(na);
    std::vector<double> cosm(2 * na);
    for (size_t m = 0; m < 2 * na; ++m) cosm[m] = std::cos((m + 0.5) * u);
    std::vector<float> pm(2 * na * nw_);
    for (int set = 0; set < 2; ++set) {
      const bool down = set == 0;
      const int n = down ? s_.ndn : s_.nup;
      const size_t base = down ? 0 : static_cast<size_t>(s_.ndn);
      for (int kk = 0; kk + 1 < n; ++kk) {
        for (int b = 0; b < sub; ++b) {
          const double f0 = kk + static_cast<double>(b) / sub, f1 = kk + static_cast<double>(b + 1) / sub;
          const double fm = 0.5 * (f0 + f1), tk = fm - kk;
          const double m2 = ViewMuAt(down, fm, r), s2 = std::sqrt(std::max(0.0, 1.0 - m2 * m2));
          const double dmu = std::abs(ViewMuAt(down, f1, r) - ViewMuAt(down, f0, r));
          const size_t kn[2] = {base + static_cast<size_t>(kk), base + static_cast<size_t>(kk) + 1};
          const double wk[2] = {1.0 - tk, tk};
          for (size_t k = 0; k < nu_; ++k) {
            const double cc = vmu[k] * m2, ss = vsn[k] * s2;
            std::fill(pm.begin(), pm.end(), 0.0f);
            for (size_t m = 0; m < 2 * na; ++m) mixture_at(mix, cc + ss * cosm[m], 1.0f, &pm[m * nw_]);
            fn(k, kn, wk, dmu, pm);
          }
        }
      }
    }
  };
  // The kernel integrated against the interpolation's basis: J(v_i) = int P(v_i . w) L(w) dw
  // with L(w) = sum_j L_j h_j(w), h_j the weight the table lookup gives node j at w (linear in
  // the view-node index f, and AzimuthBlend in the azimuth; both mirror halves of the azimuth).
  // Integrated by the midpoint rule on n sub-intervals of every view interval (in f, so as dense
  // as the nodes) and 2n of every azimuth interval. With the phase sampled at the nodes instead,
  // a node stands for its whole cell: at the zenith node (a cap ~9 deg across) the aerosol lobe,
  // ~5 deg wide after truncation at 3 deg, was counted as filling the cap, and the row's
  // normalisation then took that excess from every other direction (hazed, sun 70 deg, order 2
  // at the zenith -1.3 %, -2.4 % with 3 deg truncation; with this kernel +0.3 %).
  auto build_hat_kernel = [&](double r, const std::vector<float>& mix, const std::vector<double>& vmu,
                              const std::vector<double>& vsn, float* kernel) {
    const int sub = s_.kernel_sub;
    const size_t per = 2 * static_cast<size_t>(sub), na = nphi * per;
    const double u = kPi / static_cast<double>(na);
    std::vector<size_t> aq(na);
    std::vector<float> atq(na);
    for (size_t a = 0; a < na; ++a) {
      size_t q0;
      atq[a] = static_cast<float>(AzimuthBlend((a + 0.5) * u, s_.azimuth_even, &q0));
      aq[a] = q0;
    }
    std::vector<float> row(nphi * nw_);
    for_each_view_subsample(r, mix, vmu, vsn, [&](size_t k, const size_t* kn, const double* wk, double dmu, const std::vector<float>& pm) {
      for (size_t q = 0; q < nphi; ++q) {
        // The row of output node (k, q) over the azimuth nodes, for this view sub-interval.
        std::fill(row.begin(), row.end(), 0.0f);
        const long qa = static_cast<long>(q * per + static_cast<size_t>(sub));
        for (size_t a = 0; a < na; ++a) {
          const long dlt = qa - static_cast<long>(a);
          const size_t md = static_cast<size_t>(dlt >= 1 ? dlt - 1 : -dlt), ms = static_cast<size_t>(qa) + a;
          const float* pd = &pm[md * nw_];
          const float* ps = &pm[ms * nw_];
          const float w1 = atq[a], w0 = 1.0f - w1;
          float* r0 = &row[aq[a] * nw_];
          float* r1 = r0 + nw_;
          for (size_t w = 0; w < nw_; ++w) {
            const float v = pd[w] + ps[w];
            r0[w] += w0 * v;
            r1[w] += w1 * v;
          }
        }
        for (int x = 0; x < 2; ++x) {
          const float wgt = static_cast<float>(wk[x] * dmu * u);
          if (wgt == 0.0f) continue;
          float* out = &kernel[((k * nphi + q) * nd + kn[x] * nphi) * nw_];
          for (size_t e = 0; e < nphi * nw_; ++e) out[e] += wgt * row[e];
        }
      }
    });
  };
  auto build_kernel = [&](size_t ri, float* kernel) {
    const double r = radius_[ri];
    const std::vector<float> mix = mixture(ri);
    auto mix_at = [&](double mu, float scale, float* out) { mixture_at(mix, mu, scale, out); };
    std::fill(kernel, kernel + kernel_floats, 0.0f);
    std::vector<double> cos_dphi(nphi * nphi), cos_sphi(nphi * nphi);
    for (size_t q = 0; q < nphi; ++q) {
      for (size_t q2 = 0; q2 < nphi; ++q2) {
        const double phi = (q + 0.5) * kPi / s_.nphi, phi2 = (q2 + 0.5) * kPi / s_.nphi;
        cos_dphi[q * nphi + q2] = std::cos(phi - phi2);
        cos_sphi[q * nphi + q2] = std::cos(phi + phi2);
      }
    }
    const ViewNodes vn = view_nodes(r);
    const std::vector<double>&vmu = vn.mu, &vsn = vn.sn, &vwidth = vn.width;
    if (s_.kernel_sub > 0) {
      build_hat_kernel(r, mix, vmu, vsn, kernel);
    } else {
      for (size_t i = 0; i < nd; ++i) {
        const size_t k = i / nphi, q = i % nphi;
        for (size_t j = 0; j < nd; ++j) {
          const size_t k2 = j / nphi, q2 = j % nphi;
          const float wgt = static_cast<float>(vwidth[k2] * kPi / s_.nphi);
          float* out = &kernel[(i * nd + j) * nw_];
          const double cc = vmu[k] * vmu[k2], ss = vsn[k] * vsn[k2];
          mix_at(cc + ss * cos_dphi[q * nphi + q2], wgt, out);
          mix_at(cc + ss * cos_sphi[q * nphi + q2], wgt, out);
        }
      }
    }
    for (size_t i = 0; i < nd; ++i) {
      if (s_.normalise) {
        // Energy conservation of the discrete phase integral: every row must sum to
        // sigma_s* (the phase function integrates to 1 over incoming directions); point
        // sampling of a peaked phase on ~200 directions misses that by a few per cent.
        std::vector<double> row(nw_, 0.0);
        for (size_t j = 0; j < nd; ++j) {
          const float* kv = &kernel[(i * nd + j) * nw_];
          for (size_t w = 0; w < nw_; ++w) row[w] += kv[w];
        }
        std::vector<float> scale(nw_, 1.0f);
        for (size_t w = 0; w < nw_; ++w) scale[w] = row[w] > 0.0 ? static_cast<float>(ssc_total[ri * nw_ + w] / row[w]) : 1.0f;
        for (size_t j = 0; j < nd; ++j) {
          float* kv = &kernel[(i * nd + j) * nw_];
          for (size_t w = 0; w < nw_; ++w) kv[w] *= scale[w];
        }
      }
    }
  };
  // --- the kernel in azimuthal cosine modes. The phase depends on the azimuth only through the
  // difference of the two azimuths, and the table is even about the sun's plane: on the circle of
  // the 2 nphi azimuths theta_j = (j + 1/2) pi / nphi (the nodes and their mirror images) the
  // kernel is a circulant c(q - j), and with L even its product is diagonal in the cosine modes
  // cos(m theta), m < nphi (m = nphi vanishes at every node; m and 2 nphi - m fold onto each
  // other): S_m(k2) = sum_q L(k2, q) cos(m theta_q), T_m(k) = sum_k2 G_m(k, k2) S_m(k2),
  // J(k, q) = sum_m T_m(k) cos(m theta_q), with G_m = (m ? 2 : 1) / nphi sum_d c(d) cos(m d pi /
  // nphi). Per radius and sun node nu^2 nphi + 2 nu nphi^2 products instead of (nu nphi)^2: 10x
  // fewer for high (36 view x 24 azimuth nodes), whose matrix also did not fit in memory and was
  // rebuilt every order (half of high's build). The basis kernel's azimuth hats are translates of
  // one another except in the two end intervals, where the even blend (AzimuthBlend) departs from
  // the linear one: that difference is kept as two explicit columns per view node,
  // D_e(k, q, k2) applied to L(k2, q0) - L(k2, q0 + 1) (q0 = 0 and nphi - 2). The same values as
  // the matrix to float rounding (test MethodOrders.ModalKernelIsTheMatrixKernel).
  const bool modal = s_.kernel_modal;
  const size_t nm = nphi;
  std::vector<float> cos_mq(nm * nphi);
  for (size_t m = 0; m < nm; ++m) {
    for (size_t q = 0; q < nphi; ++q) cos_mq[m * nphi + q] = static_cast<float>(std::cos(static_cast<double>(m) * (q + 0.5) * kPi / s_.nphi));
  }
  const bool has_ends = s_.kernel_sub > 0 && s_.azimuth_even;
  const size_t modal_floats = nm * nu_ * nu_ * nw_;               // G[((m * nu + k) * nu + k2) * nw + w]
  const size_t end_floats = has_ends ? 2 * nu_ * nphi * nu_ * nw_ : 0;  // D[(((e * nu + k) * nphi + q) * nu + k2) * nw + w]
  auto build_modal_kernel = [&](size_t ri, float* G, float* D) {
    const double r = radius_[ri];
    const std::vector<float> mix = mixture(ri);
    const size_t N = 2 * nphi;
    const ViewNodes vn = view_nodes(r);
    const std::vector<double>&vmu = vn.mu, &vsn = vn.sn;
    std::vector<double> c(nu_ * nu_ * N * nw_, 0.0);  // c[((k * nu + k2) * N + d) * nw + w]
    std::vector<double> dc(end_floats, 0.0);
    std::vector<float> cd(nw_);
    if (s_.kernel_sub == 0) {
      // The phase at the nodes: c(d) = P(v_k . v_k2 at azimuth difference d pi / nphi) dmu_k2 pi / nphi.
      for (size_t k = 0; k < nu_; ++k) {
        for (size_t k2 = 0; k2 < nu_; ++k2) {
          const double wgt = vn.width[k2] * kPi / s_.nphi;
          for (size_t d = 0; d < N; ++d) {
            std::fill(cd.begin(), cd.end(), 0.0f);
            mixture_at(mix, vmu[k] * vmu[k2] + vsn[k] * vsn[k2] * std::cos(d * kPi / s_.nphi), 1.0f, cd.data());
            double* o = &c[((k * nu_ + k2) * N + d) * nw_];
            for (size_t w = 0; w < nw_; ++w) o[w] = wgt * cd[w];
          }
        }
      }
    } else {
      // The basis kernel (for_each_view_subsample's quadrature, as the matrix's): azimuth
      // sub-samples phi_a = (a + 1/2) u, u = pi / (2 sub nphi); the linear hat of node 0 is
      // 1 - |e| / (2 sub) at phi_a - theta_0 = e u, so c(d) = u sum_e hat(e) P(cos((2 sub d - e) u)).
      const int sub = s_.kernel_sub;
      const size_t per = 2 * static_cast<size_t>(sub), na = nphi * per;
      const double u = kPi / static_cast<double>(na);
      // The end intervals' departure of the even blend from the linear one at each sub-sample.
      struct EndSample {
        size_t a, e;
        double dw;  // (linear - even) weight of the interval's lower node
      };
      std::vector<EndSample> ends;
      if (has_ends) {
        for (size_t a = 0; a < na; ++a) {
          size_t q0, q1;
          const double te = AzimuthBlend((a + 0.5) * u, true, &q0), tl = AzimuthBlend((a + 0.5) * u, false, &q1);
          if (te != tl) ends.push_back({a, q0 == 0 ? size_t{0} : size_t{1}, tl - te});
        }
      }
      std::vector<double> hat(2 * per);
      for (size_t i = 0; i < 2 * per; ++i) hat[i] = 1.0 - std::abs(static_cast<double>(i) - static_cast<double>(per) + 0.5) / static_cast<double>(per);
      for_each_view_subsample(r, mix, vmu, vsn, [&](size_t k, const size_t* kn, const double* wk_hat, double dmu, const std::vector<float>& pm) {
        const double wk[2] = {wk_hat[0] * dmu * u, wk_hat[1] * dmu * u};
        for (size_t d = 0; d < N; ++d) {
          std::fill(cd.begin(), cd.end(), 0.0f);
          for (size_t i = 0; i < 2 * per; ++i) {
            // phi_a - theta_0 = e u with e = i - per + 1/2; the difference theta_d - phi_a = (2 sub d - e) u.
            const double nn = std::abs(static_cast<double>(per * d) - (static_cast<double>(i) - static_cast<double>(per) + 0.5));
            const float* pv = &pm[static_cast<size_t>(nn - 0.5) * nw_];
            const float h = static_cast<float>(hat[i]);
            for (size_t w = 0; w < nw_; ++w) cd[w] += h * pv[w];
          }
          for (int x = 0; x < 2; ++x) {
            double* o = &c[((k * nu_ + kn[x]) * N + d) * nw_];
            for (size_t w = 0; w < nw_; ++w) o[w] += wk[x] * cd[w];
          }
        }
        for (const EndSample& es : ends) {
          for (size_t q = 0; q < nphi; ++q) {
            const long dlt = static_cast<long>(q * per + static_cast<size_t>(sub)) - static_cast<long>(es.a);
            const size_t md = static_cast<size_t>(dlt >= 1 ? dlt - 1 : -dlt), ms = q * per + static_cast<size_t>(sub) + es.a;
            for (int x = 0; x < 2; ++x) {
              double* o = &dc[(((es.e * nu_ + k) * nphi + q) * nu_ + kn[x]) * nw_];
              const double wgt = wk[x] * es.dw;
              for (size_t w = 0; w < nw_; ++w) o[w] += wgt * (pm[md * nw_ + w] + pm[ms * nw_ + w]);
            }
          }
        }
      });
    }
    // Modes, with every row scaled to sum to sigma_s* (energy conservation, as the matrix's rows:
    // a row's sum is sum_k2 sum_d c(d), the same for every azimuth; the end columns add nothing).
    std::vector<double> cosd(nm * N);
    for (size_t m = 0; m < nm; ++m) {
      for (size_t d = 0; d < N; ++d) cosd[m * N + d] = std::cos(static_cast<double>(m * d) * kPi / s_.nphi);
    }
    std::vector<double> scale(nw_), v(nw_);
    for (size_t k = 0; k < nu_; ++k) {
      std::fill(scale.begin(), scale.end(), 0.0);
      for (size_t k2 = 0; k2 < nu_; ++k2) {
        for (size_t d = 0; d < N; ++d) {
          const double* cv = &c[((k * nu_ + k2) * N + d) * nw_];
          for (size_t w = 0; w < nw_; ++w) scale[w] += cv[w];
        }
      }
      for (size_t w = 0; w < nw_; ++w) scale[w] = s_.normalise && scale[w] > 0.0 ? ssc_total[ri * nw_ + w] / scale[w] : 1.0;
      for (size_t m = 0; m < nm; ++m) {
        const double f = (m == 0 ? 1.0 : 2.0) / s_.nphi;
        for (size_t k2 = 0; k2 < nu_; ++k2) {
          float* g = &G[((m * nu_ + k) * nu_ + k2) * nw_];
          // v[w] = sum_d c(d) cos(m d pi / nphi), d ascending, every wavelength at once.
          std::fill(v.begin(), v.end(), 0.0);
          for (size_t d = 0; d < N; ++d) {
            const double* cv = &c[((k * nu_ + k2) * N + d) * nw_];
            const double cm = cosd[m * N + d];
            for (size_t w = 0; w < nw_; ++w) v[w] += cv[w] * cm;
          }
          for (size_t w = 0; w < nw_; ++w) g[w] = static_cast<float>(f * scale[w] * v[w]);
        }
      }
      if (D != nullptr) {
        for (size_t e = 0; e < 2; ++e) {
          for (size_t q = 0; q < nphi; ++q) {
            for (size_t k2 = 0; k2 < nu_; ++k2) {
              const size_t o = (((e * nu_ + k) * nphi + q) * nu_ + k2) * nw_;
              for (size_t w = 0; w < nw_; ++w) D[o + w] = static_cast<float>(scale[w] * dc[o + w]);
            }
          }
        }
      }
    }
  };
  Table modal_kernels, end_kernels;
  if (modal) {
    ZeroTable(&modal_kernels, nr * modal_floats);
    ZeroTable(&end_kernels, nr * end_floats);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nr, 1), [&](const tbb::blocked_range<size_t>& rg) {
      for (size_t ri = rg.begin(); ri != rg.end(); ++ri) {
        build_modal_kernel(ri, &modal_kernels[ri * modal_floats], has_ends ? &end_kernels[ri * end_floats] : nullptr);
      }
    });
  }
  auto scatter_modal = [&](const Table& Lin, Table* Jout) {
    // The three products run 8 wavelengths wide with their sums kept in registers (ModalBlock4
    // and the others above), each sum in the order of the plain loops they replace (analysis: q
    // ascending; modes: k2 ascending; synthesis: m ascending, then the end columns e, k2
    // ascending), so the bytes are those of the loops that stored and reloaded every partial sum
    // (until 2026-11-24, sixth stop; docs/sky-methods.md "Cost cuts of 2026-11-24, sixth stop").
    // Tasks (radius, block of up to 16 sun nodes): G (nm nu^2 nw floats per radius, 9 MB for high)
    // and D (twice that) do not fit in cache and are read once per task; within a task each
    // G or D slice (nu nw floats) serves the 4 sub-blocks of 4 sun nodes while in L1. With
    // tasks of 4 sun nodes high's scatter was bound by reading G and D (27 MB per radius) 11
    // times per order.
    constexpr size_t kSub = 4, kSunBlock = 16;
    const size_t nsb = (ns_ + kSunBlock - 1) / kSunBlock;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * nsb, 1), [&](const tbb::blocked_range<size_t>& rg) {
      // S[b][m][k2][w], T[b][k][m][w], dL[b][e][k2][w]; a short last sub-block computes its
      // unused b from what the buffers hold (zeros or an earlier block's finite values) and
      // stores nothing of them.
      std::vector<float> S(kSunBlock * nm * nu_ * nw_, 0.0f), T(kSunBlock * nu_ * nm * nw_, 0.0f),
          dL(kSunBlock * 2 * nu_ * nw_, 0.0f), acc(kSub * nw_);
      const size_t sb = nm * nu_ * nw_, tb = nu_ * nm * nw_, db = 2 * nu_ * nw_;
      for (size_t idx = rg.begin(); idx != rg.end(); ++idx) {
        const size_t ri = idx / nsb, s0 = (idx % nsb) * kSunBlock, s1 = std::min(ns_, s0 + kSunBlock), nb = s1 - s0;
        const size_t nsub = (nb + kSub - 1) / kSub;
        const float* G = &modal_kernels[ri * modal_floats];
        // Analysis: S[b][m][k2] = sum_q L(k2, q) cos(m theta_q); the end differences dL.
        for (size_t b = 0; b < nb; ++b) {
          const float* lin = &Lin[((ri * ns_ + s0 + b) * nd) * nw_];
          for (size_t k2 = 0; k2 < nu_; ++k2) {
            ModalAnalysis(&lin[k2 * nphi * nw_], cos_mq.data(), nm, nphi, nw_, &S[b * sb + k2 * nw_], nu_ * nw_);
            if (has_ends) {
              for (size_t e = 0; e < 2; ++e) {
                const size_t q0 = e == 0 ? 0 : nphi - 2;
                const float* l0 = &lin[(k2 * nphi + q0) * nw_];
                float* dv = &dL[b * db + (e * nu_ + k2) * nw_];
                for (size_t w = 0; w < nw_; ++w) dv[w] = l0[w] - l0[nw_ + w];
              }
            }
          }
        }
        // Modes: T[b][k][m] = sum_k2 G_m(k, k2) S[b][m][k2].
        for (size_t m = 0; m < nm; ++m) {
          for (size_t k = 0; k < nu_; ++k) {
            for (size_t u = 0; u < nsub; ++u) {
              ModalBlock4(&G[(m * nu_ + k) * nu_ * nw_], nw_, &S[u * kSub * sb + m * nu_ * nw_], nw_, sb, nu_, nw_, acc.data());
              for (size_t b = 0; b < kSub; ++b) std::copy_n(&acc[b * nw_], nw_, &T[(u * kSub + b) * tb + (k * nm + m) * nw_]);
            }
          }
        }
        // Synthesis, the end columns, and J stored per unit sigma_s* (as the matrix's scatter).
        for (size_t k = 0; k < nu_; ++k) {
          for (size_t q = 0; q < nphi; ++q) {
            for (size_t u = 0; u < nsub; ++u) {
              ModalSynthesis4(&cos_mq[q], nphi, &T[u * kSub * tb + k * nm * nw_], tb, nm, nw_, acc.data());
              if (has_ends) {
                for (size_t e = 0; e < 2; ++e) {
                  const float* Dv = &end_kernels[ri * end_floats + (((e * nu_ + k) * nphi + q) * nu_) * nw_];
                  ModalBlock4Add(Dv, nw_, &dL[u * kSub * db + e * nu_ * nw_], nw_, db, nu_, nw_, acc.data());
                }
              }
              for (size_t b = 0; b < kSub && u * kSub + b < nb; ++b) {
                float* jo = &(*Jout)[(((ri * ns_ + s0 + u * kSub + b) * nd) + k * nphi + q) * nw_];
                const float* a = &acc[b * nw_];
                for (size_t w = 0; w < nw_; ++w) {
                  const double st = ssc_total[ri * nw_ + w];
                  jo[w] = st > 0.0 ? static_cast<float>(a[w] / st) : 0.0f;
                }
              }
            }
          }
        }
      }
    });
  };
  std::vector<float> kernels;
  if (!modal && nr * kernel_floats * sizeof(float) <= (size_t{768} << 20)) {
    kernels.resize(nr * kernel_floats);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nr, 1), [&](const tbb::blocked_range<size_t>& rg) {
      for (size_t ri = rg.begin(); ri != rg.end(); ++ri) build_kernel(ri, &kernels[ri * kernel_floats]);
    });
  }
  auto scatter = [&](const Table& Lin, Table* Jout) {
    // J_n = sum_c sigma_s*_c P*_c applied to L_{n-1}, per radius: a (nd x nd) kernel per
    // wavelength. Tasks are (radius, block of 4 sun nodes): each kernel element loaded is used
    // for 4 sun nodes (the product is load-bound otherwise).
    constexpr size_t kSunBlock = 4;
    const size_t nsb = (ns_ + kSunBlock - 1) / kSunBlock;
    auto apply = [&](size_t ri, size_t sb, const float* kernel) {
      const size_t s0 = sb * kSunBlock, s1 = std::min(ns_, s0 + kSunBlock);
      for (size_t i = 0; i < nd; ++i) {
        float* jo[kSunBlock];
        const float* lv[kSunBlock];
        for (size_t b = 0; b < kSunBlock; ++b) {
          const size_t si = std::min(s0 + b, s1 - 1);  // a short last block repeats its last node (not stored twice)
          jo[b] = &(*Jout)[(((ri * ns_ + si) * nd) + i) * nw_];
          lv[b] = &Lin[((ri * ns_ + si) * nd) * nw_];
        }
        float acc[kSunBlock][64];
        for (size_t w0 = 0; w0 < nw_; w0 += 64) {
          const size_t wn = std::min<size_t>(64, nw_ - w0);
          for (size_t b = 0; b < kSunBlock; ++b) std::fill(acc[b], acc[b] + wn, 0.0f);
          for (size_t j = 0; j < nd; ++j) {
            const float* kv = &kernel[(i * nd + j) * nw_ + w0];
            for (size_t b = 0; b < kSunBlock; ++b) {
              const float* l = lv[b] + j * nw_ + w0;
              for (size_t w = 0; w < wn; ++w) acc[b][w] += kv[w] * l[w];
            }
          }
          // Stored per unit scattering coefficient (J / sigma_s*: the phase-weighted mean
          // radiance), multiplied back by sigma_s* where it is used. Interpolating J itself
          // between radius nodes smears a thin dense layer's source over the whole interval:
          // a 1 km water cloud of optical depth 8 then amplified each order by 1.29.
          for (size_t b = 0; b < s1 - s0; ++b) {
            for (size_t w = 0; w < wn; ++w) {
              const double st = ssc_total[ri * nw_ + w0 + w];
              jo[b][w0 + w] = st > 0.0 ? static_cast<float>(acc[b][w] / st) : 0.0f;
            }
          }
        }
      }
    };
    if (!kernels.empty()) {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * nsb, 1), [&](const tbb::blocked_range<size_t>& rg) {
        for (size_t idx = rg.begin(); idx != rg.end(); ++idx) apply(idx / nsb, idx % nsb, &kernels[(idx / nsb) * kernel_floats]);
      });
    } else {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, nr, 1), [&](const tbb::blocked_range<size_t>& rg) {
        std::vector<float> kernel(kernel_floats);
        for (size_t ri = rg.begin(); ri != rg.end(); ++ri) {
          build_kernel(ri, kernel.data());
          for (size_t sb = 0; sb < nsb; ++sb) apply(ri, sb, kernel.data());
        }
      });
    }
  };
  // The transport step: L = int T* sigma_s* J dt along every table ray + the ground's
  // reflection of the irradiance of Lin (the radiance the sources J came from).
  // Twilight: between two sun nodes the sources fall ~e-fold per degree, and a linear blend of
  // the two nodes' J along a table ray overestimates the sky (clear, 1 deg nodes against 0.2 deg:
  // +4-5 % RMS, up to 9 %, at sun 95-100 deg, at the nodes themselves). The exact log-linear
  // blend would cost two transcendentals per wavelength in the innermost loop, so it is
  // approximated by a factor on the linear blend, C = gbar_0^(1-t) gbar_1^t / ((1-t) gbar_0 +
  // t gbar_1), gbar the mean J over the directions at the radius node and sun node (exact when
  // the nodes' J have the same shape): tabulated per order at kLogBins + 1 values of t, per
  // radius node, sun interval and wavelength, for the intervals from loglin_from_deg on.
  constexpr size_t kLogBins = 16;
  size_t loglin_first = ns_;
  for (size_t si = 0; si + 1 < ns_; ++si) {
    if (s_.sun_deg[si] >= s_.loglin_from_deg - 1e-9) {
      loglin_first = si;
      break;
    }
  }
  std::vector<float> cfac;  // [((ri * ns + si) * (kLogBins + 1) + b) * nw + w], si >= loglin_first
  auto build_cfac = [&](const Table& Jin) {
    if (loglin_first >= ns_) return;
    cfac.assign(nr * ns_ * (kLogBins + 1) * nw_, 1.0f);
    tbb::parallel_for(size_t{0}, nr, [&](size_t ri) {
      std::vector<double> g(ns_ * nw_, 0.0);
      for (size_t si = loglin_first; si < ns_; ++si) {
        for (size_t i = 0; i < nd; ++i) {
          const float* v = &Jin[(((ri * ns_ + si) * nd) + i) * nw_];
          for (size_t w = 0; w < nw_; ++w) g[si * nw_ + w] += v[w];
        }
      }
      for (size_t si = loglin_first; si + 1 < ns_; ++si) {
        for (size_t b = 0; b <= kLogBins; ++b) {
          const double t = static_cast<double>(b) / kLogBins;
          float* c = &cfac[((ri * ns_ + si) * (kLogBins + 1) + b) * nw_];
          for (size_t w = 0; w < nw_; ++w) {
            const double a = g[si * nw_ + w], bb = g[(si + 1) * nw_ + w];
            const double lin = (1.0 - t) * a + t * bb;
            c[w] = a > 0.0 && bb > 0.0 && lin > 0.0 ? static_cast<float>(a * std::pow(bb / a, t) / lin) : 1.0f;
          }
        }
      }
    });
  };
  // Twilight's blend of a step's gathered J: jlo (the lower radius's corners) and jhi (the upper's)
  // each times its factor C at the step's sun interval, interpolated between the kLogBins + 1
  // tabulated t; the result in jlo.
  auto log_blend = [&](const SunAzimuth& p, size_t r0, float* jlo, const float* jhi) {
    const float fb = p.ts * kLogBins;
    const size_t b0 = std::min(static_cast<size_t>(fb), kLogBins - 1);
    const float tb = fb - static_cast<float>(b0);
    const size_t r1 = std::min(r0 + 1, nr - 1);
    const float* c00 = &cfac[((r0 * ns_ + p.si) * (kLogBins + 1) + b0) * nw_];
    const float* c10 = &cfac[((r1 * ns_ + p.si) * (kLogBins + 1) + b0) * nw_];
    for (size_t w = 0; w < nw_; ++w) {
      const float f0 = c00[w] + (c00[w + nw_] - c00[w]) * tb, f1 = c10[w] + (c10[w + nw_] - c10[w]) * tb;
      jlo[w] = jlo[w] * f0 + jhi[w] * f1;
    }
  };
  auto transport_cells = [&](const Table& Jin, const Table& Lin, Table* Lout) {
    ground_irradiance(Lin, &E);
    build_cfac(Jin);
    // L_n = int T* J_n dt + ground reflection of E_{n-1}.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * ns_ * nu_, 4), [&](const tbb::blocked_range<size_t>& rg) {
      std::vector<float> acc(nw_), jv(nw_), jv2(nw_), eg(nw_);
      for (size_t idx = rg.begin(); idx != rg.end(); ++idx) {
        const size_t ri = idx / (ns_ * nu_), si = (idx / nu_) % ns_, k = idx % nu_;
        const Family& f = fam[ri * nu_ + k];
        const double r = radius_[ri], ts = sun_theta_rad_[si];
        for (size_t q = 0; q < nphi; ++q) {
          double mu, nu;
          cell_geometry(ri, si, k, q, &mu, &nu);
          std::fill(acc.begin(), acc.end(), 0.0f);
          const SunAzimuth* sa = sun_az.empty() ? nullptr : &sun_az[Cell(ri, si, k, q) * nt];
          for (size_t m = 0; m < f.t.size(); ++m) {
            // The 16-corner gather of J (radius x view x sun x azimuth), the hot loop of the
            // solve: offsets and weights split into the step's radius/view part (per family)
            // and its sun/azimuth part (per cell).
            const SunAzimuth p = sa != nullptr ? sa[m] : step_sun_azimuth(f, m, r, ts, nu);
            if (p.si == kNoSun) continue;
            const size_t so = (static_cast<size_t>(p.si) * nu_) * nphi + p.q0;
            const float ws[4] = {(1.0f - p.ts) * (1.0f - p.tq), (1.0f - p.ts) * p.tq, p.ts * (1.0f - p.tq), p.ts * p.tq};
            // A corner of weight 0 reads the first one (its own cell may lie past the table's
            // end: the last azimuth or sun node with t = 0).
            const size_t sofs[4] = {so, ws[1] != 0.0f ? so + 1 : so, ws[2] != 0.0f ? so + nu_ * nphi : so,
                                    ws[3] != 0.0f ? so + nu_ * nphi + 1 : so};
            const Family::Corners& c = f.rc[m];
            const float* v[16];
            float wv[16];
            for (int a = 0; a < 4; ++a) {
              for (int b = 0; b < 4; ++b) {
                v[4 * a + b] = &Jin[(c.off[a] + sofs[b]) * nw_];
                wv[4 * a + b] = c.w[a] * ws[b];
              }
            }
            float* jvp = jv.data();
            // The 16 products summed in one pass per wavelength, in corner order (a term of
            // weight 0 adds +-0: the same sums as skipping it); twilight: the upper radius
            // corners accumulate apart, for their own factor C.
            const bool loglin = p.si >= loglin_first && p.ts > 0.0f;
            if (!loglin) {
              Gather16(v, wv, 0, 16, nw_, jvp);
            } else {
              Gather16(v, wv, 0, 8, nw_, jvp);
              Gather16(v, wv, 8, 16, nw_, jv2.data());
            }
            if (loglin) log_blend(p, f.rv[m].ri, jvp, jv2.data());
            const float* gm = &f.g[m * nw_];
            for (size_t w = 0; w < nw_; ++w) acc[w] += gm[w] * jvp[w];
          }
          if (f.ground) {
            const double mus_g = (r * std::cos(ts) + f.d * nu) / R;
            interp_E(E, std::acos(std::clamp(mus_g, -1.0, 1.0)), eg.data());
            for (size_t w = 0; w < nw_; ++w) acc[w] += f.trans_end[w] * static_cast<float>(albedo_[w] / kPi) * eg[w];
          }
          std::copy(acc.begin(), acc.end(), &(*Lout)[Cell(ri, si, k, q) * nw_]);
        }
      }
    });
  };
  // The same transport by families (since 2026-11-24, `table_size` key `gather_split`, 0 = the
  // cell-by-cell form above, which the test compares against): all cells of a family (radius
  // node, view node) share each step's point and so its 4 radius/view corners. Per step, the
  // radius/view blend of J is formed once for every sun and azimuth node (a slab of ns x nphi x nw,
  // which stays in cache), and each cell then blends 4 sun/azimuth corners of the slab: 4 + 4
  // products per wavelength per cell instead of 16, and the cells' reads go to the slab instead of
  // 16 scattered table rows. The same sums in another order: the result differs from the
  // cell-by-cell form by float rounding (MethodOrders.SplitGatherIsTheCellGather).
  auto transport_split = [&](const Table& Jin, const Table& Lin, Table* Lout) {
    ground_irradiance(Lin, &E);
    build_cfac(Jin);
    const size_t plane = ns_ * nphi;  // cells of one family
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nr * nu_, 1), [&](const tbb::blocked_range<size_t>& rg) {
      // slab[(s * nphi + q) * nw + w]: sum over the 4 radius/view corners; lo / hi: the lower and
      // the upper radius's 2 corners apart (twilight's log-linear factor), for s >= loglin_first.
      std::vector<float> slab(plane * nw_), lo(plane * nw_), hi(plane * nw_), acc(plane * nw_), jv(nw_), jv2(nw_), eg(nw_);
      std::vector<SunAzimuth> pts(plane);
      for (size_t fi = rg.begin(); fi != rg.end(); ++fi) {
        const size_t ri = fi / nu_, k = fi % nu_;
        const Family& f = fam[fi];
        const double r = radius_[ri];
        std::fill(acc.begin(), acc.end(), 0.0f);
        for (size_t m = 0; m < f.t.size(); ++m) {
          // The cells' sun/azimuth positions at this step, and the sun nodes they read.
          size_t s_lo = ns_, s_hi = 0;
          for (size_t si = 0; si < ns_; ++si) {
            for (size_t q = 0; q < nphi; ++q) {
              SunAzimuth p;
              if (!sun_az.empty()) {
                p = sun_az[Cell(ri, si, k, q) * nt + m];
              } else {
                double mu, nu;
                cell_geometry(ri, si, k, q, &mu, &nu);
                p = step_sun_azimuth(f, m, r, sun_theta_rad_[si], nu);
              }
              pts[si * nphi + q] = p;
              if (p.si == kNoSun) continue;
              s_lo = std::min<size_t>(s_lo, p.si);
              s_hi = std::max<size_t>(s_hi, std::min<size_t>(p.si + 1, ns_ - 1));
            }
          }
          if (s_lo > s_hi) continue;
          const Family::Corners& c = f.rc[m];
          for (size_t s = s_lo; s <= s_hi; ++s) {
            const size_t so = s * nu_ * nphi;
            const float* v[4];
            for (int a = 0; a < 4; ++a) v[a] = &Jin[(c.off[a] + so) * nw_];
            const size_t n = nphi * nw_;
            float* out = &slab[s * n];
            if (s < loglin_first) {
              Gather16(v, c.w, 0, 4, n, out);
            } else {
              Gather16(v, c.w, 0, 2, n, &lo[s * n]);
              Gather16(v, c.w, 2, 4, n, &hi[s * n]);
              for (size_t x = 0; x < n; ++x) out[x] = lo[s * n + x] + hi[s * n + x];
            }
          }
          const float* gm = &f.g[m * nw_];
          for (size_t cell = 0; cell < plane; ++cell) {
            const SunAzimuth& p = pts[cell];
            if (p.si == kNoSun) continue;
            const size_t so = static_cast<size_t>(p.si) * nphi + p.q0;
            const float ws[4] = {(1.0f - p.ts) * (1.0f - p.tq), (1.0f - p.ts) * p.tq, p.ts * (1.0f - p.tq), p.ts * p.tq};
            // A corner of weight 0 reads the first one (it may lie past the table's end).
            const size_t sofs[4] = {so, ws[1] != 0.0f ? so + 1 : so, ws[2] != 0.0f ? so + nphi : so,
                                    ws[3] != 0.0f ? so + nphi + 1 : so};
            const bool loglin = p.si >= loglin_first && p.ts > 0.0f;
            float* jvp = jv.data();
            if (!loglin) {
              const float* v[4] = {&slab[sofs[0] * nw_], &slab[sofs[1] * nw_], &slab[sofs[2] * nw_], &slab[sofs[3] * nw_]};
              Gather16(v, ws, 0, 4, nw_, jvp);
            } else {
              const float* vl[4] = {&lo[sofs[0] * nw_], &lo[sofs[1] * nw_], &lo[sofs[2] * nw_], &lo[sofs[3] * nw_]};
              const float* vh[4] = {&hi[sofs[0] * nw_], &hi[sofs[1] * nw_], &hi[sofs[2] * nw_], &hi[sofs[3] * nw_]};
              Gather16(vl, ws, 0, 4, nw_, jvp);
              Gather16(vh, ws, 0, 4, nw_, jv2.data());
              log_blend(p, f.rv[m].ri, jvp, jv2.data());
            }
            float* a = &acc[cell * nw_];
            for (size_t w = 0; w < nw_; ++w) a[w] += gm[w] * jvp[w];
          }
        }
        for (size_t si = 0; si < ns_; ++si) {
          const double ts = sun_theta_rad_[si];
          for (size_t q = 0; q < nphi; ++q) {
            float* a = &acc[(si * nphi + q) * nw_];
            if (f.ground) {
              double mu, nu;
              cell_geometry(ri, si, k, q, &mu, &nu);
              const double mus_g = (r * std::cos(ts) + f.d * nu) / R;
              interp_E(E, std::acos(std::clamp(mus_g, -1.0, 1.0)), eg.data());
              for (size_t w = 0; w < nw_; ++w) a[w] += f.trans_end[w] * static_cast<float>(albedo_[w] / kPi) * eg[w];
            }
            std::copy(a, a + nw_, &(*Lout)[Cell(ri, si, k, q) * nw_]);
          }
        }
      }
    });
  };
  auto transport = [&](const Table& Jin, const Table& Lin, Table* Lout) {
    if (s_.gather_split) transport_split(Jin, Lin, Lout);
    else transport_cells(Jin, Lin, Lout);
  };
  for (int order = 2; order <= s_.max_orders; ++order) {
    ReportProgress(progress, fmt::format("orders: order {}", order), 0.0);
    if (modal) scatter_modal(L, &J);
    else scatter(L, &J);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, jms_.size(), size_t{1} << 18), [&](const tbb::blocked_range<size_t>& rg) {
      for (size_t i = rg.begin(); i != rg.end(); ++i) jms_[i] += J[i];
    });
    transport(J, L, &Lnext);
    // Rotate: L = L_n, Lprev = L_{n-1}, Lnext = L_{n-2}.
    std::swap(Lprev, L);
    std::swap(L, Lnext);
    // Accumulate at the observer radius; convergence on the reference wavelength.
    double norm = 0.0, total = 0.0;
    for (size_t si = 0; si < ns_; ++si) {
      for (size_t i = 0; i < nd; ++i) {
        const float* v = &L[(((obs_index_ * ns_ + si) * nd) + i) * nw_];
        float* a = &ms_[((si * nd) + i) * nw_];
        for (size_t w = 0; w < nw_; ++w) a[w] += v[w];
        norm += v[wref];
        total += a[wref];
      }
    }
    orders_done_ = order;
    last_fraction_ = total > 0.0 ? norm / total : 0.0;
    const double ratio = prev_norm > 0.0 ? norm / prev_norm : -1.0;
    if (last_fraction_ < s_.tolerance) break;
    // Geometric tail once the ratio of successive orders has settled: the remaining orders sum
    // to L_n rho / (1 - rho), and an error d_rho in rho changes that by about
    // fraction_n d_rho / (1 - rho)^2 of the total; stop when that is below the tolerance and
    // the tail is at most tail_share_max (10 %) of the total, or at the last allowed order if the
    // ratio has settled at all. The share limit: in a thick layer the ratio creeps up over many
    // orders while each step of it is small (a tail taken at order 16 of a tau-8 cloud was 4-5 %
    // short of the converged sum). 30 % was tried with the energy-conserving step weights: within
    // 0.3 % on cloudy4/5 (5 and 18 orders fewer), but on the hazed sky with 24 azimuths and a 3 deg
    // cone it took the tail at order 4-5 and the horizon came out 11 % dark (docs/sky-methods.md).
    // d_rho is the larger of the last two changes of the ratio (since 2026-11-24): with one, a
    // ratio passing an extremum looked settled - the hazed sky with 1 deg sun nodes from 80 to
    // 90 deg had ratios 0.521, 0.503, 0.503 at orders 3-5, took the tail at order 5 and came out
    // 2.2 % RMS at sun 70 deg instead of 0.6 % (its ratio went on to 0.52 by order 12).
    const bool settled = ratio > 0.0 && ratio < 1.0 && prev_ratio > 0.0;
    const double d_rho = std::max(std::abs(ratio - prev_ratio), prev_prev_ratio > 0.0 ? std::abs(prev_ratio - prev_prev_ratio) : 1.0);
    const double tail_error = settled ? last_fraction_ * d_rho / ((1.0 - ratio) * (1.0 - ratio)) : 1.0;
    const double tail_share = settled ? last_fraction_ * ratio / (1.0 - ratio) : 1.0;
    if (settled && s_.early_tail && order >= 5 && tail_error < s_.tolerance && tail_share <= s_.tail_share_max) last_order_tail = true;
    if (last_order_tail || (order == s_.max_orders && settled && std::abs(ratio - prev_ratio) < 0.02)) {
      // Geometric tail: sum_{k>n} L_k ~ L_n rho / (1 - rho), with rho per table element (the
      // horizon and the shadowed sky decay more slowly than the observer's average: with one
      // global rho the hazed horizon missed 0.55 % at tolerance 1e-3, within 0.3 % per element;
      // tests/transport/method_orders_test.cpp): the element's L_n / L_{n-1} where that and
      // L_{n-1} / L_{n-2} agree within 0.05 and are below 1, the observer's global ratio
      // elsewhere (an element whose orders still grow - the low-sun horizon's at order 4 - got
      // a tail of 9 L_n from its own ratio and came out 60 % bright). The sources J_n decay
      // like the radiances of their node. rho is capped at rho_cap (0.98: tail <= 49 L_n).
      auto tail_at = [&](size_t e) {
        const double r1 = Lprev[e] > 0.0f ? L[e] / static_cast<double>(Lprev[e]) : 2.0;
        const double r0 = Lnext[e] > 0.0f ? Lprev[e] / static_cast<double>(Lnext[e]) : 2.0;
        double rho = r1 < 1.0 && r0 < 1.0 && std::abs(r1 - r0) < 0.05 ? r1 : ratio;
        rho = std::clamp(rho, 0.0, s_.rho_cap);
        return static_cast<float>(rho / (1.0 - rho));
      };
      for (size_t si = 0; si < ns_; ++si) {
        for (size_t i = 0; i < nd; ++i) {
          const size_t e0 = (((obs_index_ * ns_ + si) * nd) + i) * nw_;
          float* a = &ms_[((si * nd) + i) * nw_];
          for (size_t w = 0; w < nw_; ++w) a[w] += tail_at(e0 + w) * L[e0 + w];
        }
      }
      tbb::parallel_for(tbb::blocked_range<size_t>(0, jms_.size(), size_t{1} << 18), [&](const tbb::blocked_range<size_t>& rg) {
        for (size_t i = rg.begin(); i != rg.end(); ++i) jms_[i] += tail_at(i) * J[i];
      });
      tail_ = true;
      break;
    }
    prev_prev_ratio = prev_ratio;
    prev_ratio = ratio;
    prev_norm = norm;
  }
}

// ---------------------------------------------------------------------------- output

void OrdersMethod::Render(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                          const ViewSegment* segment, std::vector<double>* out, std::vector<double>* single) const {
  const double R = m_.bottom_radius_m, top = m_.top_radius_m;
  const double r = R + observer_altitude_m;
  const double ts = sun_zenith_rad;
  out->assign(dirs.size() * nw_, 0.0);
  if (single != nullptr) single->assign(dirs.size() * nw_, 0.0);
  const size_t nd = nu_ * static_cast<size_t>(s_.nphi);
  // Log-linear interpolation of the MS table in the sun angle (exact for exponential twilight decay).
  const Lerp ls = Locate(sun_theta_rad_, ts);
  std::vector<float> tsun(nw_), st(nw_), acc(nw_), ms0(nw_), ms1(nw_), pc(nc_ * nw_), jv(nw_), jv1(nw_), hwt(nw_);
  std::vector<double> seg_ms(nw_), pv(nw_);

  // What along a view ray does not depend on the sun or the azimuth - the steps, the medium at
  // each point and its transmittance from the observer - is computed once per view zenith
  // cosine and reused while the directions share it (a LUT row, an ambient ring: 32-128
  // directions per call; it was two thirds of a clear-sky LUT's render), and, for whole view
  // rays, kept across calls (CachedViewRay: the LUT's ambient rings recur in every sun slice).
  ViewRay local;
  std::shared_ptr<const ViewRay> cached;
  const ViewRay* cur = nullptr;
  auto build_ray = [&](double mu, ViewRay& ray) {
    ray.mu = mu;
    ray.pts.clear();
    ray.e.clear();
    ray.seg.clear();
    const size_t npts = 2 * static_cast<size_t>(s_.nss);
    ray.pts.reserve(npts);
    ray.e.reserve(npts * nc_ * nw_);
    if (segment != nullptr) ray.seg.reserve(npts * nw_);
    const double disc_g = r * r * (mu * mu - 1.0) + R * R;
    // Segments never include the ground surface (transport/view_segment.h).
    ray.ground = segment == nullptr && mu < 0.0 && disc_g >= 0.0;
    if (segment != nullptr) {
      ray.length = SegmentEnd(m_, observer_altitude_m, mu, *segment);
    } else {
      ray.length = mu < 0.0 && disc_g >= 0.0 ? -r * mu - std::sqrt(std::max(0.0, disc_g))
                                             : -r * mu + std::sqrt(std::max(0.0, r * r * (mu * mu - 1.0) + top * top));
    }
    const double length = ray.length;
    std::vector<double> tau(nw_, 0.0), tau_star(nw_, 0.0);
    ray.t_end.assign(nw_, 1.0f);
    if (length <= 0.0) return;
    // Steps uniform in the parameter s = (tau_ref/tau_tot + t/length)/2 computed on a fine
    // uniform sub-grid at the middle wavelength (as the table rays).
    const int nf = s_.fine;
    std::vector<double> cum(static_cast<size_t>(nf) + 1, 0.0);
    const size_t wref = nw_ / 2;
    for (int p = 0; p < nf; ++p) {
      const double tm = (p + 0.5) * length / nf;
      const double rr = std::sqrt(r * r + 2.0 * r * mu * tm + tm * tm);
      cum[static_cast<size_t>(p) + 1] = cum[static_cast<size_t>(p)] + SigmaTAt(rr - R, false, wref) * length / nf;
    }
    const double tau_tot = std::max(cum.back(), 1e-12);
    std::vector<double> s_at(static_cast<size_t>(nf) + 1);
    for (int p = 0; p <= nf; ++p) s_at[static_cast<size_t>(p)] = 0.5 * (cum[static_cast<size_t>(p)] / tau_tot + static_cast<double>(p) / nf);
    // t(s) for increasing s: the interval is found by walking on from the last one (the same
    // interval as a search, s_at being strictly increasing; no locator built per ray - its
    // construction was 1.4 % of a hazed LUT's render).
    size_t s_i = 0;
    auto t_of_s = [&](double sv) {
      double u;
      if (sv <= s_at.front()) {
        u = 0.0;
      } else if (sv >= s_at.back()) {
        u = static_cast<double>(nf);
      } else {
        while (s_i + 2 < s_at.size() && s_at[s_i + 1] <= sv) ++s_i;
        u = static_cast<double>(s_i) + (sv - s_at[s_i]) / (s_at[s_i + 1] - s_at[s_i]);
      }
      return u * length / nf;
    };
    // Gauss-Legendre (2 points) on each step; optical depth accumulated with the same rule.
    static const double kG = 0.5773502691896257;
    double t_prev = 0.0;
    for (int m = 0; m < s_.nss; ++m) {
      const double t0 = t_of_s(static_cast<double>(m) / s_.nss), t1 = t_of_s(static_cast<double>(m + 1) / s_.nss);
      const double h = t1 - t0;
      for (double g : {-kG, kG}) {
        const double t = 0.5 * (t0 + t1) + 0.5 * g * h;
        const double rr = std::sqrt(r * r + 2.0 * r * mu * t + t * t);
        // Optical depth from the observer to t: advance from t_prev with the midpoint value.
        const double tmid = 0.5 * (t_prev + t);
        const double rmid = std::sqrt(r * r + 2.0 * r * mu * tmid + tmid * tmid);
        const AtmosphereModel::Cell cmid = m_.Locate(rmid - R), cell = m_.Locate(rr - R);
        SigmaTView(cmid, st.data());
        for (size_t w = 0; w < nw_; ++w) tau[w] += st[w] * (t - t_prev);
        if (segment != nullptr) {
          SigmaT(cmid, true, st.data());
          for (size_t w = 0; w < nw_; ++w) tau_star[w] += st[w] * (t - t_prev);
        }
        t_prev = t;
        ray.pts.push_back({t, rr, std::clamp((r * mu + t) / rr, -1.0, 1.0), SunRadius(rr, ss_scaled_)});
        const float hw = static_cast<float>(segment == nullptr || segment->single_scattering ? 0.5 * h : 0.0);
        const size_t e0 = ray.e.size();
        ray.e.resize(e0 + nc_ * nw_);
        // Single precision exp (the radiance is accumulated in float anyway), once per point for
        // all components (it was a third of a LUT row's ray build when taken per component).
        for (size_t w = 0; w < nw_; ++w) hwt[w] = hw * ExpF(-static_cast<float>(tau[w]));
        for (size_t c = 0; c < nc_; ++c) {
          SigmaS(c, cell, false, st.data());
          for (size_t w = 0; w < nw_; ++w) ray.e[e0 + c * nw_ + w] = hwt[w] * st[w];
        }
        if (segment != nullptr) {
          const size_t s0 = ray.seg.size();
          ray.seg.resize(s0 + nw_, 0.0f);
          for (size_t c = 0; c < nc_; ++c) {
            SigmaS(c, cell, true, st.data());
            for (size_t w = 0; w < nw_; ++w) ray.seg[s0 + w] += st[w];
          }
          for (size_t w = 0; w < nw_; ++w) ray.seg[s0 + w] *= static_cast<float>(0.5 * h * std::exp(-tau_star[w]));
        }
      }
    }
    if (ray.ground) {
      // Finish the optical depth to the ground.
      const double tmid = 0.5 * (t_prev + length);
      const double rmid = std::sqrt(r * r + 2.0 * r * mu * tmid + tmid * tmid);
      SigmaTView(m_.Locate(rmid - R), st.data());
      for (size_t w = 0; w < nw_; ++w) ray.t_end[w] = static_cast<float>(std::exp(-(tau[w] + st[w] * (length - t_prev))));
    }
    if (segment == nullptr) {
      // Points behind an optical depth of ~88 at every wavelength (a grazing ray through a
      // cloud deck) have a weight of exactly 0 (ExpF underflows): their single scattering adds
      // nothing, so they are dropped (the same bytes, fewer sun lookups).
      const size_t per = nc_ * nw_;
      size_t keep = ray.pts.size();
      while (keep > 0 && std::all_of(ray.e.begin() + static_cast<std::ptrdiff_t>((keep - 1) * per),
                                     ray.e.begin() + static_cast<std::ptrdiff_t>(keep * per), [](float v) { return v == 0.0f; })) {
        --keep;
      }
      ray.pts.resize(keep);
      ray.e.resize(keep * per);
    }
  };

  for (size_t d = 0; d < dirs.size(); ++d) {
    const double mu = std::clamp(dirs[d][2], -1.0, 1.0);
    const double sn = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    const double cphi = sn > 1e-12 ? dirs[d][0] / sn : 1.0;
    const double nu = dirs[d][0] * std::sin(ts) + mu * std::cos(ts);  // the sun is (sin ts, 0, cos ts)
    if (cur == nullptr || mu != cur->mu) {
      if (segment == nullptr) {
        cached = CachedViewRay(observer_altitude_m, mu, [&](ViewRay* ray) { build_ray(mu, *ray); });
        cur = cached.get();
      } else {
        build_ray(mu, local);
        cur = &local;
      }
    }
    const ViewRay& ray = *cur;
    // --- single scattering along the view ray (unscaled medium, full phase)
    for (size_t c = 0; c < nc_; ++c) {
      // The phase times the sun's irradiance (per direction, not per point).
      phase_[c]->EvalAll(nu, nw_, pv.data());
      for (size_t w = 0; w < nw_; ++w) pc[c * nw_ + w] = static_cast<float>(pv[w] * sun_e_[w]);
    }
    std::fill(acc.begin(), acc.end(), 0.0f);
    std::fill(seg_ms.begin(), seg_ms.end(), 0.0);
    for (size_t p = 0; p < ray.pts.size(); ++p) {
      const ViewPoint& pt = ray.pts[p];
      const double mus = (r * std::cos(ts) + pt.t * nu) / pt.rr;
      if (segment == nullptr || segment->single_scattering) {
        SunTransmittanceAt(pt.sun_r, mus, ss_scaled_, tsun.data());
        const float* e = &ray.e[p * nc_ * nw_];
        std::fill(st.begin(), st.end(), 0.0f);
        for (size_t c = 0; c < nc_; ++c) {
          for (size_t w = 0; w < nw_; ++w) st[w] += e[c * nw_ + w] * pc[c * nw_ + w];
        }
        for (size_t w = 0; w < nw_; ++w) acc[w] += st[w] * tsun[w];
      }
      if (segment != nullptr) {
        // Multiple scattering of the segment: the tabulated source J_ms* at this point, in
        // its local frame, attenuated by the scaled medium (the TMS split's L* part).
        const double mus_c = std::clamp(mus, -1.0, 1.0);
        const double mu2 = pt.mu2;
        const double denom = std::sqrt(std::max(1e-12, (1.0 - mu2 * mu2) * (1.0 - mus_c * mus_c)));
        const double cphi2 = std::clamp((nu - mu2 * mus_c) / denom, -1.0, 1.0);
        // Log-linear in the sun angle, as the sky's own multiple scattering below: between
        // twilight nodes 1 deg apart the sources fall ~e-fold, and linear interpolation put
        // the fog between nodes ~10 % above the nodes' (docs/fog.md, "Limits").
        const SunAzimuth sa = SunAzimuthAt(std::acos(mus_c), cphi2);
        std::fill(jv.begin(), jv.end(), 0.0f);
        if (sa.si != kNoSun) {
          const RadialView rv = RadialViewAt(pt.rr, mu2);
          std::fill(jv1.begin(), jv1.end(), 0.0f);
          Interpolate(jms_, rv, SunAzimuth{sa.si, sa.q0, 0.0f, sa.tq}, 1.0, jv.data());
          if (sa.ts > 0.0f) {
            Interpolate(jms_, rv, SunAzimuth{static_cast<uint16_t>(sa.si + 1), sa.q0, 0.0f, sa.tq}, 1.0, jv1.data());
            for (size_t w = 0; w < nw_; ++w) {
              const float a = jv[w], b = jv1[w];
              jv[w] = a > 0.0f && b > 0.0f ? a * std::pow(b / a, sa.ts) : a + (b - a) * sa.ts;
            }
          }
        }
        const float* sg = &ray.seg[p * nw_];
        for (size_t w = 0; w < nw_; ++w) seg_ms[w] += sg[w] * jv[w];
      }
    }
    if (ray.ground) {
      // The ground's first reflection of the sun.
      const double mus_g = (r * std::cos(ts) + std::max(0.0, ray.length) * nu) / R;
      if (mus_g > -0.5) {
        SunTransmittance(R, mus_g, ss_scaled_, tsun.data());
        for (size_t w = 0; w < nw_; ++w) {
          acc[w] += static_cast<float>(ray.t_end[w] * albedo_[w] / kPi * sun_e_[w] * std::max(0.0, mus_g)) * tsun[w];
        }
      }
    }
    if (segment != nullptr) {
      for (size_t w = 0; w < nw_; ++w) (*out)[d * nw_ + w] = acc[w] + std::max(0.0, seg_ms[w]);
      continue;
    }
    if (single != nullptr) {
      for (size_t w = 0; w < nw_; ++w) (*single)[d * nw_ + w] = static_cast<double>(acc[w]);
    }
    // --- multiple scattering from the table at the observer radius
    std::fill(ms0.begin(), ms0.end(), 0.0f);
    std::fill(ms1.begin(), ms1.end(), 0.0f);
    if (ts <= sun_theta_rad_.back()) {
      size_t k0, k1;
      double tk;
      ViewIndex(mu, r, &k0, &k1, &tk);
      size_t q0;
      const double tq = AzimuthBlend(std::acos(std::clamp(cphi, -1.0, 1.0)), s_.azimuth_even, &q0);
      for (int ds = 0; ds < 2; ++ds) {
        float* dst = ds ? ms1.data() : ms0.data();
        const size_t si = ls.i + static_cast<size_t>(ds);
        for (int dk = 0; dk < 2; ++dk) {
          for (int dq = 0; dq < 2; ++dq) {
            const float wgt = static_cast<float>((dk ? tk : 1.0 - tk) * (dq ? tq : 1.0 - tq));
            const float* v = &ms_[((si * nd) + (dk ? k1 : k0) * static_cast<size_t>(s_.nphi) + q0 + static_cast<size_t>(dq)) * nw_];
            for (size_t w = 0; w < nw_; ++w) dst[w] += wgt * v[w];
          }
        }
      }
    }
    // Log-linear between the two sun nodes, a (b/a)^t, where both are positive normal floats and
    // their ratio is within 1e+-30 (else linear). In float with ExpF/LogF, which vectorise: the
    // double log, log and exp per texel and wavelength were ~7 % of a hazed LUT's render (the two
    // agree to ~3e-7 relative).
    const float tf = static_cast<float>(ls.t);
    for (size_t w = 0; w < nw_; ++w) {
      const float a = ms0[w], b = ms1[w];
      const float ratio = b / a;
      const float geo = a * ExpF(tf * LogF(ratio));
      const float lin = a + (b - a) * tf;
      const bool use_geo = a >= std::numeric_limits<float>::min() && b >= std::numeric_limits<float>::min() && ratio > 1e-30f && ratio < 1e30f;
      const float ms = use_geo ? geo : lin;
      (*out)[d * nw_ + w] = static_cast<double>(acc[w]) + static_cast<double>(std::max(0.0f, ms));
    }
  }
}

}  // namespace

std::unique_ptr<SkyMethod> MakeOrdersMethod(const AtmosphereModel& model, const SkyMethodOptions& options,
                                            const ProgressFn& progress) {
  return std::make_unique<OrdersMethod>(model, options, progress);
}

}  // namespace skybake
