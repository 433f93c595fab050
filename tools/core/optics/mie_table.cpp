#include "optics/mie_table.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "io/error.h"
#include "io/fileio.h"
#include "io/interp.h"
#include "io/yaml.h"

namespace skybake::mie {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// (e^L - 1)/L, the logarithmic-mean factor of a segment (1 at L = 0).
double ExpFactor(double L) { return L == 0.0 ? 1.0 : std::expm1(L) / L; }

// j with mu[j] >= v >= mu[j+1] (mu descending), clamped to [0, n-2].
size_t FindSegment(const std::vector<double>& mu, double v) {
  size_t lo = 0, hi = mu.size() - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    if (mu[mid] >= v) lo = mid;
    else hi = mid;
  }
  return lo;
}

// Channels of the "spectral" part: name, unit, accessor.
struct SpectralChannel {
  const char* name;
  const char* unit;
  double (*get)(const MieTable&, size_t);
  void (*set)(MieTable&, size_t, double);
};

#define SKYBAKE_VEC(field)                                                      \
  [](const MieTable& t, size_t i) { return t.field[i]; },                       \
      [](MieTable& t, size_t i, double v) { t.field[i] = v; }
#define SKYBAKE_FIT(field)                                                      \
  [](const MieTable& t, size_t i) { return t.fits[i].field; },                  \
      [](MieTable& t, size_t i, double v) { t.fits[i].field = v; }

const SpectralChannel kSpectral[] = {
    {"cext_m2", "m^2", SKYBAKE_VEC(cext_m2)},
    {"csca_m2", "m^2", SKYBAKE_VEC(csca_m2)},
    {"cabs_m2", "m^2", SKYBAKE_VEC(cabs_m2)},
    {"ssa", "1", SKYBAKE_VEC(ssa)},
    {"g", "1", SKYBAKE_VEC(g)},
    {"phase_norm_error", "1", SKYBAKE_VEC(phase_norm_error)},
    {"hg_g", "1", SKYBAKE_FIT(hg_g)},
    {"hg_rms_log", "1", SKYBAKE_FIT(hg.rms_log)},
    {"hg_max_log", "1", SKYBAKE_FIT(hg.max_log)},
    {"hgm_rms_log", "1", SKYBAKE_FIT(hg_moment.rms_log)},
    {"hgm_max_log", "1", SKYBAKE_FIT(hg_moment.max_log)},
    {"cs_g", "1", SKYBAKE_FIT(cs_g)},
    {"cs_rms_log", "1", SKYBAKE_FIT(cs.rms_log)},
    {"cs_max_log", "1", SKYBAKE_FIT(cs.max_log)},
    {"dhg_g1", "1", SKYBAKE_FIT(dhg_g1)},
    {"dhg_g2", "1", SKYBAKE_FIT(dhg_g2)},
    {"dhg_w", "1", SKYBAKE_FIT(dhg_w)},
    {"dhg_rms_log", "1", SKYBAKE_FIT(dhg.rms_log)},
    {"dhg_max_log", "1", SKYBAKE_FIT(dhg.max_log)},
};
#undef SKYBAKE_VEC
#undef SKYBAKE_FIT

const char* kInterpolation =
    "phase: log-linear in mu = cos(theta) between grid angles (P = P_j (P_j+1/P_j)^t, t = (mu_j - mu)/(mu_j - "
    "mu_j+1)), scaled so that this interpolant integrates to 1 over the sphere; cdf is its exact integral from "
    "theta = 0; wavelength: linear in wavelength for every channel (docs/mie.md)";

}  // namespace

double IntegratePhase(const std::vector<double>& mu, const std::vector<double>& phase) {
  double total = 0.0;
  for (size_t j = 0; j + 1 < mu.size(); ++j) {
    total += kTwoPi * (mu[j] - mu[j + 1]) * phase[j] * ExpFactor(std::log(phase[j + 1] / phase[j]));
  }
  return total;
}

double MieTable::FinishPhase() {
  const size_t n = mu.size();
  SKYBAKE_CHECK_GE(n, 2u);
  dmu_.resize(n - 1);
  for (size_t j = 0; j + 1 < n; ++j) {
    dmu_[j] = mu[j] - mu[j + 1];
    SKYBAKE_CHECK_GT(dmu_[j], 0.0);
  }
  double worst = 0.0;
  ln_phase_.assign(phase.size(), {});
  cdf.assign(phase.size(), {});
  for (size_t w = 0; w < phase.size(); ++w) {
    std::vector<double>& p = phase[w];
    SKYBAKE_CHECK_EQ(p.size(), n);
    const double scale = 1.0 / IntegratePhase(mu, p);
    worst = std::max(worst, std::abs(scale - 1.0));
    std::vector<double>& lp = ln_phase_[w];
    lp.resize(n);
    for (size_t j = 0; j < n; ++j) {
      p[j] *= scale;
      lp[j] = std::log(p[j]);
    }
    std::vector<double>& c = cdf[w];
    c.assign(n, 0.0);
    for (size_t j = 0; j + 1 < n; ++j) c[j + 1] = c[j] + kTwoPi * dmu_[j] * p[j] * ExpFactor(lp[j + 1] - lp[j]);
    c[n - 1] = 1.0;  // equal to the sum within rounding (the scale made it 1)
  }
  return worst;
}

