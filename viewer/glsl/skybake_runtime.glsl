// skybake_runtime.glsl: the reference runtime of skybake's baked textures, GLSL ES 3.00.
//
// One file a studio ports: every function a game needs to turn the textures of `lut-pack` and
// `fog-fit` into sky radiance, fog and attenuation, with the names and equations of
// docs/lut-pack.md ("Mappings", "Decoding") and docs/fog.md ("The model", "The evaluator"). It is
// the float32 twin of the C++ reference decoders tools/core/lut/decoder.h (SkyLutDecoder),
// tools/core/lut/gt7_mapping.h (TimeMapping, SphereMapping) and tools/core/fog/fog_evaluator.h
// (FogEvaluator); viewer/ renders with it and tests/viewer/test_viewer.py checks it against them.
// docs/runtime.md lists the fetches and ALU per pixel and what a port to HLSL needs.
//
// Frame (lut/directions.h): +z the zenith, +x the sun's azimuth, the sun at
// (sin theta_s, 0, cos theta_s); the sky is mirror-symmetric about the x-z plane, so only |y|
// matters. Angles in radians, radiance in cd/m^2 (Linear Rec.2020, the textures' colour space),
// distances in metres.
//
// Every texture read goes through SB_TEXTURE / SB_TEXEL_FETCH so that a build with
// SB_COUNT_FETCHES defined counts them per pixel (the viewer's benchmark reads the count back).

#ifdef SB_COUNT_FETCHES
float sb_fetches = 0.0;
#define SB_TEXTURE(s, c) (sb_fetches += 1.0, texture(s, c))
#define SB_TEXEL_FETCH(s, c, l) (sb_fetches += 1.0, texelFetch(s, c, l))
#else
#define SB_TEXTURE(s, c) texture(s, c)
#define SB_TEXEL_FETCH(s, c, l) texelFetch(s, c, l)
#endif

const float SB_PI = 3.14159265358979;
const float SB_DEG = SB_PI / 180.0;

// ------------------------------------------------------------------------------------ time
// GT7 "Adaptive Mapping of LUT (time component)"; lut/gt7_mapping.h TimeMapping. Slices
// 0 .. Nu-1 (upper): d_i = lerp(d_min, d_max, (i/(Nu-1))^p), cos theta_i = (R^2 - r^2 - d_i^2) /
// (2 r d_i); slices Nu .. Nu+Nl-1 (lower): theta_i = lerp(90, 100 deg, ((i - Nu)/(Nl - 1))^2).
struct SbTimeMapping {
  float upper;     // Nu (GT7: 48)
  float lower;     // Nl (GT7: 16)
  float power;     // p: 1 "gt7", 2 "gt7-quadratic"
  float r;         // observer radius (m): planet radius + observer altitude
  float R;         // top of the atmosphere's radius (m)
};

float sbSlices(SbTimeMapping tm) { return tm.upper + tm.lower; }
float sbDMin(SbTimeMapping tm) { return tm.R - tm.r; }
float sbDMax(SbTimeMapping tm) { return sqrt((tm.R - tm.r) * (tm.R + tm.r)); }

// Path length from the observer to the top of the atmosphere along zenith angle z; the
// rationalised form (R^2 - r^2) / (root + r cos z) for cos z >= 0 has no cancellation.
float sbPathToBoundary(SbTimeMapping tm, float z) {
  float c = cos(z);
  float k = (tm.R - tm.r) * (tm.R + tm.r);
  float root = sqrt(tm.r * tm.r * c * c + k);
  return c >= 0.0 ? k / (root + tm.r * c) : root - tm.r * c;
}

// The sun zenith angle of slice i.
float sbSliceZenith(SbTimeMapping tm, float i) {
  if (i < tm.upper) {
    if (i <= 0.0) return 0.0;
    if (i >= tm.upper - 1.0) return 0.5 * SB_PI;
    float d = mix(sbDMin(tm), sbDMax(tm), pow(i / (tm.upper - 1.0), tm.power));
    float c = clamp(((tm.R - tm.r) * (tm.R + tm.r) - d * d) / (2.0 * tm.r * d), -1.0, 1.0);
    return atan(sqrt((1.0 - c) * (1.0 + c)), c);  // acos(c), without acos' loss near c = 1 on some GPUs
  }
  float f = (i - tm.upper) / (tm.lower - 1.0);
  return (90.0 + 10.0 * f * f) * SB_DEG;
}

