// The fog model's errors against its reference (docs/fog.md, "Measured errors"): every sample of
// the depth tables, twice (the depth function with the exact x = 1 fog, "fit", and the evaluator
// on the packed textures, "evaluator"), as relative luminance error statistics over subsets and
// as residual maps; the fit error with other parameter choices (diagnostics); and the attenuation
// LUT against the exact sunlight-weighted transmittance. Accumulated serially in table order, so
// the statistics are deterministic.
#pragma once

#include "fog/fog_evaluator.h"
#include "fog/fog_luts.h"
#include "fog/fog_reference.h"

namespace skybake::fog {

// Fills out->fog_fit, fog_eval, shadowed_fit, shadowed_eval, the residual maps,
// excluded_samples and reference_noise_rms. `eval` reads out's packed textures and parameters.
void MeasureFogErrors(const FogReference& ref, const FogEvaluator& eval, FogProducts* out);

// Appends to out->diagnostics the fog's fit error (luminance) with other parameter choices on the
// same samples: global, per table, per table and azimuth, per table and elevation.
void AddFitDiagnostics(const FogReference& ref, FogProducts* out);

// Fills out->attenuation_rms_abs and attenuation_max_abs: the evaluator's transmittance against
// `sunlight` of the render's exact transmittance at the depth tables' points.
void MeasureAttenuation(const FogReference& ref, const FogEvaluator& eval, const SunlightTransmittance& sunlight,
                        FogProducts* out);

}  // namespace skybake::fog