MieTable::PhasePoint MieTable::LocatePhase(double cos_theta) const {
  const double v = std::clamp(cos_theta, -1.0, 1.0);
  const size_t j = FindSegment(mu, v);
  return {j, std::clamp((mu[j] - v) / dmu_[j], 0.0, 1.0)};
}

double MieTable::EvalPhase(size_t wl, double cos_theta) const {
  SKYBAKE_CHECK_LT(wl, ln_phase_.size());
  return EvalPhase(wl, LocatePhase(cos_theta));
}

double MieTable::SamplePhaseCosTheta(size_t wl, double u) const {
  SKYBAKE_CHECK_LT(wl, cdf.size());
  const std::vector<double>& c = cdf[wl];
  const double v = std::clamp(u, 0.0, 1.0);
  // The segment j with c[j] <= v < c[j+1].
  size_t j = static_cast<size_t>(std::upper_bound(c.begin(), c.end(), v) - c.begin());
  j = std::clamp<size_t>(j, 1, c.size() - 1) - 1;
  const double L = ln_phase_[wl][j + 1] - ln_phase_[wl][j];
  const double y = (v - c[j]) / (kTwoPi * dmu_[j] * phase[wl][j]);
  double t = L == 0.0 ? y : std::log1p(y * L) / L;
  if (!(t >= 0.0)) t = 0.0;  // also catches NaN from log1p of a value <= -1 at the very end
  t = std::min(t, 1.0);
  return mu[j] - t * dmu_[j];
}

MieTable::Bracket MieTable::BracketWavelength(double wl) const {
  SKYBAKE_CHECK(!wavelength_nm.empty());
  const double lo = wavelength_nm.front(), hi = wavelength_nm.back();
  const double tol = 1e-9 * std::max(1.0, hi - lo);
  if (!(wl >= lo - tol && wl <= hi + tol)) {
    detail::CheckFailed(__FILE__, __LINE__,
                        fmt::format("wavelength {} nm outside the Mie table ({}-{} nm)", wl, lo, hi));
  }
  if (wavelength_nm.size() == 1) return {0, 0, 0.0};
  const size_t i = FindInterval(wavelength_nm, wl);
  const double t = std::clamp((wl - wavelength_nm[i]) / (wavelength_nm[i + 1] - wavelength_nm[i]), 0.0, 1.0);
  return {i, i + 1, t};
}

double MieTable::Interpolate(const std::vector<double>& v, double wl) const {
  const Bracket b = BracketWavelength(wl);
  return v[b.i0] + b.t * (v[b.i1] - v[b.i0]);
}

double MieTable::EvalPhaseAt(double wl, double cos_theta) const {
  const Bracket b = BracketWavelength(wl);
  return (1.0 - b.t) * EvalPhase(b.i0, cos_theta) + b.t * EvalPhase(b.i1, cos_theta);
}

double MieTable::SamplePhaseCosThetaAt(double wl, double u_pick, double u) const {
  const Bracket b = BracketWavelength(wl);
  return SamplePhaseCosTheta(u_pick < b.t ? b.i1 : b.i0, u);
}

// ---------------------------------------------------------------------------- files

std::vector<ExrPart> MieTableParts(const MieTable& t, const Provenance& provenance) {
  const size_t nw = t.wavelengths();
  SKYBAKE_CHECK_GE(nw, 1u);
  ExrAxis wl_axis{"wavelength", "nm", "vacuum wavelength of the light, the pipeline's spectral grid", t.wavelength_nm};

  ExrTable spectral;
  spectral.axes = {wl_axis};
  for (const SpectralChannel& c : kSpectral) {
    spectral.channels.push_back(c.name);
    spectral.channel_units.push_back(c.unit);
  }
  spectral.values.resize(nw * spectral.channels.size());
  for (size_t i = 0; i < nw; ++i) {
    for (size_t c = 0; c < std::size(kSpectral); ++c) spectral.At(i, c) = static_cast<float>(kSpectral[c].get(t, i));
  }

  ExrTable phase;
  phase.axes = {ExrAxis{"theta", "rad",
                        "scattering angle, 0 = forward; log-spaced 0.01-5 deg and its mirror about 90 deg, 0.125 deg "
                        "steps between (docs/mie.md)",
                        t.theta_rad},
                wl_axis};
  phase.channels = {"phase_sr", "cdf"};
  phase.channel_units = {"sr^-1", "1"};
  const size_t na = t.theta_rad.size();
  phase.values.resize(na * nw * 2);
  for (size_t w = 0; w < nw; ++w) {
    for (size_t j = 0; j < na; ++j) {
      phase.At(w * na + j, 0) = static_cast<float>(t.phase[w][j]);
      phase.At(w * na + j, 1) = static_cast<float>(t.cdf[w][j]);
    }
  }

  std::vector<ExrPart> parts{{"spectral", TableToImage(spectral)}, {"phase", TableToImage(phase)}};
  for (ExrPart& p : parts) {
    SetProvenance(p.image, provenance);
    p.image.strings["skybake.mie.particle"] = t.particle;
    p.image.strings["skybake.mie.interpolation"] = kInterpolation;
    p.image.strings["skybake.mie.modes"] = t.modes_text;
    p.image.doubles["skybake.mie.mean_particle_volume_m3"] = t.mean_particle_volume_m3;
  }
  return parts;
}