// The continuous slice coordinate s(theta) in [0, N - 1]: the exact inverse of sbSliceZenith.
float sbSliceCoordinate(SbTimeMapping tm, float z) {
  if (!(z > 0.0)) return 0.0;
  if (z <= 0.5 * SB_PI) {
    float x = max(0.0, (sbPathToBoundary(tm, z) - sbDMin(tm)) / (sbDMax(tm) - sbDMin(tm)));
    return clamp((tm.upper - 1.0) * pow(x, 1.0 / tm.power), 0.0, tm.upper - 1.0);
  }
  float f = sqrt((z / SB_DEG - 90.0) / 10.0);
  return min(tm.upper + (tm.lower - 1.0) * f, sbSlices(tm) - 1.0);
}

// The two slices a sun zenith angle reads and the weight of the second (decoder.h SliceBlend):
// i = min(floor(s), N - 2), t = (theta - theta_i) / (theta_{i+1} - theta_i), linear in the angle.
// Beyond the last slice: i = N - 1, t = 0.
vec2 sbSliceBlend(SbTimeMapping tm, float z) {
  float n = sbSlices(tm);
  if (z > sbSliceZenith(tm, n - 1.0)) return vec2(n - 1.0, 0.0);
  float i = min(floor(sbSliceCoordinate(tm, z)), n - 2.0);
  float a = sbSliceZenith(tm, i), b = sbSliceZenith(tm, i + 1.0);
  float t = b > a ? clamp((z - a) / (b - a), 0.0, 1.0) : 0.0;
  return vec2(i, t);
}

// ---------------------------------------------------------------------------------- sphere
// GT7 "Adaptive Mapping of LUT (spherical direction)", "Concept Code"; lut/gt7_mapping.h
// SphereMapping::UvIn. Sun-aligned family (sun elevation >= the threshold, 15 deg): polar angles
// around the sun normalised by the horizon's, the concept code's v transform (a 0.5, b 0.8,
// c 0.25, d 0.5; the horizon at v = 0.8). Lat-long family (below): view zenith pi v' with the
// K transform, azimuth from the sun pi u^2.

// The concept code's v' -> v (inverse of its v transform), lut/gt7_mapping.cpp SunAlignedUnwarp.
float sbSunAlignedUnwarp(float vp) {
  vp = clamp(vp, 0.0, 1.0);
  if (vp <= 0.25) return 0.5 * sqrt(vp / 0.25);
  if (vp <= 0.5) return 0.8 - 0.3 * sqrt((0.5 - vp) / 0.25);
  float k = sqrt((vp - 0.5) * (0.5 + (1.0 - vp))) / 0.5;
  return 0.8 + 0.2 * min(k, 1.0);
}

// v' -> v of the lat-long family, K = min(1/2, theta_s / pi) (rows crowd at the sun's zenith).
float sbLatLongUnwarp(float vp, float k) {
  vp = clamp(vp, 0.0, 1.0);
  if (vp <= k) return k - sqrt(max(0.0, (k - vp) * (k + vp)));
  return k + sqrt(max(0.0, (vp - k) * (2.0 - k - vp)));
}

