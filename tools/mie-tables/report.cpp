#include "report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "io/yaml.h"

namespace skybake::mietool {

namespace {

std::string Num(double v) { return std::isfinite(v) ? FormatExact(v) : std::string("null"); }

std::string Quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

std::string Fit(const mie::FitError& e) {
  return fmt::format("\"rms_log\": {}, \"max_log\": {}", Num(e.rms_log), Num(e.max_log));
}

}  // namespace

std::string SphereJson(const mie::MieSphereResult& r, std::span<const double> angles_deg) {
  std::string s = "{\n";
  s += "  \"convention\": \"m = n + ik (k >= 0 absorbs), e^(-i omega t), S1 perpendicular and S2 parallel "
       "amplitudes as in Bohren & Huffman (1983); MIEV0 prints the complex conjugates\",\n";
  s += fmt::format("  \"x\": {},\n  \"m\": [{}, {}],\n  \"terms\": {},\n", Num(r.x), Num(r.m.real()), Num(r.m.imag()),
                   r.terms);
  s += fmt::format("  \"qext\": {},\n  \"qsca\": {},\n  \"qabs\": {},\n  \"qback\": {},\n  \"g\": {},\n", Num(r.q.qext),
                   Num(r.q.qsca), Num(r.q.qabs), Num(r.q.qback), Num(r.q.g));
  s += "  \"angles\": [";
  for (size_t i = 0; i < r.mu.size(); ++i) {
    const double i1 = std::norm(r.s1[i]), i2 = std::norm(r.s2[i]);
    s += fmt::format(
        "{}\n    {{\"theta_deg\": {}, \"mu\": {}, \"s1\": [{}, {}], \"s2\": [{}, {}], \"s11\": {}, \"polarization\": {}}}",
        i ? "," : "", Num(angles_deg[i]), Num(r.mu[i]), Num(r.s1[i].real()), Num(r.s1[i].imag()), Num(r.s2[i].real()),
        Num(r.s2[i].imag()), Num(0.5 * (i1 + i2)), Num(i1 + i2 > 0.0 ? (i1 - i2) / (i1 + i2) : 0.0));
  }
  s += r.mu.empty() ? "]\n" : "\n  ]\n";
  s += "}\n";
  return s;
}

std::string BuildReportJson(const mie::ParticleType& type, const mie::MieBuild& build,
                            const mie::MieBuildOptions& options) {
  const mie::MieTable& t = build.table;
  const std::vector<double> f = type.NumberFractions();
  std::string s = "{\n";
  s += fmt::format("  \"particle\": {},\n", Quote(type.name));
  s += fmt::format("  \"wavelengths_nm\": {{\"count\": {}, \"min\": {}, \"max\": {}}},\n", t.wavelengths(),
                   Num(t.wavelength_nm.front()), Num(t.wavelength_nm.back()));
  s += fmt::format("  \"angles\": {},\n", t.theta_rad.size());
  s += fmt::format("  \"quadrature\": {{\"tolerance\": {}, \"x_step_accept\": {}, \"window_tail\": {}}},\n",
                   Num(options.quadrature.tolerance), Num(options.quadrature.x_step_accept),
                   Num(options.quadrature.window_tail));
  s += "  \"mean_particle_volume_m3\": " + Num(t.mean_particle_volume_m3) + ",\n";
  s += "  \"modes\": [";
  for (size_t i = 0; i < type.modes.size(); ++i) {
    const mie::SizeMode& m = type.modes[i];
    if (m.IsTable()) {
      // A tabulated mode: the table's own moments (r_eff = <r^3>/<r^2>, v_eff = <r^4><r^2>/<r^3>^2 - 1).
      const mie::SizeTable& tb = *m.table;
      const double m2 = tb.MomentUm(2), m3 = tb.MomentUm(3), m4 = tb.MomentUm(4);
      s += fmt::format(
          "{}\n    {{\"name\": {}, \"number_fraction\": {}, \"size_table\": {}, \"size_table_basis\": {}, "
          "\"size_table_rows\": {}, \"effective_radius_um\": {}, \"effective_variance\": {}, \"mean_radius_um\": {}, "
          "\"r_min_um\": {}, \"r_max_um\": {}, \"mean_volume_inside_um3\": {}, \"refractive_index\": {}}}",
          i ? "," : "", Quote(m.name), Num(f[i]), Quote(tb.file.filename().string()),
          Quote(tb.basis == mie::SizeBasis::kVolume ? "volume" : "number"), tb.ln_r_um.size(), Num(m3 / m2),
          Num(m4 * m2 / (m3 * m3) - 1.0), Num(tb.MomentUm(1)), Num(m.r_min_um), Num(m.r_max_um),
          Num(m.MeanVolumeInsideUm3()), Quote(m.index.Describe()));
      continue;
    }
    s += fmt::format(
        "{}\n    {{\"name\": {}, \"number_fraction\": {}, \"number_median_radius_um\": {}, "
        "\"volume_median_radius_um\": {}, \"effective_radius_um\": {}, \"effective_variance\": {}, "
        "\"mean_radius_um\": {}, \"ln_sigma_g\": {}, \"r_min_um\": {}, \"r_max_um\": {}, "
        "\"fraction_of_particles_inside\": {}, \"mean_volume_inside_um3\": {}, \"refractive_index\": {}}}",
        i ? "," : "", Quote(m.name), Num(f[i]), Num(m.NumberMedianRadiusUm()), Num(m.VolumeMedianRadiusUm()),
        Num(m.EffectiveRadiusUm()), Num(m.EffectiveVariance()), Num(m.MeanRadiusUm()), Num(m.LnSigma()),
        Num(m.r_min_um), Num(m.r_max_um), Num(m.NumberFractionInside()), Num(m.MeanVolumeInsideUm3()),
        Quote(m.index.Describe()));
  }
  s += "\n  ],\n";
  long radii_total = 0;
  int radii_max = 0;
  double change_max = 0.0, norm_max = 0.0;
  for (size_t w = 0; w < t.wavelengths(); ++w) {
    radii_total += build.integrals[w].radii;
    radii_max = std::max(radii_max, build.integrals[w].radii);
    change_max = std::max(change_max, build.integrals[w].change);
    norm_max = std::max(norm_max, std::abs(t.phase_norm_error[w]));
  }
  s += fmt::format("  \"summary\": {{\"radii_total\": {}, \"radii_max_per_wavelength\": {}, \"largest_last_change\": {}, "
                   "\"largest_phase_norm_error\": {}}},\n",
                   radii_total, radii_max, Num(change_max), Num(norm_max));
  s += "  \"per_wavelength\": [";
  for (size_t w = 0; w < t.wavelengths(); ++w) {
    const mie::PhaseFits& fit = t.fits[w];
    const mie::MixtureIntegral& mi = build.integrals[w];
    std::string groups;
    for (size_t i = 0; i < mi.group_radii.size(); ++i) {
      groups += fmt::format("{}{{\"modes\": {}, \"radii\": {}}}", i ? ", " : "", Quote(mi.group_modes[i]), mi.group_radii[i]);
    }
    s += fmt::format(
        "{}\n    {{\"wavelength_nm\": {}, \"cext_m2\": {}, \"csca_m2\": {}, \"cabs_m2\": {}, \"ssa\": {}, \"g\": {}, "
        "\"phase_norm_error\": {}, \"radii\": {}, \"groups\": [{}], \"levels\": {}, \"last_change\": {}, "
        "\"last_phase_change\": {}, \"panel_change_sum\": {}, \"largest_size_parameter\": {}, "
        "\"hg\": {{\"g\": {}, {}}}, \"hg_moment\": {{{}}}, \"cs\": {{\"g\": {}, {}}}, "
        "\"dhg\": {{\"g1\": {}, \"g2\": {}, \"w\": {}, {}}}}}",
        w ? "," : "", Num(t.wavelength_nm[w]), Num(t.cext_m2[w]), Num(t.csca_m2[w]), Num(t.cabs_m2[w]), Num(t.ssa[w]),
        Num(t.g[w]), Num(t.phase_norm_error[w]), mi.radii, groups, mi.levels, Num(mi.change), Num(mi.phase_change), Num(mi.panel_change_sum),
        Num(mi.x_max), Num(fit.hg_g), Fit(fit.hg), Fit(fit.hg_moment), Num(fit.cs_g), Fit(fit.cs), Num(fit.dhg_g1),
        Num(fit.dhg_g2), Num(fit.dhg_w), Fit(fit.dhg));
  }
  s += "\n  ]\n}\n";
  return s;
}

std::string SpectralCsv(const mie::MieTable& t, const std::string& source) {
  std::string s = "# source: " + source + "\n";
  s += "wavelength_nm,cext_m2,csca_m2,cabs_m2,ssa,g,phase_norm_error,hg_g,hg_rms_log,hg_max_log,hgm_rms_log,"
       "hgm_max_log,cs_g,cs_rms_log,cs_max_log,dhg_g1,dhg_g2,dhg_w,dhg_rms_log,dhg_max_log\n";
  for (size_t w = 0; w < t.wavelengths(); ++w) {
    const mie::PhaseFits& f = t.fits[w];
    s += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", Num(t.wavelength_nm[w]),
                     Num(t.cext_m2[w]), Num(t.csca_m2[w]), Num(t.cabs_m2[w]), Num(t.ssa[w]), Num(t.g[w]),
                     Num(t.phase_norm_error[w]), Num(f.hg_g), Num(f.hg.rms_log), Num(f.hg.max_log),
                     Num(f.hg_moment.rms_log), Num(f.hg_moment.max_log), Num(f.cs_g), Num(f.cs.rms_log),
                     Num(f.cs.max_log), Num(f.dhg_g1), Num(f.dhg_g2), Num(f.dhg_w), Num(f.dhg.rms_log),
                     Num(f.dhg.max_log));
  }
  return s;
}

std::string PhaseCsv(const mie::MieTable& t, size_t wl, const std::string& source) {
  const mie::PhaseFits& f = t.fits[wl];
  std::string s = "# source: " + source + fmt::format(", wavelength {} nm", Num(t.wavelength_nm[wl])) + "\n";
  s += "theta_deg,mu,phase_sr,cdf,hg_sr,hg_moment_sr,cs_sr,dhg_sr\n";
  for (size_t j = 0; j < t.theta_rad.size(); ++j) {
    const double mu = t.mu[j];
    s += fmt::format("{},{},{},{},{},{},{},{}\n", Num(t.theta_rad[j] * 180.0 / std::numbers::pi), Num(mu),
                     Num(t.phase[wl][j]), Num(t.cdf[wl][j]), Num(mie::HenyeyGreenstein(mu, f.hg_g)),
                     Num(mie::HenyeyGreenstein(mu, t.g[wl])), Num(mie::CornetteShanks(mu, f.cs_g)),
                     Num(mie::DualHenyeyGreenstein(mu, f.dhg_g1, f.dhg_g2, f.dhg_w)));
  }
  return s;
}

}  // namespace skybake::mietool