bool WriteMieTable(const std::filesystem::path& path, const MieTable& table, const Provenance& provenance) {
  return WriteExrParts(path, MieTableParts(table, provenance));
}

MieTable ReadMieTable(const std::filesystem::path& path) {
  const std::string name = path.string();
  auto fail = [&](const std::string& what) { throw InputError(FileLoc{name, 0}, "not a Mie table: " + what); };
  const std::vector<ExrPart> parts = ReadExrParts(path);
  const ExrImage& spectral_img = FindPart(parts, "spectral", name);
  const ExrImage& phase_img = FindPart(parts, "phase", name);
  const ExrTable spectral = ImageToTable(spectral_img, name);
  const ExrTable phase = ImageToTable(phase_img, name);
  if (spectral.axes.size() != 1 || spectral.axes[0].name != "wavelength" || spectral.axes[0].unit != "nm") {
    fail("part 'spectral' must have one axis 'wavelength' in nm");
  }
  if (phase.axes.size() != 2 || phase.axes[0].name != "theta" || phase.axes[0].unit != "rad" ||
      phase.axes[1].name != "wavelength" || phase.axes[1].values != spectral.axes[0].values) {
    fail("part 'phase' must have axes 'theta' (rad) and the same 'wavelength' axis");
  }
  MieTable t;
  t.wavelength_nm = spectral.axes[0].values;
  t.theta_rad = phase.axes[0].values;
  const size_t nw = t.wavelength_nm.size(), na = t.theta_rad.size();
  if (na < 2 || t.theta_rad.front() != 0.0 || std::abs(t.theta_rad.back() - std::numbers::pi) > 1e-12) {
    fail("the theta axis must run from 0 to pi");
  }
  for (size_t j = 1; j < na; ++j) {
    if (!(t.theta_rad[j] > t.theta_rad[j - 1])) fail("the theta axis must increase strictly");
  }
  for (size_t i = 1; i < nw; ++i) {
    if (!(t.wavelength_nm[i] > t.wavelength_nm[i - 1])) fail("the wavelength axis must increase strictly");
  }
  auto it = spectral_img.strings.find("skybake.mie.particle");
  if (it != spectral_img.strings.end()) t.particle = it->second;
  it = spectral_img.strings.find("skybake.mie.modes");
  if (it != spectral_img.strings.end()) t.modes_text = it->second;
  auto vol = spectral_img.doubles.find("skybake.mie.mean_particle_volume_m3");
  if (vol != spectral_img.doubles.end()) t.mean_particle_volume_m3 = vol->second;

  t.cext_m2.resize(nw);
  t.csca_m2.resize(nw);
  t.cabs_m2.resize(nw);
  t.ssa.resize(nw);
  t.g.resize(nw);
  t.phase_norm_error.resize(nw);
  t.fits.resize(nw);
  for (const SpectralChannel& c : kSpectral) {
    const int ci = spectral.ChannelIndex(c.name);
    if (ci < 0) fail(fmt::format("part 'spectral' has no channel '{}'", c.name));
    for (size_t i = 0; i < nw; ++i) {
      const double v = spectral.At(i, ci);
      if (!std::isfinite(v)) fail(fmt::format("channel '{}' holds a non-finite value", c.name));
      c.set(t, i, v);
    }
  }
  const int pc = phase.ChannelIndex("phase_sr");
  if (pc < 0 || phase.ChannelIndex("cdf") < 0) fail("part 'phase' needs channels 'phase_sr' and 'cdf'");
  t.mu.resize(na);
  for (size_t j = 0; j < na; ++j) t.mu[j] = t.theta_rad[j] == std::numbers::pi / 2.0 ? 0.0 : std::cos(t.theta_rad[j]);
  t.phase.assign(nw, std::vector<double>(na));
  for (size_t w = 0; w < nw; ++w) {
    for (size_t j = 0; j < na; ++j) {
      const double v = phase.At(w * na + j, pc);
      if (!(v > 0.0) || !std::isfinite(v)) {
        fail(fmt::format("phase_sr at {} nm, theta = {} rad is {} (must be positive)", FormatExact(t.wavelength_nm[w]),
                         FormatExact(t.theta_rad[j]), v));
      }
      t.phase[w][j] = v;
    }
  }
  // Stored values are float32: the interpolant integrates to 1 within their rounding. Rescale
  // exactly (double) and rebuild the CDF so that sampling matches EvalPhase to double precision.
  const double correction = t.FinishPhase();
  if (correction > 1e-5) fail(fmt::format("a phase function integrates to 1 only within {:.3g}", correction));
  return t;
}

}  // namespace skybake::mie
