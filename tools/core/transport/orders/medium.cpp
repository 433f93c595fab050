#include "transport/orders/medium.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "atmosphere/phase_peak.h"
#include "transport/orders/grid.h"

namespace skybake::orders {

namespace {

// Each component's truncation cone (OrdersSettings::truncation_min_deg): the smallest angle in
// 0.5 deg steps from the minimum up to truncation_deg at which, for every wavelength, the phase
// function one azimuth interval further out is no more than R times lower. So what the kernel must
// integrate is no sharper than its grid resolves. At 550 nm and high's azimuth interval (5 deg with
// 36 azimuths) the continental aerosol falls 3-4.5x from 1 deg (1 deg cone with R = 10), a 10 um
// water droplet over 100x from 1 deg, 5-7x from 3 deg and 2x from 6.5 deg. A component whose phase
// peaks above kPeakedPhaseMin (cloud droplets' diffraction peak, ~1e3 / sr; the aerosols ~10, air
// 0.12; atmosphere/phase_peak.h) takes R = cone_peaked_ratio (2 at high, so 6.5 deg for the droplets): inside the cloud
// its lobe is scattered again in every order, and with a 3 deg cone the kernel's spread of it left
// a low sun's sky under cloudy0-2 1.5-3.5 % RMS bright against the path tracer (sun 70 and 85 deg;
// docs/sky-methods.md "Truncation cone per component").
void ChooseCones(const OrdersSettings& s, Medium* md) {
  const double interval_deg = 180.0 / s.nphi;  // azimuth nodes at cell centres, pi / nphi apart
  md->cone_deg.assign(md->nc, s.truncation_deg);
  for (size_t c = 0; c < md->nc; ++c) {
    const double ratio = PhasePeak(*md->phase[c], md->nw) > kPeakedPhaseMin ? s.cone_peaked_ratio : s.cone_ratio;
    for (double th = s.truncation_min_deg; th < s.truncation_deg - 1e-9; th += 0.5) {
      bool smooth = true;
      for (size_t w = 0; w < md->nw && smooth; ++w) {
        const double p0 = md->phase[c]->Eval(w, std::cos(th * kDeg));
        const double p1 = md->phase[c]->Eval(w, std::cos(std::min(180.0, th + interval_deg) * kDeg));
        smooth = p0 <= ratio * p1;
      }
      if (smooth) {
        md->cone_deg[c] = th;
        break;
      }
    }
  }
}

// Truncated fractions f and truncated phase functions P* = P / (1 - f) outside the cone, P(cos_c)
// / (1 - f) inside it, on a uniform grid in cos(theta).
void TruncatePhases(Medium* md) {
  const size_t nc = md->nc, nw = md->nw;
  constexpr int kPhaseGrid = Medium::kPhaseGrid;
  md->f.assign(nc * nw, 0.0);
  md->phase_star.assign(nc * kPhaseGrid * nw, 0.0f);
  for (size_t c = 0; c < nc; ++c) {
    const PhaseModel& phase = *md->phase[c];
    const double cos_c = std::cos(md->cone_deg[c] * kDeg);
    for (size_t w = 0; w < nw; ++w) {
      // f = 2 pi int_{cos_c}^{1} (P(mu) - P(cos_c)) dmu, integrated in theta on a log grid
      // (the forward peak of large particles is ~1/x rad wide).
      const double p_c = phase.Eval(w, cos_c);
      const int n = 4000;
      const double th_min = 1e-5, th_max = md->cone_deg[c] * kDeg;
      double f = 0.0, prev_th = 0.0, prev_v = 2 * kPi * std::max(0.0, phase.Eval(w, 1.0) - p_c) * 0.0;
      for (int i = 0; i <= n; ++i) {
        const double th = th_min * std::pow(th_max / th_min, static_cast<double>(i) / n);
        const double v = 2 * kPi * std::max(0.0, phase.Eval(w, std::cos(th)) - p_c) * std::sin(th);
        f += 0.5 * (v + prev_v) * (th - prev_th);
        prev_th = th;
        prev_v = v;
      }
      f = std::clamp(f, 0.0, 0.999);
      md->f[c * nw + w] = f;
      for (int g = 0; g < kPhaseGrid; ++g) {
        const double mu = -1.0 + 2.0 * g / (kPhaseGrid - 1);
        const double p = mu > cos_c ? p_c : phase.Eval(w, mu);
        md->phase_star[(c * kPhaseGrid + g) * nw + w] = static_cast<float>(p / (1.0 - f));
      }
    }
  }
}

// The per-level coefficients. The components whose view-ray attenuation is delta-scaled
// (OrdersSettings::ss_scaled_view): all (2), none (0), or (1) those whose cone holds at least a
// quarter of their scattering at the grid's middle wavelength - cloud droplets (10 um: ~0.5 in a
// 3-5 deg cone), not the aerosols (continental 0.015-0.025 in 5 deg), whose long horizontal view
// rays near the horizon the scaled attenuation makes up to 1 % bright (docs/sky-methods.md
// "TMS attenuation").
void FillCoefficients(const AtmosphereModel& m, const OrdersSettings& s, bool ss_scaled_view, Medium* md) {
  const size_t nl = m.levels(), nc = md->nc, nw = md->nw;
  constexpr double kViewScaledFraction = 0.25;
  std::vector<bool> view_scaled(nc, false);
  for (size_t c = 0; c < nc; ++c) {
    view_scaled[c] = ss_scaled_view && (s.ss_scaled_view == 2 || md->f[c * nw + nw / 2] >= kViewScaledFraction);
  }
  md->sigma_t.assign(nl * nw, 0.0f);
  md->sigma_t_star.assign(nl * nw, 0.0f);
  md->sigma_t_view.assign(nl * nw, 0.0f);
  md->sigma_s.assign(nc * nl * nw, 0.0f);
  md->sigma_s_star.assign(nc * nl * nw, 0.0f);
  for (size_t l = 0; l < nl; ++l) {
    size_t c = 0;
    for (size_t comp = 0; comp < m.components.size(); ++comp) {
      const MediumComponent& mc = m.components[comp];
      for (size_t w = 0; w < nw; ++w) {
        const double ss = mc.scattering[l * nw + w], sa = mc.absorption[l * nw + w];
        md->sigma_t[l * nw + w] += static_cast<float>(ss + sa);
        double trunc = 0.0;
        if (mc.phase) {
          trunc = md->f[c * nw + w] * ss;
          md->sigma_s[(c * nl + l) * nw + w] = static_cast<float>(ss);
          md->sigma_s_star[(c * nl + l) * nw + w] = static_cast<float>(ss - trunc);
        }
        md->sigma_t_star[l * nw + w] += static_cast<float>(ss + sa - trunc);
        md->sigma_t_view[l * nw + w] += static_cast<float>(ss + sa - (mc.phase && view_scaled[c] ? trunc : 0.0));
      }
      if (mc.phase) ++c;
    }
  }
}

}  // namespace

Medium PrepareMedium(const AtmosphereModel& m, const OrdersSettings& s, bool ss_scaled_view) {
  Medium md;
  md.m = &m;
  md.nw = m.wavelengths();
  md.wref = md.nw / 2;
  for (const MediumComponent& c : m.components) {
    if (c.phase) md.phase.push_back(c.phase);
  }
  md.nc = md.phase.size();
  md.albedo = m.ground_albedo;
  md.sun_e = m.sun.irradiance;
  ChooseCones(s, &md);
  TruncatePhases(&md);
  FillCoefficients(m, s, ss_scaled_view, &md);
  return md;
}

Medium SliceMedium(const Medium& md, const std::vector<size_t>& ws) {
  Medium b = md;
  const size_t nw = md.nw, nv = ws.size();
  b.nw = nv;
  b.wref = static_cast<size_t>(std::find(ws.begin(), ws.end(), md.wref) - ws.begin());
  if (b.wref == nv) throw std::logic_error("orders: a wavelength batch without the reference wavelength");
  for (auto* v : {&b.sigma_t, &b.sigma_t_star, &b.sigma_s, &b.sigma_s_star, &b.sigma_t_view, &b.phase_star}) *v = SliceColumns(*v, nw, ws);
  for (auto* v : {&b.f, &b.albedo, &b.sun_e}) *v = SliceColumns(*v, nw, ws);
  b.phase.clear();  // indexed by the model's wavelengths: the render's, never a batch's
  return b;
}

float Medium::SigmaTAt(double z, bool scaled, size_t w) const {
  const AtmosphereModel::Cell c = m->Locate(z);
  const std::vector<float>& s = scaled ? sigma_t_star : sigma_t;
  const float a = s[c.i * nw + w], b = s[(c.i + 1) * nw + w];
  return a + (b - a) * static_cast<float>(c.t);
}

void Medium::LevelLerp(const std::vector<float>& s, const AtmosphereModel::Cell& c, float* out) const {
  const float* a = &s[c.i * nw];
  const float* b = &s[(c.i + 1) * nw];
  const float t = static_cast<float>(c.t);
  for (size_t w = 0; w < nw; ++w) out[w] = a[w] + (b[w] - a[w]) * t;
}

void Medium::SigmaT(const AtmosphereModel::Cell& c, bool scaled, float* out) const {
  LevelLerp(scaled ? sigma_t_star : sigma_t, c, out);
}

void Medium::SigmaTView(const AtmosphereModel::Cell& c, float* out) const { LevelLerp(sigma_t_view, c, out); }

void Medium::SigmaS(size_t comp, const AtmosphereModel::Cell& c, bool scaled, float* out) const {
  const size_t nl = m->levels();
  const std::vector<float>& s = scaled ? sigma_s_star : sigma_s;
  const float* a = &s[(comp * nl + c.i) * nw];
  const float* b = &s[(comp * nl + c.i + 1) * nw];
  const float t = static_cast<float>(c.t);
  for (size_t w = 0; w < nw; ++w) out[w] = a[w] + (b[w] - a[w]) * t;
}

float Medium::PhaseStar(size_t c, double mu, size_t w) const {
  const double g = (mu + 1.0) * 0.5 * (kPhaseGrid - 1);
  const size_t gi = std::min(static_cast<size_t>(g), static_cast<size_t>(kPhaseGrid - 2));
  const float t = static_cast<float>(g - static_cast<double>(gi));
  const float a = phase_star[(c * kPhaseGrid + gi) * nw + w], b = phase_star[(c * kPhaseGrid + gi + 1) * nw + w];
  return a + (b - a) * t;
}

std::string Medium::ConesText() const {
  std::string text;
  size_t c = 0;
  for (const MediumComponent& mc : m->components) {
    if (!mc.phase) continue;
    text += fmt::format("{}{:g} ({}, truncated fraction {:.3f} at {:g} nm)", text.empty() ? "" : ", ", cone_deg[c], mc.name,
                        f[c * nw + nw / 2], m->wavelength_nm[nw / 2]);
    ++c;
  }
  return text;
}

}  // namespace skybake::orders
