#pragma once
// GLSL 3.30 sources of the hair splat passes (Bando 2003 §3.4; internal, used by splat_gl.cpp).
// Particles live in a texture buffer (4 RGBA32F texels each, world space):
//   0: position, billboard half-width [m]     1: unit direction t_i, billboard half-length [m]
//   2: linear RGB colour, opacity alpha_i     3: min sin(theta), cast_shadow, self_shadow, item
// and an int texture buffer holds draw orders (light order first, then the view order).
// Billboards are drawn without vertex attributes: vertex v is corner v % 6 of particle
// uOrder[uOrderBase + v / 6].
namespace follicle::render::glsl {

inline constexpr const char* kSplatCommon = R"(
uniform samplerBuffer uParticles;
uniform isamplerBuffer uOrder;
uniform int uOrderBase;
uniform sampler2D uHairTex;
uniform sampler2D uIntensity;  // per particle: R objects' visibility, G light through the hair
uniform int uIntensityWidth;

struct Particle {
  vec3 pos; float half_w;
  vec3 t; float half_l;
  vec3 color; float alpha;
  float min_sin; float casts; float selfs; int item;
};

Particle fetch_particle(int i) {
  Particle p;
  vec4 a = texelFetch(uParticles, 4 * i);
  vec4 b = texelFetch(uParticles, 4 * i + 1);
  vec4 c = texelFetch(uParticles, 4 * i + 2);
  vec4 d = texelFetch(uParticles, 4 * i + 3);
  p.pos = a.xyz; p.half_w = a.w;
  p.t = b.xyz; p.half_l = b.w;
  p.color = c.rgb; p.alpha = c.a;
  p.min_sin = d.x; p.casts = d.y; p.selfs = d.z; p.item = int(d.w + 0.5);
  return p;
}

ivec2 intensity_texel(int i) { return ivec2(i % uIntensityWidth, i / uIntensityWidth); }

// Bando 2003 §3.4 / Fig. 3.5(b): the billboard lies across the projection direction dp with
// its vertical axis along the projection of t_i; s = max(sin(theta), min_sin) with
// cos(theta) = t_i . dp. Its length is scaled by s (what the t-aligned quad projects to) and
// its opacity by 1/s.
void billboard_axes(vec3 t, vec3 dp, float min_sin, out vec3 along, out vec3 across, out float s) {
  vec3 tp = t - dot(t, dp) * dp;
  float st = length(tp);
  if (st < 1e-6) {
    tp = cross(dp, abs(dp.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0));
    st = 0.0;
  }
  along = normalize(tp);
  across = normalize(cross(dp, along));
  s = max(st, min_sin);
}

const vec2 kCorner[6] = vec2[6](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(1.0, 1.0),
                                vec2(-1.0, -1.0), vec2(1.0, 1.0), vec2(-1.0, 1.0));

vec3 billboard_corner(Particle p, vec3 dp, int corner, out vec2 uv, out float s) {
  vec3 along, across;
  billboard_axes(p.t, dp, p.min_sin, along, across, s);
  vec2 c = kCorner[corner];
  uv = c * 0.5 + 0.5;  // u across, v along the hair
  return p.pos + c.x * p.half_w * across + c.y * p.half_l * s * along;
}
)";

// Light pass, step 1 of a batch (pseudo-code lines 8-9): one point per particle written into
// its texel of the intensity texture: the objects' shadow-map visibility and the light reaching
// it through the hair splatted so far (the light buffer, averaged over 5 taps of its footprint).
inline constexpr const char* kSplatGatherVs = R"(
uniform mat4 uLightVP;
uniform vec3 uLightTravel;  // unit direction the light travels
uniform sampler2DShadow uShadowTex;
uniform sampler2D uLightBuf;
uniform float uShadowTexel;
uniform float uShadowBias;
uniform int uIntensityHeight;
uniform bool uVisibilityOnly;  // the "cpu" light pass reads the hair light itself: skip it here
flat out vec2 vValue;

float light_buffer(vec3 w) {
  vec4 c = uLightVP * vec4(w, 1.0);
  vec2 s = c.xy / c.w * 0.5 + 0.5;
  if (s.x < 0.0 || s.x > 1.0 || s.y < 0.0 || s.y > 1.0) return 1.0;
  return textureLod(uLightBuf, s, 0.0).r;
}

void main() {
  int i = texelFetch(uOrder, uOrderBase + gl_VertexID).r;
  Particle p = fetch_particle(i);
  ivec2 tx = intensity_texel(i);
  gl_Position = vec4((vec2(tx) + 0.5) / vec2(uIntensityWidth, uIntensityHeight) * 2.0 - 1.0,
                     0.0, 1.0);
  gl_PointSize = 1.0;
  vec4 c = uLightVP * vec4(p.pos, 1.0);
  vec3 s = c.xyz / c.w * 0.5 + 0.5;
  float vis = 1.0;
  if (s.x >= 0.0 && s.x <= 1.0 && s.y >= 0.0 && s.y <= 1.0 && s.z <= 1.0) {
    vis = 0.0;
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        vis += 0.25 * texture(uShadowTex, vec3(s.xy + (vec2(k, j) - 0.5) * uShadowTexel,
                                               s.z - uShadowBias));
  }
  if (uVisibilityOnly) {
    vValue = vec2(vis, 1.0);
    return;
  }
  vec3 along, across;
  float sn;
  billboard_axes(p.t, uLightTravel, p.min_sin, along, across, sn);
  vec3 da = 0.5 * p.half_l * sn * along, dc = 0.5 * p.half_w * across;
  float T = 0.4 * light_buffer(p.pos) +
            0.15 * (light_buffer(p.pos + da) + light_buffer(p.pos - da) +
                    light_buffer(p.pos + dc) + light_buffer(p.pos - dc));
  vValue = vec2(vis, T);
}
)";

