#include "atmosphere/mie_optics.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

namespace skybake {

namespace {

class TabulatedMiePhase : public PhaseModel {
 public:
  TabulatedMiePhase(std::shared_ptr<const mie::MieTable> table, const WavelengthGrid& grid) : table_(std::move(table)) {
    for (size_t i = 0; i < grid.size(); ++i) brackets_.push_back(table_->BracketWavelength(grid[i]));
  }
  double Eval(size_t wl, double mu) const override { return At(wl, table_->LocatePhase(mu)); }
  void EvalAll(double mu, size_t n, double* out) const override {
    const mie::MieTable::PhasePoint at = table_->LocatePhase(mu);  // once for every wavelength
    for (size_t w = 0; w < n; ++w) out[w] = At(w, at);
  }
  double SampleMu(size_t wl, double u) const override {
    const mie::MieTable::Bracket& b = brackets_[wl];
    if (b.t <= 0.0) return table_->SamplePhaseCosTheta(b.i0, u);
    if (u < b.t) return table_->SamplePhaseCosTheta(b.i1, u / b.t);
    return table_->SamplePhaseCosTheta(b.i0, (u - b.t) / (1.0 - b.t));
  }
  std::string Name() const override { return "mie-tabulated(" + table_->particle + ")"; }

 private:
  // The grid wavelength's phase at a located angle: its two table neighbours blended linearly.
  double At(size_t wl, const mie::MieTable::PhasePoint& at) const {
    const mie::MieTable::Bracket& b = brackets_[wl];
    const double p0 = table_->EvalPhase(b.i0, at);
    return b.t == 0.0 ? p0 : p0 + (table_->EvalPhase(b.i1, at) - p0) * b.t;
  }
  std::shared_ptr<const mie::MieTable> table_;
  std::vector<mie::MieTable::Bracket> brackets_;
};

// Two-term HG: P = w HG(g1) + (1 - w) HG(g2), sampled by picking a lobe with w.
class DualLobePhase : public PhaseModel {
 public:
  DualLobePhase(std::vector<double> g1, std::vector<double> g2, std::vector<double> w)
      : g1_(std::move(g1)), g2_(std::move(g2)), w_(std::move(w)) {}
  double Eval(size_t wl, double mu) const override {
    return w_[wl] * HenyeyGreensteinPhase::Eval(g1_[wl], mu) + (1.0 - w_[wl]) * HenyeyGreensteinPhase::Eval(g2_[wl], mu);
  }
  double SampleMu(size_t wl, double u) const override {
    if (u < w_[wl]) return HenyeyGreensteinPhase::SampleMu(g1_[wl], u / w_[wl]);
    return HenyeyGreensteinPhase::SampleMu(g2_[wl], (u - w_[wl]) / (1.0 - w_[wl]));
  }
  std::string Name() const override { return "dual-lobe-hg"; }

 private:
  std::vector<double> g1_, g2_, w_;
};

}  // namespace

const char* AerosolPhaseName(AerosolPhase p) {
  switch (p) {
    case AerosolPhase::kTabulated: return "mie";
    case AerosolPhase::kHenyeyGreenstein: return "hg";
    case AerosolPhase::kHenyeyGreensteinMoment: return "hg-moment";
    case AerosolPhase::kCornetteShanks: return "cornette-shanks";
    case AerosolPhase::kDualLobe: return "dual-lobe";
  }
  return "?";
}

AerosolOptics AerosolOpticsFromMie(const std::string& layer, std::shared_ptr<const mie::MieTable> table,
                                   const WavelengthGrid& grid, AerosolPhase phase) {
  const double lo = table->wavelength_nm.front(), hi = table->wavelength_nm.back();
  for (double w : grid.wavelength_nm()) {
    if (w < lo - 1e-9 || w > hi + 1e-9) {
      throw InputError(FileLoc{table->particle, 0},
                       fmt::format("the Mie table covers {}-{} nm, the render grid needs {} nm", lo, hi, w));
    }
  }
  if (550.0 < lo || 550.0 > hi) {
    throw InputError(FileLoc{table->particle, 0}, "the Mie table does not cover 550 nm (needed to scale optical depths)");
  }
  AerosolOptics a;
  a.layer = layer;
  for (double w : grid.wavelength_nm()) {
    a.cext_m2.push_back(table->Interpolate(table->cext_m2, w));
    a.csca_m2.push_back(table->Interpolate(table->csca_m2, w));
  }
  a.cext_550nm_m2 = table->Interpolate(table->cext_m2, 550.0);
  std::vector<double> g, g1, g2, wt;
  for (double w : grid.wavelength_nm()) {
    const mie::MieTable::Bracket b = table->BracketWavelength(w);
    auto mix = [&](auto get) { return get(table->fits[b.i0]) * (1.0 - b.t) + get(table->fits[b.i1]) * b.t; };
    switch (phase) {
      case AerosolPhase::kHenyeyGreenstein: g.push_back(mix([](const mie::PhaseFits& f) { return f.hg_g; })); break;
      case AerosolPhase::kHenyeyGreensteinMoment: g.push_back(table->Interpolate(table->g, w)); break;
      case AerosolPhase::kCornetteShanks: g.push_back(mix([](const mie::PhaseFits& f) { return f.cs_g; })); break;
      case AerosolPhase::kDualLobe:
        g1.push_back(mix([](const mie::PhaseFits& f) { return f.dhg_g1; }));
        g2.push_back(mix([](const mie::PhaseFits& f) { return f.dhg_g2; }));
        wt.push_back(mix([](const mie::PhaseFits& f) { return f.dhg_w; }));
        break;
      case AerosolPhase::kTabulated: break;
    }
  }
  switch (phase) {
    case AerosolPhase::kTabulated: a.phase = std::make_shared<TabulatedMiePhase>(table, grid); break;
    case AerosolPhase::kHenyeyGreenstein:
    case AerosolPhase::kHenyeyGreensteinMoment: a.phase = std::make_shared<HenyeyGreensteinPhase>(g); break;
    case AerosolPhase::kCornetteShanks: a.phase = std::make_shared<CornetteShanksPhase>(g); break;
    case AerosolPhase::kDualLobe: a.phase = std::make_shared<DualLobePhase>(g1, g2, wt); break;
  }
  return a;
}

}  // namespace skybake