// Direction -> (u, v) in the sun-aligned family for a sun at zenith zs (< 90 deg).
vec2 sbUvSunAligned(vec3 d, float zs) {
  float ss = sin(zs), cs = cos(zs);
  float ds = ss * d.x + cs * d.z;  // along the sun s = (sin zs, 0, cos zs)
  float dt = cs * d.x - ss * d.z;  // along t = (cos zs, 0, -sin zs): from the sun down to the horizon
  float db = abs(d.y);             // along b = (0, 1, 0), folded onto the mirror side
  float rho = length(vec2(dt, db));
  float theta = atan(rho, ds);                       // angle from the sun
  float phi = rho > 0.0 ? atan(db, dt) : 0.0;        // azimuth around the sun, [0, pi]
  float edge = 0.5 * SB_PI - atan(cos(phi) * tan(zs));  // the horizon's angle from the sun along phi
  float vp = theta <= edge ? theta / (2.0 * edge) : 0.5 + (theta - edge) / (2.0 * (SB_PI - edge));
  return vec2(clamp(phi / SB_PI, 0.0, 1.0), sbSunAlignedUnwarp(vp));
}

// Direction -> (u, v) in the latitude-longitude family for a sun at zenith zs.
vec2 sbUvLatLong(vec3 d, float zs) {
  float theta = atan(length(d.xy), d.z);
  float phi = atan(abs(d.y), d.x);
  return vec2(clamp(sqrt(phi / SB_PI), 0.0, 1.0), sbLatLongUnwarp(theta / SB_PI, min(0.5, zs / SB_PI)));
}

// --------------------------------------------------------------------------------- sky LUT
// lut-pack's sky LUT as a 2D array texture (sky_<name>_array.ktx2, R11F_G11F_B10F, LINEAR,
// CLAMP_TO_EDGE; layer layerBase + k = slice k), decoded as docs/lut-pack.md "Decoding" says.
// layerBase lets several LUTs of one size share an array (the viewer stacks the fog LUTs of
// all basis skies: one sampler for any number of skies); 0 for a texture of its own.
struct SbSkyLut {
  SbTimeMapping time;
  float thresholdZenith;  // zenith angle (rad) of the sphere mapping's threshold (75 deg)
  vec2 size;              // W, H texels of a slice
  float nodes;            // 1: texel (x, y) at u = x/(W-1) (fog LUTs, skybake.texel_grid = nodes); 0: centres
  float invScale;         // 1 / skybake.scale (texels store cd/m^2 x scale)
  vec3 night;             // skybake.night_rgb (cd/m^2): the uniform sky reached at nightEnd
  float nightEnd;         // skybake.night_end_zenith_deg, rad
  float geometric;        // 1: geometric slice blend (default), 0: linear (the talk's lerp)
  float layerBase;        // the array layer of slice 0
};

// Texture coordinate of (u, v) on the texel grid: centres as is, nodes at both ends.
vec2 sbTexelCoord(vec2 uv, vec2 size, float nodes) {
  return nodes > 0.5 ? (uv * (size - 1.0) + 0.5) / size : uv;
}

// Slice k read along d for a sun at zenith zs with the family slice k was rendered with; a
// sun-aligned slice is read at min(zs, threshold), its domain.
vec3 sbSkySlice(sampler2DArray lut, SbSkyLut p, float k, vec3 d, float zs) {
  bool sunAligned = sbSliceZenith(p.time, k) <= p.thresholdZenith;
  vec2 uv = sunAligned ? sbUvSunAligned(d, min(zs, p.thresholdZenith)) : sbUvLatLong(d, zs);
  return SB_TEXTURE(lut, vec3(sbTexelCoord(uv, p.size, p.nodes), p.layerBase + k)).rgb * p.invScale;
}

// The decoded sky radiance (cd/m^2, Linear Rec.2020) along unit direction d for a sun at zenith
// angle zs (lut/decoder.h SkyLutDecoder::Radiance):
//   zs <= theta_last: L = max(S_i, eps)^(1-t) max(S_{i+1}, eps)^t per channel, eps = 1e-6 cd/m^2
//   beyond: L = (1 - f) S_last(d, theta_last) + f night, f = (zs - theta_last)/(nightEnd - theta_last)
// Two fetches (one beyond the last slice or on a slice).
vec3 sbSkyRadiance(sampler2DArray lut, SbSkyLut p, vec3 d, float zs) {
  float n = sbSlices(p.time);
  float zLast = sbSliceZenith(p.time, n - 1.0);
  if (zs > zLast) {
    float f = p.nightEnd > zLast ? clamp((zs - zLast) / (p.nightEnd - zLast), 0.0, 1.0) : 1.0;
    return mix(sbSkySlice(lut, p, n - 1.0, d, zLast), p.night, f);
  }
  vec2 it = sbSliceBlend(p.time, zs);
  vec3 a = sbSkySlice(lut, p, it.x, d, zs);
  if (it.y <= 0.0) return a;
  vec3 b = sbSkySlice(lut, p, it.x + 1.0, d, zs);
  if (p.geometric < 0.5) return mix(a, b, it.y);
  const vec3 eps = vec3(1e-6);
  return exp2(mix(log2(max(a, eps)), log2(max(b, eps)), it.y));
}

