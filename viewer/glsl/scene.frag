// The game view: a camera at 2 m above a flat ground, the blended sky (skyBlend), the sun disk,
// a ray-marched cumulus layer (GT7 "Run-time Cloud Rendering Method", as far as the talk
// describes it; the approximations are listed in docs/runtime.md) and the global fog over a
// ground with distance rings. Output: linear radiance (cd/m^2, Linear Rec.2020) in .rgb, the
// distance to the surface seen (m; 0 for the sky) in .a, into an RGBA32F target.
//
// World frame: +z up, x east, y north, the observer at the world centre; the sun at azimuth
// uSunAzimuth (rad, from +x towards +y) and zenith uSunZenith. The LUTs' frame has +x at the
// sun's azimuth: a world direction is rotated by -uSunAzimuth about z before a LUT is read.
uniform vec2 uResolution;
uniform vec3 uCamRight, uCamUp, uCamForward;
uniform float uTanHalfFov;   // tan(vertical field of view / 2)
uniform float uSunZenith, uSunAzimuth;
uniform float uSunRadius;    // angular radius of the sun (rad)
uniform float uGroundAlbedo; // the ground's diffuse albedo (1)
uniform float uEyeHeight;    // m

uniform float uCloudsOn;
uniform sampler3D uNoiseLow, uNoiseHigh;
uniform sampler2D uCumulus;
uniform sampler2DArray uCoverage;
uniform vec2 uNoiseTile;     // tile sizes of the low and high volumes (m; skybake.tile_size_m)
uniform vec2 uCumulusMap;    // skybake.mapping.a, skybake.mapping.half_extent_m (m)
uniform vec2 uCoverageAlt;   // altitudes of the coverage texture's first and last rows (m)
uniform vec2 uCoverageSize;  // its W x H
uniform float uCloudTypes;   // its layers
uniform float uCloudSteps;   // the most ray-march steps through the layer

in vec2 vUv;
layout(location = 0) out vec4 outColor;

const float kPlanetRadius = 6371e3;  // m (the basis skies' planet, docs/lut-pack.md "Basis skies")
// Extinction of cumulus at full density: beta = 3 LWC / (2 rho_w r_eff) with a liquid water content
// of 0.3 g/m^3 and r_eff = 10 um (Stephens 1978, J. Atmos. Sci. 35:2123, eq. 10; cumulus LWC
// 0.2-0.5 g/m^3): 0.045 m^-1. Cloud droplets do not absorb in the visible (albedo 1).
const float kSigmaMax = 0.045;
const float kMidTile = 2000.0;       // m: GT7's mid frequency, the low volume at a 2 km tile

vec3 toSunFrame(vec3 w) {
  float c = cos(uSunAzimuth), s = sin(uSunAzimuth);
  return vec3(c * w.x + s * w.y, -s * w.x + c * w.y, w.z);
}

// Henyey-Greenstein phase function (1/sr).
float hg(float cosTheta, float g) {
  float d = 1.0 + g * g - 2.0 * g * cosTheta;
  return (1.0 - g * g) / (4.0 * SB_PI * d * sqrt(d));
}

// Cumulus-map texture coordinates of a world position (docs/clouds.md "Nonlinear texel
// distribution": u = asinh(x sinh(a) / R) / a per axis; a -> 0 is the uniform map).
vec2 cumulusUv(vec2 p) {
  float a = uCumulusMap.x, R = uCumulusMap.y;
  vec2 u = a > 1e-6 ? vec2(asinh(p.x * sinh(a) / R), asinh(p.y * sinh(a) / R)) / a : p / R;
  return 0.5 * (u + 1.0);
}

