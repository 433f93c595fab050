// The fit of GT7's depth function to a reference fog (docs/fog.md, "The fit" and "Where a and p
// live"): which depth tables and elevations the fit uses, the global (a, p) of the fog and the
// shadowed fog, their fit per depth table, and, in the per-slice modes, (a, p) per slice of the fog
// LUT interpolated between the tables' sun angles (and a per elevation node).
#pragma once

#include "fog/fog_luts.h"
#include "fog/fog_reference.h"

namespace skybake::fog {

// Fills out->table_in_fit, elevation_in_fit, fit_fog, fit_shadowed, table_fit_fog,
// table_fit_shadowed and params. UsageError when a --fit-sun-zenith-deg angle is not a depth table
// of the render.
void FitFogParameters(const FogReference& ref, const std::string& sky, FogProducts* out);

}  // namespace skybake::fog
