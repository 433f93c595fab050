// The viewer's uniforms and the weather blend of the basis skies over skybake_runtime.glsl:
// four sky-LUT slots (clear, hazed and the two cloudy skies the cloudiness falls between), the
// sun / ambient / transmittance LUTs (one row per basis sky) and the fog textures of every sky
// stacked in 2D arrays (viewer/js/bake.js). Frame: the sun's local frame of skybake_runtime.glsl.

uniform sampler2DArray uSkyLut0, uSkyLut1, uSkyLut2, uSkyLut3;
uniform SbSkyLut uSkyP[4];
uniform vec4 uWeights;     // weights of the four slots (sbWeatherWeights), 0 for an empty slot
uniform vec4 uSkyRow;      // each slot's row in the sun / ambient / transmittance LUTs
uniform float uRows;       // rows of those LUTs (the basis skies)
uniform sampler2D uSunLut, uAmbientLut, uTransLut;
uniform vec3 uOtherInvScale;  // 1 / skybake.scale of sun, ambient, transmittance

uniform float uFogOn;
uniform sampler2DArray uFogLut, uFogShadowedLut, uFogParams, uFogAtt;
uniform SbFog uFogP[4];    // the fog of each slot's sky
uniform vec4 uFogHave;     // 1 where that sky has fog products

vec3 skySlot(int s, vec3 d, float zs) {
  if (s == 0) return sbSkyRadiance(uSkyLut0, uSkyP[0], d, zs);
  if (s == 1) return sbSkyRadiance(uSkyLut1, uSkyP[1], d, zs);
  if (s == 2) return sbSkyRadiance(uSkyLut2, uSkyP[2], d, zs);
  return sbSkyRadiance(uSkyLut3, uSkyP[3], d, zs);
}

// L = sum_k w_k L_k over the slots with a weight (lut/decoder.h BlendRadiance).
vec3 skyBlend(vec3 d, float zs) {
  vec3 l = vec3(0.0);
  if (uWeights.x > 0.0) l += uWeights.x * skySlot(0, d, zs);
  if (uWeights.y > 0.0) l += uWeights.y * skySlot(1, d, zs);
  if (uWeights.z > 0.0) l += uWeights.z * skySlot(2, d, zs);
  if (uWeights.w > 0.0) l += uWeights.w * skySlot(3, d, zs);
  return l;
}

// sum_k w_k of a per-sky LUT value: sun illuminance (which 0), ambient (1).
vec3 slicedBlend(int which, float zs) {
  vec3 e = vec3(0.0);
  for (int s = 0; s < 4; ++s) {
    float w = uWeights[s];
    if (w <= 0.0) continue;
    e += w * (which == 0 ? sbSlicedLut(uSunLut, uSkyP[0].time, uSkyRow[s], uRows, uOtherInvScale.x, zs)
                         : sbSlicedLut(uAmbientLut, uSkyP[0].time, uSkyRow[s], uRows, uOtherInvScale.y, zs));
  }
  return e;
}

vec3 transmittanceBlend(float z) {
  vec3 t = vec3(0.0);
  for (int s = 0; s < 4; ++s) {
    float w = uWeights[s];
    if (w > 0.0) t += w * sbTransmittance(uTransLut, uSkyRow[s], uRows, uOtherInvScale.z, z);
  }
  return t;
}

// The fog of slot s in front of an object at `depth` along d: in-scattered radiance and
// transmittance (fog_evaluator.h Evaluate).
void fogSlot(int s, vec3 d, float depth, float zs, float o, out vec3 inscattered, out vec3 transmittance) {
  SbFog f = uFogP[0];
  if (s == 1) f = uFogP[1];
  if (s == 2) f = uFogP[2];
  if (s == 3) f = uFogP[3];
  inscattered = sbFogInscattered(uFogLut, uFogShadowedLut, uFogParams, f, d, depth, zs, o);
  transmittance = sbFogTransmittance(uFogAtt, f, d, depth);
}

// The weather blend of the fog: pixel = object sum_k w_k T_k + sum_k w_k I_k (weights of the
// slots with fog, renormalised).
vec3 fogBlend(vec3 object, vec3 d, float depth, float zs, float o) {
  vec3 inscattered = vec3(0.0), transmittance = vec3(0.0);
  float wsum = 0.0;
  for (int s = 0; s < 4; ++s) {
    float w = uWeights[s] * uFogHave[s];
    if (w <= 0.0) continue;
    vec3 i, t;
    fogSlot(s, d, depth, zs, o, i, t);
    inscattered += w * i;
    transmittance += w * t;
    wsum += w;
  }
  if (wsum <= 0.0) return object;
  return (object * transmittance + inscattered) / wsum;
}
