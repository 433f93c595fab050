// Text outputs of mie-tables (docs/mie.md, "Command line"): the single-sphere JSON, the build report
// JSON and the CSV dumps. Numbers are written so that they read back exactly (shortest
// round-trip form); nothing depends on time or thread count, so equal inputs give equal bytes.
#pragma once

#include <span>
#include <string>

#include "optics/mie_sphere.h"
#include "optics/mie_table.h"
#include "optics/particle_type.h"
#include "optics/polydisperse.h"

namespace skybake::mietool {

// JSON of one sphere; `angles_deg` are the angles of r.mu.
std::string SphereJson(const mie::MieSphereResult& r, std::span<const double> angles_deg);

// The build report: modes, quadrature counts, convergence, normalisation and fit errors.
std::string BuildReportJson(const mie::ParticleType& type, const mie::MieBuild& build,
                            const mie::MieBuildOptions& options);

// CSV dumps of a table (first line "# source: ...", unit-bearing headers).
std::string SpectralCsv(const mie::MieTable& t, const std::string& source);
// The phase function at tabulated wavelength index `wl` with the fitted models beside it.
std::string PhaseCsv(const mie::MieTable& t, size_t wl, const std::string& source);

}  // namespace skybake::mietool
