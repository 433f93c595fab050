#include "transport/spectral_stride.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "io/error.h"

namespace skybake {

namespace {

// A phase model seen through an index map (subset wavelength -> full-grid wavelength).
class SubsetPhase : public PhaseModel {
 public:
  SubsetPhase(std::shared_ptr<const PhaseModel> inner, std::vector<size_t> idx)
      : inner_(std::move(inner)), idx_(std::move(idx)) {}
  double Eval(size_t wl, double mu) const override { return inner_->Eval(idx_[wl], mu); }
  double SampleMu(size_t wl, double u) const override { return inner_->SampleMu(idx_[wl], u); }
  std::string Name() const override { return inner_->Name(); }

 private:
  std::shared_ptr<const PhaseModel> inner_;
  std::vector<size_t> idx_;
};

class SpectralStrideMethod : public SkyMethod {
 public:
  SpectralStrideMethod(const std::string& inner, const AtmosphereModel& model, const SkyMethodOptions& options,
                       const ProgressFn& progress, int stride)
      : stride_(stride),
        idx_(StrideIndices(model.wavelengths(), stride)),
        sub_(SubsetWavelengths(model, idx_, true)),
        sun_(model.sun.irradiance),
        wl_(model.wavelength_nm) {
    SkyMethodOptions o = options;
    o.spectral_stride = 1;
    inner_ = MakeSkyMethod(inner, sub_, o, progress);
    // Per full-grid wavelength: the bracketing subset nodes and the log-lambda weight.
    for (size_t w = 0; w < wl_.size(); ++w) {
      size_t k = static_cast<size_t>(std::upper_bound(idx_.begin(), idx_.end(), w) - idx_.begin());
      k = std::clamp<size_t>(k, 1, idx_.size() - 1);
      const size_t a = idx_[k - 1], b = idx_[k];
      const double t = b == a ? 0.0 : std::log(wl_[w] / wl_[a]) / std::log(wl_[b] / wl_[a]);
      node_.push_back({k - 1, std::clamp(t, 0.0, 1.0)});
    }
  }

  std::string Name() const override { return inner_->Name(); }
  std::string Describe() const override {
    return inner_->Describe() + fmt::format("spectral_stride: {}  # {} of {} wavelengths, transfer log-log interpolated\n",
                                            stride_, idx_.size(), wl_.size());
  }
  void Radiance(double h, double sz, const std::vector<std::array<double, 3>>& dirs, std::vector<double>* out) const override {
    std::vector<double> sub;
    inner_->Radiance(h, sz, dirs, &sub);
    Expand(sub, dirs.size(), out);
  }
  bool SupportsSegments() const override { return inner_->SupportsSegments(); }
  bool SingleScatteringRadiance(double h, double sz, const std::vector<std::array<double, 3>>& dirs,
                                std::vector<double>* out) const override {
    std::vector<double> sub;
    if (!inner_->SingleScatteringRadiance(h, sz, dirs, &sub)) return false;
    Expand(sub, dirs.size(), out);
    return true;
  }
  void SegmentRadiance(double h, double sz, const std::vector<std::array<double, 3>>& dirs, const ViewSegment& seg,
                       std::vector<double>* out) const override {
    std::vector<double> sub;
    inner_->SegmentRadiance(h, sz, dirs, seg, &sub);
    Expand(sub, dirs.size(), out);
  }

 private:
  struct Node {
    size_t k;  // lower subset node
    double t;  // weight of the upper one in log(lambda)
  };

  void Expand(const std::vector<double>& sub, size_t n, std::vector<double>* out) const {
    const size_t ns = idx_.size(), nw = wl_.size();
    out->assign(n * nw, 0.0);
    for (size_t d = 0; d < n; ++d) {
      const double* s = &sub[d * ns];
      double* o = &(*out)[d * nw];
      for (size_t w = 0; w < nw; ++w) {
        const Node& q = node_[w];
        const double a = s[q.k], b = s[q.k + 1];
        const double tr = (a > 0.0 && b > 0.0) ? std::exp((1.0 - q.t) * std::log(a) + q.t * std::log(b))
                                               : (1.0 - q.t) * a + q.t * b;
        o[w] = sun_[w] * tr;
      }
    }
  }

  int stride_;
  std::vector<size_t> idx_;
  AtmosphereModel sub_;  // before inner_: the method keeps a reference to it
  std::vector<double> sun_, wl_;
  std::vector<Node> node_;
  std::unique_ptr<SkyMethod> inner_;
};

}  // namespace

std::vector<size_t> StrideIndices(size_t n, int stride) {
  std::vector<size_t> idx;
  if (n == 0) return idx;
  const size_t k = static_cast<size_t>(std::max(1, stride));
  for (size_t i = 0; i < n; i += k) idx.push_back(i);
  if (idx.back() != n - 1) idx.push_back(n - 1);
  return idx;
}

AtmosphereModel SubsetWavelengths(const AtmosphereModel& m, const std::vector<size_t>& idx, bool unit_sun) {
  const size_t nw = m.wavelengths();
  AtmosphereModel s;
  s.bottom_radius_m = m.bottom_radius_m;
  s.top_radius_m = m.top_radius_m;
  s.altitude_m = m.altitude_m;
  for (size_t i : idx) {
    SKYBAKE_CHECK(i < nw);
    s.wavelength_nm.push_back(m.wavelength_nm[i]);
    s.ground_albedo.push_back(m.ground_albedo[i]);
    s.sun.irradiance.push_back(unit_sun ? 1.0 : m.sun.irradiance[i]);
    if (!m.sun.limb_coefficients.empty()) s.sun.limb_coefficients.push_back(m.sun.limb_coefficients[i]);
  }
  s.sun.angular_radius_rad = m.sun.angular_radius_rad;
  for (const MediumComponent& c : m.components) {
    MediumComponent d;
    d.name = c.name;
    if (c.phase) d.phase = std::make_shared<SubsetPhase>(c.phase, idx);
    for (size_t l = 0; l < m.levels(); ++l) {
      for (size_t i : idx) {
        d.scattering.push_back(c.scattering[l * nw + i]);
        d.absorption.push_back(c.absorption[l * nw + i]);
      }
    }
    s.components.push_back(std::move(d));
  }
  s.Finalize();
  return s;
}

std::unique_ptr<SkyMethod> MakeSpectralStrideMethod(const std::string& inner, const AtmosphereModel& model,
                                                    const SkyMethodOptions& options, const ProgressFn& progress) {
  return std::make_unique<SpectralStrideMethod>(inner, model, options, progress, options.spectral_stride);
}

}  // namespace skybake