// ------------------------------------------------------------------ weather: basis-sky blend
// GT7 "Interpolation of Basis Skies": haziness h weights clear against hazed (the sunny mode);
// cloudiness c in [0, 1] walks the ladder sunny, cloudy0, ..., cloudy(M-1) in M equal steps
// (c = 0 the sunny mode, c = 1/M cloudy0, c = 1 the last cloudy sky), so it is both the weight
// between neighbouring cloudy skies and the sunny-to-cloudy transition (docs/runtime.md,
// decision 1). The result is L = sum_k w_k L_k (lut/decoder.h BlendRadiance).
// Returns the weights of (clear, hazed, cloudy j, cloudy j+1) and j in .w of the second vec4.
void sbWeatherWeights(float h, float c, float cloudySkies, out vec4 w, out float j) {
  h = clamp(h, 0.0, 1.0);
  c = clamp(c, 0.0, 1.0);
  float s = c * cloudySkies;          // 0: sunny, 1: cloudy0, ..., M: cloudy(M-1)
  float sunny = max(0.0, 1.0 - s);    // the sunny mode's weight
  float pos = max(s - 1.0, 0.0);      // position among the cloudy skies
  j = min(floor(pos), max(cloudySkies - 2.0, 0.0));
  float f = cloudySkies > 1.0 ? clamp(pos - j, 0.0, 1.0) : 0.0;
  float cloudy = 1.0 - sunny;
  w = vec4(sunny * (1.0 - h), sunny * h, cloudy * (1.0 - f), cloudy * f);
}

// ------------------------------------------------------------------------------------- fog
// docs/fog.md "The model" and "The evaluator"; fog/fog_model.h, fog/fog_evaluator.h.
struct SbFog {
  SbSkyLut lut;           // the fog LUT's decoding (also the shadowed fog LUT's: same layout)
  float planetRadius;     // R (m)
  float observerAltitude; // h (m)
  float cutAltitude;      // c (m): top of the low atmosphere that makes the fog
  float pathAngle;        // 1: theta = (c - h)/D (skybake's default), 0: theta = asin(mu)/(pi/2)
  float nodes;            // elevation nodes of a (0: one a per slice)
  vec2 attSize;           // attenuation LUT W x H
  float attInvScale;      // 1 / its skybake.scale
  float sky;              // this sky's index in stacked arrays: parameter layers 2 sky (+1 shadowed),
                          // attenuation layer sky (0 for textures of their own)
};

// D(mu): distance to the cut sphere along zenith cosine mu (clamped to [0, 1]), far root of
// |r + t mu| = r_c, as (r_c^2 - r^2)/(r mu + sqrt(r^2 mu^2 + r_c^2 - r^2)).
float sbFogBoundary(SbFog f, float mu) {
  mu = clamp(mu, 0.0, 1.0);
  float r = f.planetRadius + f.observerAltitude;
  float k = (f.cutAltitude - f.observerAltitude) * (2.0 * f.planetRadius + f.cutAltitude + f.observerAltitude);
  return k / (r * mu + sqrt(r * r * mu * mu + k));
}

// The elevation asin(mu) of a zenith cosine mu in [0, 1], as an atan (asin, like acos, loses
// precision next to 1 in some GPUs' approximations).
float sbElevation(float mu) { return atan(mu, sqrt((1.0 - mu) * (1.0 + mu))); }

