// The checks' fog points: pixel i of a N x 1 target evaluates the fog of one basis sky at the
// (sun zenith, view zenith, relative azimuth, depth) of texel i of uPoints (deg, deg, deg, m) and
// the occlusion in texel i of uPoints2.r, as `fog-fit eval` does (docs/fog.md): target 0 the
// in-scattered radiance (cd/m^2), target 1 the transmittance.
uniform sampler2D uPoints, uPoints2;
uniform int uFogSlot;
layout(location = 0) out vec4 outInscattered;
layout(location = 1) out vec4 outTransmittance;
void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 q = texelFetch(uPoints, px, 0);
  float o = texelFetch(uPoints2, px, 0).r;
  float t = q.y * SB_DEG, p = q.z * SB_DEG;
  vec3 d = vec3(sin(t) * cos(p), sin(t) * sin(p), cos(t));
  vec3 i, tr;
  fogSlot(uFogSlot, d, q.w, q.x * SB_DEG, o, i, tr);
  outInscattered = vec4(i, 1.0);
  outTransmittance = vec4(tr, 1.0);
}
