// A phase function tabulated against the scattering angle in a CSV file (an aerosol layer's
// `phase: {table: ...}`, atmosphere/optics_spec.h), the same at every wavelength.
//
// The table's rows give P at angles theta_j from 0 to 180 deg (strictly increasing, both ends
// present); between rows P is linear in mu = cos theta, so the function is exactly integrable:
// it is normalised on load to 2 pi int_{-1}^{1} P dmu = 1 (tables come with other conventions:
// libRadtran's phase files integrate to 2 over mu, some to 4 pi), and sampled by inverting its
// piecewise-quadratic CDF in closed form.
#pragma once

#include <filesystem>
#include <vector>

#include "atmosphere/model.h"

namespace skybake {

class TabulatedPhase : public PhaseModel {
 public:
  // Throws InputError (file:line) for a table that is not a phase function.
  static TabulatedPhase Load(const std::filesystem::path& file, const std::string& angle_column,
                             const std::string& value_column);
  // From angles (rad, ascending from 0 to pi) and values >= 0 (any normalisation, not all 0).
  TabulatedPhase(const std::vector<double>& theta_rad, const std::vector<double>& values, std::string name);

  double Eval(size_t, double mu) const override;
  double SampleMu(size_t, double u) const override;
  std::string Name() const override { return "tabulated(" + name_ + ")"; }
  // The factor the table's values were multiplied by to integrate to 1.
  double normalisation() const { return normalisation_; }

 private:
  std::vector<double> mu_;   // ascending from -1 to 1
  std::vector<double> p_;    // normalised, at mu_
  std::vector<double> cdf_;  // 2 pi int_{-1}^{mu_j} P dmu; cdf_.back() = 1
  std::string name_;
  double normalisation_ = 1.0;
};

}  // namespace skybake