// The normalised view angle theta of k = a theta^p.
float sbFogTheta(SbFog f, float mu) {
  mu = clamp(mu, 0.0, 1.0);
  if (f.pathAngle > 0.5) return (f.cutAltitude - f.observerAltitude) / sbFogBoundary(f, mu);
  return sbElevation(mu) / (0.5 * SB_PI);
}

// F(x, k) = (1 - e^{-kx}) / (1 - e^{-k}), k = a theta^p (theta in [1e-6, 1], k in [0, 1e6]);
// the series x (1 + k (1 - x)/2) below k = 1e-3, where float loses digits to 1 - e^{-k}.
vec3 sbDepthFactor(float x, vec3 a, vec3 p, float theta) {
  vec3 k = clamp(a * pow(vec3(clamp(theta, 1e-6, 1.0)), p), 0.0, 1e6);
  vec3 direct = (1.0 - exp(-k * x)) / max(1.0 - exp(-k), 1e-30);
  vec3 series = x * (1.0 + 0.5 * k * (1.0 - x));
  return clamp(mix(direct, series, vec3(lessThan(k, vec3(1e-3)))), 0.0, 1.0);
}

// The attenuation LUT's v = (elevation / 90 deg)^(1/2) (always the elevation).
float sbAttenuationV(float mu) { return sqrt(sbElevation(clamp(mu, 0.0, 1.0)) / (0.5 * SB_PI)); }

// a and p of one slice k at v: p at texel (0, k), a at texels (1 + j, k) of the parameter
// texture (fog_<sky>_params.ktx2, RGBA32F 2D array, layer 0 fog, 1 shadowed fog; + 2 sky when
// stacked), linear in v
// between the nodes, which are uniform in v (the depth tables' elevations 90 deg (j/(m-1))^2).
void sbFogSliceParams(sampler2DArray params, SbFog f, float k, float v, float layer, out vec3 a, out vec3 p) {
  layer += 2.0 * f.sky;
  p = SB_TEXEL_FETCH(params, ivec3(0, int(k), int(layer)), 0).rgb;
  if (f.nodes < 1.5) {
    a = SB_TEXEL_FETCH(params, ivec3(1, int(k), int(layer)), 0).rgb;
    return;
  }
  float x = clamp(v, 0.0, 1.0) * (f.nodes - 1.0);
  float j = min(floor(x), f.nodes - 2.0);
  float w = x - j;
  vec3 a0 = SB_TEXEL_FETCH(params, ivec3(1 + int(j), int(k), int(layer)), 0).rgb;
  vec3 a1 = SB_TEXEL_FETCH(params, ivec3(2 + int(j), int(k), int(layer)), 0).rgb;
  a = mix(a0, a1, w);
}

// a and p at a sun zenith angle: the slices' values blended with the fog LUT's own slice weight.
void sbFogParams(sampler2DArray params, SbFog f, float zs, float mu, float layer, out vec3 a, out vec3 p) {
  vec2 it = sbSliceBlend(f.lut.time, zs);
  float v = sbAttenuationV(mu);
  sbFogSliceParams(params, f, it.x, v, layer, a, p);
  if (it.y > 0.0) {
    vec3 a1, p1;
    sbFogSliceParams(params, f, it.x + 1.0, v, layer, a1, p1);
    a = mix(a, a1, it.y);
    p = mix(p, p1, it.y);
  }
}

