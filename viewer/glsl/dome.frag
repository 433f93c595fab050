// The checks' fixed views: the blended sky on the upper-hemisphere dome of lut/dome_view.h
// (azimuth from the sun 2 pi (x + 1/2)/W - pi, view zenith (pi/2)(y + 1/2)/H, row 0 at the
// zenith), linear radiance (cd/m^2, Linear Rec.2020) into an RGBA32F target. Read back with
// readPixels (rows bottom-up: the page flips them).
uniform float uSunZenith;
uniform vec2 uDomeSize;
in vec2 vUv;
layout(location = 0) out vec4 outColor;
void main() {
  vec2 px = floor(gl_FragCoord.xy);
  float x = px.x, y = uDomeSize.y - 1.0 - px.y;  // row 0 of the dome at the top of the target
  float phi = 2.0 * SB_PI * (x + 0.5) / uDomeSize.x - SB_PI;
  float theta = 0.5 * SB_PI * (y + 0.5) / uDomeSize.y;
  vec3 d = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
  outColor = vec4(skyBlend(d, uSunZenith), 1.0);
#ifdef SB_COUNT_FETCHES
  outColor.a = sb_fetches;
#endif
}