inline constexpr const char* kSplatGatherFs = R"(
flat in vec2 vValue;
out vec4 fragColor;
void main() { fragColor = vec4(vValue, 0.0, 1.0); }
)";

// Light pass, step 2 of a batch (line 10): the batch's billboards seen from the light,
// multiplying the light buffer by (1 - alpha) (blend ZERO, ONE_MINUS_SRC_ALPHA). A particle in
// the objects' shadow is not splatted (line 8; weighted by the PCF visibility).
inline constexpr const char* kSplatLightVs = R"(
uniform mat4 uLightVP;
uniform vec3 uLightTravel;
uniform float uShadowOpacity[8];
out vec2 vUV;
out float vAlpha;
void main() {
  int i = texelFetch(uOrder, uOrderBase + gl_VertexID / 6).r;
  Particle p = fetch_particle(i);
  float s;
  vec3 w = billboard_corner(p, uLightTravel, gl_VertexID % 6, vUV, s);
  float vis = texelFetch(uIntensity, intensity_texel(i), 0).r;
  vAlpha = min(1.0, p.alpha / s * uShadowOpacity[p.item]) * vis * p.casts;
  gl_Position = uLightVP * vec4(w, 1.0);
}
)";

inline constexpr const char* kSplatLightFs = R"(
in vec2 vUV;
in float vAlpha;
out vec4 fragColor;
void main() { fragColor = vec4(0.0, 0.0, 0.0, vAlpha * texture(uHairTex, vUV).a); }
)";

// View pass (lines 18-21): back-to-front billboards facing the eye, shaded per particle with
// Kajiya-Kay x Goldman under the light attenuated by the objects and the hair.
inline constexpr const char* kSplatViewVs = R"(
uniform mat4 uViewProj;
uniform int uShadowLight;     // index of the light of the light pass, -1: none
uniform bool uHasIntensity;
uniform float uDiffuse[8];
uniform float uSpecular[8];
uniform float uShininess[8];
uniform float uAmbient[8];
uniform float uReflect[8];
uniform float uTransmit[8];
out vec2 vUV;
flat out vec3 vColor;
flat out float vAlpha;
void main() {
  int i = texelFetch(uOrder, uOrderBase + gl_VertexID / 6).r;
  Particle p = fetch_particle(i);
  vec3 dp = normalize(p.pos - uEye);
  float s;
  vec3 w = billboard_corner(p, dp, gl_VertexID % 6, vUV, s);
  gl_Position = uViewProj * vec4(w, 1.0);
  vAlpha = min(1.0, p.alpha / s);  // Bando 2003 §3.4: opacity / sin(theta)
  float att = 1.0;
  if (uHasIntensity) {
    vec2 li = texelFetch(uIntensity, intensity_texel(i), 0).rg;
    att = li.r * (p.selfs > 0.5 ? li.g : 1.0);
  }
  int m = p.item;
  vec3 T = p.t, E = -dp;
  float te = dot(T, E);
  float se = sqrt(max(0.0, 1.0 - te * te));
  vec3 col = p.color * uAmbient[m] * uAmbientColor;
  for (int j = 0; j < uNumLights; ++j) {
    vec3 L = uLightDir[j];
    float tl = dot(T, L);
    float sl = sqrt(max(0.0, 1.0 - tl * tl));
    // Kajiya-Kay 1989 phase function
    float spec = pow(max(0.0, sl * se - tl * te), uShininess[m]);
    // Goldman 1997 directionality: kappa = cos of the angle between planes (t,l) and (t,e)
    vec3 a = cross(T, L), b = cross(T, E);
    float den = length(a) * length(b);
    float kappa = den > 1e-9 ? clamp(dot(a, b) / den, -1.0, 1.0) : 0.0;
    float fdir = 0.5 * (1.0 + kappa) * uReflect[m] + 0.5 * (1.0 - kappa) * uTransmit[m];
    vec3 Ej = uLightColor[j] * (j == uShadowLight ? att : 1.0);
    col += Ej * fdir * (uDiffuse[m] * sl * p.color + vec3(uSpecular[m] * spec));
  }
  if (uNumLights == 0) col = p.color;  // no lights: unlit hair colour
  vColor = col;
}
)";

inline constexpr const char* kSplatViewFs = R"(
in vec2 vUV;
flat in vec3 vColor;
flat in float vAlpha;
out vec4 fragColor;
void main() {
  vec4 tx = texture(uHairTex, vUV);
  if (tx.a < 0.004) discard;  // most of a hair billboard is empty: skip the blend
  fragColor = vec4(vColor * tx.rgb, vAlpha * tx.a);
}
)";

}  // namespace follicle::render::glsl