// Cloud density (0-1, of kSigmaMax) and the coverage texture's ambient factor at world position p
// (m) and altitude z (m): rho = saturate(R + G n_low + B n_mid - erosion) (docs/clouds.md "The
// coverage texture"), R, G, B, A from the coverage layer of the map's cloud type.
vec2 cloudDensity(vec3 p, float z) {
  if (z < uCoverageAlt.x || z > uCoverageAlt.y) return vec2(0.0);
  vec2 uv = cumulusUv(p.xy);
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return vec2(0.0);  // beyond the 240 km map
  vec2 m = SB_TEXTURE(uCumulus, uv).rg;  // density, cloud type
  if (m.x <= 0.0) return vec2(0.0);
  vec2 cuv = vec2((m.x * (uCoverageSize.x - 1.0) + 0.5) / uCoverageSize.x,
                  ((z - uCoverageAlt.x) / (uCoverageAlt.y - uCoverageAlt.x) * (uCoverageSize.y - 1.0) + 0.5) / uCoverageSize.y);
  float layer = m.y * (uCloudTypes - 1.0);
  float l0 = floor(layer);
  vec4 cov = SB_TEXTURE(uCoverage, vec3(cuv, l0));
  if (layer > l0) cov = mix(cov, SB_TEXTURE(uCoverage, vec3(cuv, l0 + 1.0)), layer - l0);
  if (cov.r + cov.g + cov.b <= 0.0) return vec2(0.0, cov.a);
  float nLow = SB_TEXTURE(uNoiseLow, p / uNoiseTile.x).r;
  float nMid = SB_TEXTURE(uNoiseLow, p / kMidTile).r;
  float base = cov.r + cov.g * nLow + cov.b * nMid;
  if (base <= 0.0) return vec2(0.0, cov.a);
  // Erosion by the high-frequency Worley noise at the cloud's edges (Schneider 2015's remap: thin
  // parts lose most): the viewer's choice, the coverage contract leaves erosion() open.
  float nHigh = SB_TEXTURE(uNoiseHigh, p / uNoiseTile.y).r;
  float rho = clamp(base - 0.35 * (1.0 - nHigh) * (1.0 - clamp(base, 0.0, 1.0)), 0.0, 1.0);
  return vec2(rho, cov.a);
}

// Distances along a ray from radius r0 (|o| = r0, direction cosine mu to the local vertical) to the
// sphere of radius R (the far root; -1 when it is not hit ahead).
float sphereExit(float r0, float mu, float R) {
  float b = r0 * mu, c = r0 * r0 - R * R;
  float disc = b * b - c;
  if (disc < 0.0) return -1.0;
  return -b + sqrt(disc);
}

// Altitude of world point p (the observer at the world centre, eye height above the ground).
float altitudeOf(vec3 p) { return length(p + vec3(0.0, 0.0, kPlanetRadius)) - kPlanetRadius; }

// Optical depth through the layer from p towards the sun (6 steps growing by 1.6x).
float sunOpticalDepth(vec3 p, vec3 sun) {
  float tau = 0.0, t = 0.0, dt = 120.0;
  for (int i = 0; i < 6; ++i) {
    vec3 q = p + sun * (t + 0.5 * dt);
    tau += cloudDensity(q, altitudeOf(q)).x * kSigmaMax * dt;
    t += dt;
    dt *= 1.6;
  }
  return tau;
}

// The cumulus layer along unit world direction d from the eye: in-scattered radiance (rgb) and
// transmittance (a). Front-to-back march with the energy-conserving step integral
// (S - S e^{-sigma dt}) / sigma (Hillaire 2016, "Physically Based Sky, Atmosphere and Cloud
// Rendering in Frostbite", 5.6.3); sunlight with Wrenninge et al. 2013's multiple-scattering
// octaves (a = b = c = 1/2, 3 octaves; GT7 "Lighting Calculations of G-Buffer"), a two-lobe HG
// phase; ambient light E_ambient / pi scaled by the coverage texture's ambient channel.
vec4 clouds(vec3 d, vec3 sunW, vec3 eSun, vec3 eAmb) {
  float r0 = kPlanetRadius + uEyeHeight;
  float t0 = sphereExit(r0, d.z, kPlanetRadius + uCoverageAlt.x);
  float t1 = sphereExit(r0, d.z, kPlanetRadius + uCoverageAlt.y);
  if (t1 <= 0.0 || d.z < -0.05) return vec4(0.0, 0.0, 0.0, 1.0);
  t0 = max(t0, 0.0);
  t1 = min(t1, t0 + 60000.0);  // at most 60 km of the layer (GT7's map spans 240 km)
  // Steps grow with the distance (2 % of it, 40 m to 1 km): the detail a pixel can show. A fixed
  // per-pixel offset of the first step (interleaved gradient noise, Jimenez 2014, "Next
  // Generation Post Processing in Call of Duty: Advanced Warfare") breaks the banding and stays
  // the same every frame, so the images are deterministic.
  float jitter = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
  float cosTheta = dot(d, sunW);
  vec3 l = vec3(0.0);
  float tr = 1.0;
  float t = t0;
  for (int i = 0; i < 512; ++i) {
    if (float(i) >= uCloudSteps || tr < 0.01 || t >= t1) break;
    float dt = clamp(0.02 * t, 40.0, 1000.0);
    float ts = t + jitter * dt;
    t += dt;
    vec3 p = d * ts;
    vec2 rho = cloudDensity(p, altitudeOf(p));
    if (rho.x <= 0.0) continue;
    float sigma = rho.x * kSigmaMax;
    float tau = sunOpticalDepth(p, sunW);
    float sun = 0.0, a = 1.0, b = 1.0, c = 1.0;
    for (int o = 0; o < 3; ++o) {
      float phase = mix(hg(cosTheta, 0.8 * c), hg(cosTheta, -0.3 * c), 0.3);
      sun += b * phase * exp(-a * tau);
      a *= 0.5; b *= 0.5; c *= 0.5;
    }
    vec3 s = sigma * (eSun * sun + eAmb * (rho.y / SB_PI));
    float e = exp(-sigma * dt);
    l += tr * (s - s * e) / sigma;
    tr *= e;
  }
  return vec4(l, tr);
}