// The fog in front of an object at distance depth (m) along unit direction d, sun at zenith zs,
// cloud occlusion o in [0, 1] (GT7: "interpolated with Fog LUT using the cloud occlusion"):
//   x = min(depth / D(mu), 1),  inscattered = (1 - o) L F(x, a theta^p) + o S F(x, a' theta^p')
// L, S: the fog and shadowed fog LUTs read at d itself (their texels below the horizon hold the
// horizon's value). Returns the in-scattered radiance (cd/m^2).
vec3 sbFogInscattered(sampler2DArray fogLut, sampler2DArray shadowedLut, sampler2DArray params, SbFog f,
                      vec3 d, float depth, float zs, float o) {
  float x = min(max(depth, 0.0) / sbFogBoundary(f, d.z), 1.0);
  if (!(x > 0.0)) return vec3(0.0);
  float theta = sbFogTheta(f, d.z);
  vec3 a, p;
  sbFogParams(params, f, zs, d.z, 0.0, a, p);
  vec3 fog = sbSkyRadiance(fogLut, f.lut, d, zs) * sbDepthFactor(x, a, p, theta);
  if (o <= 0.0) return fog;
  vec3 as, ps;
  sbFogParams(params, f, zs, d.z, 1.0, as, ps);
  vec3 shadowed = sbSkyRadiance(shadowedLut, f.lut, d, zs) * sbDepthFactor(x, as, ps, theta);
  return mix(fog, shadowed, clamp(o, 0.0, 1.0));
}

// The transmittance from the observer to the object (per Rec.2020 channel, sunlight-weighted):
// the attenuation LUT at u = x^(1/3), v = (elevation / 90 deg)^(1/2), nodes at both ends.
vec3 sbFogTransmittance(sampler2DArray att, SbFog f, vec3 d, float depth) {
  float x = min(max(depth, 0.0) / sbFogBoundary(f, d.z), 1.0);
  vec2 uv = vec2(pow(x, 1.0 / 3.0), sbAttenuationV(d.z));
  return SB_TEXTURE(att, vec3(sbTexelCoord(uv, f.attSize, 1.0), f.sky)).rgb * f.attInvScale;
}

// -------------------------------------------------------------------- sun, transmittance, ambient
// lut-pack's other LUTs (docs/lut-pack.md "Outputs"): one row per basis sky (v = (row + 1/2)/rows).
//   transmittance.ktx2: 181 x rows, T_c(view zenith) for sunlight, u = (i + 1/2)/181, i = zenith in deg
//   sun.ktx2, ambient.ktx2: N x rows at the slice angles, u = (i + t + 1/2)/N from sbSliceBlend
// (hardware linear filtering between texels i and i + 1 with weight t is the decoder's blend).

// Sun illuminance at normal incidence (lux, Rec.2020) or the sky's horizontal illuminance without
// the sun (ambient, lux) for a sun at zenith zs: one fetch.
vec3 sbSlicedLut(sampler2D lut, SbTimeMapping tm, float row, float rows, float invScale, float zs) {
  vec2 it = sbSliceBlend(tm, zs);
  float n = sbSlices(tm);
  return SB_TEXTURE(lut, vec2((it.x + it.y + 0.5) / n, (row + 0.5) / rows)).rgb * invScale;
}

// Transmittance to space along view zenith angle z (rad): one fetch.
vec3 sbTransmittance(sampler2D lut, float row, float rows, float invScale, float z) {
  float u = (clamp(z / SB_DEG, 0.0, 180.0) + 0.5) / 181.0;
  return SB_TEXTURE(lut, vec2(u, (row + 0.5) / rows)).rgb * invScale;
}

// The sun disk's radiance (cd/m^2) at angular distance g from the sun's centre for a disk of
// angular radius alpha with illuminance E (lux): E / (2 pi (1 - cos alpha)) times the limb darkening
// I(mu)/I(1) = 1 - u (1 - mu), mu = cos of the angle on the solar surface = sqrt(1 - (g/alpha)^2),
// normalised so the disk's integral is E (the mean of 1 - u(1 - mu) over the disk is 1 - u/3);
// u = 0.6 is the linear law's coefficient near 550 nm (Neckel & Labs 1994, Solar Physics 153:91).
vec3 sbSunDisk(vec3 e, float g, float alpha) {
  if (g >= alpha) return vec3(0.0);
  float q = g / alpha;
  float mu = sqrt(max(0.0, 1.0 - q * q));
  const float u = 0.6;
  float solidAngle = 4.0 * SB_PI * sin(0.5 * alpha) * sin(0.5 * alpha);  // 2 pi (1 - cos alpha), no cancellation
  return e / solidAngle * (1.0 - u * (1.0 - mu)) / (1.0 - u / 3.0);
}
