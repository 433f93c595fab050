// Aerosol optics for the renderers from a Mie table (optics/mie_table.h), on the render grid.
//
// Cross sections are interpolated linearly in wavelength (the table's rule); the phase function
// at a render wavelength between two table wavelengths is the table's linear blend of its
// neighbours, sampled exactly by picking a neighbour with the blend weight (the first uniform
// number is split: u < t picks the upper neighbour with u/t, else the lower with (u-t)/(1-t)).
// On the pipeline's grid the table and the render wavelengths coincide (t = 0).
//
// The simplified phase models of sky-render part 2 (Henyey-Greenstein, Cornette-Shanks,
// dual-lobe HG with the table's per-wavelength best fits) are built from the same table so that
// their cost can be measured against the exact tabulated phase.
#pragma once

#include <memory>
#include <string>

#include "atmosphere/model_build.h"
#include "optics/mie_table.h"
#include "spectrum/grid.h"

namespace skybake {

enum class AerosolPhase { kTabulated, kHenyeyGreenstein, kHenyeyGreensteinMoment, kCornetteShanks, kDualLobe };
const char* AerosolPhaseName(AerosolPhase p);

// Throws InputError(table path) if the table does not cover the grid or 550 nm.
AerosolOptics AerosolOpticsFromMie(const std::string& layer, std::shared_ptr<const mie::MieTable> table,
                                   const WavelengthGrid& grid, AerosolPhase phase = AerosolPhase::kTabulated);

}  // namespace skybake