void main() {
  vec2 ndc = (gl_FragCoord.xy / uResolution) * 2.0 - 1.0;
  float aspect = uResolution.x / uResolution.y;
  vec3 d = normalize(uCamForward + ndc.x * aspect * uTanHalfFov * uCamRight + ndc.y * uTanHalfFov * uCamUp);
  float zs = uSunZenith;
  vec3 sunW = vec3(sin(zs) * cos(uSunAzimuth), sin(zs) * sin(uSunAzimuth), cos(zs));
  vec3 eSun = slicedBlend(0, zs);      // lux at normal incidence, at the ground
  vec3 eAmb = slicedBlend(1, zs);      // lux on a horizontal surface, without the sun
  float occlusion = 0.0;               // cloud cover of the sun from the observer (for the fog)
  if (uCloudsOn > 0.5 && sunW.z > -0.02) {
    vec3 base = sunW * sphereExit(kPlanetRadius + uEyeHeight, sunW.z, kPlanetRadius + uCoverageAlt.x);
    occlusion = 1.0 - exp(-sunOpticalDepth(base, sunW));
  }
  vec3 color;
  float depth = 0.0;
  if (d.z >= 0.0) {
    color = skyBlend(toSunFrame(d), zs);
    // The sun disk: the sun LUT's illuminance, each point of the disk through the transmittance
    // of its own view zenith (the lower limb redder and dimmer near the horizon): E0 T(z_pixel)
    // with E0 = E_sun / T(z_sun).
    float g = atan(length(cross(d, sunW)), dot(d, sunW));  // the angle from the sun (acos loses it near 1)
    if (g < uSunRadius) {
      vec3 t = transmittanceBlend(atan(length(d.xy), d.z)) / max(transmittanceBlend(zs), vec3(1e-12));
      color += sbSunDisk(eSun * t, g, uSunRadius);
    }
    if (uCloudsOn > 0.5) {
      vec4 c = clouds(d, sunW, eSun, eAmb);
      color = color * c.a + c.rgb;
    }
  } else {
    // The ground: Lambertian, lit by the sun (shadowed by the clouds) and the ambient sky, with
    // marks of the distance (the fog's scale).
    depth = uEyeHeight / -d.z;
    vec3 p = d * depth;
    float shadow = 1.0;
    if (uCloudsOn > 0.5 && sunW.z > 0.0) {
      float toBase = sphereExit(kPlanetRadius, sunW.z, kPlanetRadius + uCoverageAlt.x);
      shadow = exp(-sunOpticalDepth(p + sunW * toBase, sunW));
    }
    // Checkers of 10 m, 100 m and 1 km cells (albedo uGroundAlbedo -/+ 10 % each), each faded
    // where a pixel covers a quarter of its cell (no mipmaps: it would alias), and rings at 100 m,
    // 1, 5, 10, 20 and 50 km, about a pixel wide.
    float r = length(p.xy);
    float pixelAngle = 2.0 * uTanHalfFov / uResolution.y;
    float footprint = r * pixelAngle / max(-d.z, 1e-4);  // m of ground under one pixel, along the view
    float modulation = 0.0;
    for (int k = 0; k < 3; ++k) {
      float size = k == 0 ? 10.0 : k == 1 ? 100.0 : 1000.0;
      vec2 cell = floor(p.xy / size);
      modulation += 0.1 * (mod(cell.x + cell.y, 2.0) * 2.0 - 1.0) * clamp(1.0 - 4.0 * footprint / size, 0.0, 1.0);
    }
    float albedo = uGroundAlbedo * (1.0 + modulation);
    float width = max(r * pixelAngle, 0.5 * footprint);
    for (int k = 0; k < 6; ++k) {
      float ring = k == 0 ? 100.0 : k == 1 ? 1000.0 : k == 2 ? 5000.0 : k == 3 ? 10000.0 : k == 4 ? 20000.0 : 50000.0;
      if (abs(r - ring) < width) albedo = 2.0 * uGroundAlbedo;
    }
    vec3 e = eSun * max(sunW.z, 0.0) * shadow + eAmb;
    color = albedo / SB_PI * e;
    if (uFogOn > 0.5) color = fogBlend(color, toSunFrame(d), depth, zs, occlusion);
  }
  outColor = vec4(color, depth);
#ifdef SB_COUNT_FETCHES
  outColor.a = sb_fetches;
#endif
}
